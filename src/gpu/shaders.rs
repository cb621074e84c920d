//! The WGSL kernels as the runtime loads them: each kernel file with shaders/mesh.wgsl (the
//! shared bindings and helpers) in front, since WGSL has no includes. tests/gpu_shaders.rs
//! validates exactly these sources with naga.

use std::borrow::Cow;

/// Shared declarations every kernel starts with.
const MESH_PRELUDE: &str = include_str!("../../shaders/mesh.wgsl");

/// One shader module: a kernel file and its entry points.
#[derive(Clone, Copy, Debug)]
pub struct Kernel {
    /// The file under shaders/.
    pub file: &'static str,
    pub entry_points: &'static [&'static str],
    body: &'static str,
}

pub const UMBRELLA: Kernel = Kernel {
    file: "umbrella.wgsl",
    entry_points: &["umbrella_step"],
    body: include_str!("../../shaders/umbrella.wgsl"),
};

pub const HC: Kernel = Kernel {
    file: "hc.wgsl",
    entry_points: &["hc_differences", "hc_correct"],
    body: include_str!("../../shaders/hc.wgsl"),
};

pub const SINC: Kernel = Kernel {
    file: "sinc.wgsl",
    entry_points: &["sinc_first", "sinc_term", "sinc_finish"],
    body: include_str!("../../shaders/sinc.wgsl"),
};

/// Every kernel the engine loads.
pub const KERNELS: [Kernel; 3] = [UMBRELLA, HC, SINC];

/// The file every kernel is prefixed with.
pub const PRELUDE_FILE: &str = "mesh.wgsl";

impl Kernel {
    /// The complete WGSL source the runtime compiles.
    pub fn source(&self) -> String {
        format!("{MESH_PRELUDE}\n{}", self.body)
    }

    pub(crate) fn create_module(&self, device: &wgpu::Device) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(self.file),
            source: wgpu::ShaderSource::Wgsl(Cow::Owned(self.source())),
        })
    }
}
