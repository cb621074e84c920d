//! One GPU device per test binary, on whatever adapter the machine has (lavapipe here).
//! Without an adapter the tests print a notice and pass, unless REQUIRE_GPU=1, where they fail.
#![allow(dead_code)]

use std::sync::OnceLock;

use meshsmooth::gpu::{
    request_native_device, request_native_device_with_limits, GpuContext, GpuError, GpuSmoother,
};

pub struct Gpu {
    pub ctx: GpuContext,
    pub smoother: GpuSmoother,
}

pub fn require_gpu() -> bool {
    std::env::var("REQUIRE_GPU").is_ok_and(|v| v == "1")
}

fn no_adapter(e: GpuError) -> Option<Gpu> {
    assert!(!require_gpu(), "REQUIRE_GPU=1 but no GPU device: {e}");
    eprintln!("NOTICE: skipping GPU test, no adapter ({e}); set REQUIRE_GPU=1 to fail instead");
    None
}

/// A device of its own, with `limits` (WebGPU's defaults when `None`).
pub fn gpu_with(limits: Option<wgpu::Limits>) -> Option<Gpu> {
    let ctx = match limits {
        None => request_native_device(),
        Some(l) => request_native_device_with_limits(l),
    };
    match ctx {
        Ok(ctx) => {
            let smoother = GpuSmoother::new(&ctx.device);
            Some(Gpu { ctx, smoother })
        }
        Err(e) => no_adapter(e),
    }
}

/// One device for the whole test binary (creating one on lavapipe takes a while).
pub fn gpu() -> Option<&'static Gpu> {
    static GPU: OnceLock<Option<Gpu>> = OnceLock::new();
    GPU.get_or_init(|| {
        let gpu = gpu_with(None);
        if let Some(g) = &gpu {
            let info = &g.ctx.adapter_info;
            eprintln!(
                "GPU tests on {} ({:?}, {:?})",
                info.name, info.backend, info.device_type
            );
        }
        gpu
    })
    .as_ref()
}
