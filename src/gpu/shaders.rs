//! The WGSL kernels as the runtime loads them: each kernel file with its prelude in front, since
//! WGSL has no includes. The smoothing kernels share shaders/mesh.wgsl (the mesh bindings and
//! helpers); the drift, normal and measure kernels share shaders/surface.wgsl.
//! tests/gpu_shaders.rs validates exactly these sources with naga.

use std::borrow::Cow;

/// Shared declarations every smoothing kernel starts with.
const MESH_PRELUDE: &str = include_str!("../../shaders/mesh.wgsl");
/// Shared declarations every surface kernel (drift, normals, measures) starts with.
const SURFACE_PRELUDE: &str = include_str!("../../shaders/surface.wgsl");

/// One shader module: a kernel file and its entry points.
#[derive(Clone, Copy, Debug)]
pub struct Kernel {
    /// The file under shaders/.
    pub file: &'static str,
    /// The file under shaders/ put in front of it.
    pub prelude_file: &'static str,
    pub entry_points: &'static [&'static str],
    prelude: &'static str,
    body: &'static str,
}

pub const UMBRELLA: Kernel = Kernel {
    file: "umbrella.wgsl",
    prelude_file: MESH_PRELUDE_FILE,
    entry_points: &["umbrella_step"],
    prelude: MESH_PRELUDE,
    body: include_str!("../../shaders/umbrella.wgsl"),
};

pub const HC: Kernel = Kernel {
    file: "hc.wgsl",
    prelude_file: MESH_PRELUDE_FILE,
    entry_points: &["hc_differences", "hc_correct"],
    prelude: MESH_PRELUDE,
    body: include_str!("../../shaders/hc.wgsl"),
};

pub const SINC: Kernel = Kernel {
    file: "sinc.wgsl",
    prelude_file: MESH_PRELUDE_FILE,
    entry_points: &["sinc_first", "sinc_term", "sinc_finish"],
    prelude: MESH_PRELUDE,
    body: include_str!("../../shaders/sinc.wgsl"),
};

pub const DRIFT: Kernel = Kernel {
    file: "drift.wgsl",
    prelude_file: SURFACE_PRELUDE_FILE,
    entry_points: &["reference_reset", "reference_drift"],
    prelude: SURFACE_PRELUDE,
    body: include_str!("../../shaders/drift.wgsl"),
};

pub const NORMALS: Kernel = Kernel {
    file: "normals.wgsl",
    prelude_file: SURFACE_PRELUDE_FILE,
    entry_points: &["vertex_normals"],
    prelude: SURFACE_PRELUDE,
    body: include_str!("../../shaders/normals.wgsl"),
};

pub const MEASURE: Kernel = Kernel {
    file: "measure.wgsl",
    prelude_file: SURFACE_PRELUDE_FILE,
    entry_points: &["measure_vertices"],
    prelude: SURFACE_PRELUDE,
    body: include_str!("../../shaders/measure.wgsl"),
};

/// Every kernel the engine loads.
pub const KERNELS: [Kernel; 6] = [UMBRELLA, HC, SINC, DRIFT, NORMALS, MEASURE];

/// The prelude of the smoothing kernels.
pub const MESH_PRELUDE_FILE: &str = "mesh.wgsl";
/// The prelude of the surface kernels.
pub const SURFACE_PRELUDE_FILE: &str = "surface.wgsl";
/// Every prelude file.
pub const PRELUDE_FILES: [&str; 2] = [MESH_PRELUDE_FILE, SURFACE_PRELUDE_FILE];

impl Kernel {
    /// The complete WGSL source the runtime compiles.
    pub fn source(&self) -> String {
        format!("{}\n{}", self.prelude, self.body)
    }

    pub(crate) fn create_module(&self, device: &wgpu::Device) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(self.file),
            source: wgpu::ShaderSource::Wgsl(Cow::Owned(self.source())),
        })
    }
}
