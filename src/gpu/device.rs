//! Getting a device natively (CLI, tests, benchmarks): a real GPU when there is one, else a
//! software adapter (lavapipe, llvmpipe). The app gets its device from eframe instead.

use super::GpuError;

/// A device and the adapter it came from.
pub struct GpuContext {
    pub adapter_info: wgpu::AdapterInfo,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

/// Preference among adapters, lowest first: real GPUs, then virtual ones, software last; within
/// a kind, the native APIs before GL (whose compute support is the weakest).
fn rank(device_type: wgpu::DeviceType, backend: wgpu::Backend) -> (u8, u8) {
    let kind = match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    let api = match backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        _ => 1,
    };
    (kind, api)
}

/// Requests a device with WebGPU's default limits (so native runs refuse what the browser
/// would) from the most preferred adapter that supports them and compute shaders.
pub fn request_native_device() -> Result<GpuContext, GpuError> {
    request_native_device_with_limits(wgpu::Limits::default())
}

/// As [`request_native_device`], with the given limits (tests lower them to exercise the
/// limit checks and the 2-D dispatch on small meshes).
pub fn request_native_device_with_limits(limits: wgpu::Limits) -> Result<GpuContext, GpuError> {
    // GL only when no Vulkan/Metal/DX12 adapter qualifies: probing EGL without a display
    // prints errors, and its compute support is the weakest.
    for backends in [wgpu::Backends::PRIMARY, wgpu::Backends::SECONDARY] {
        match request_from(backends, &limits) {
            Err(GpuError::NoAdapter(_)) if backends == wgpu::Backends::PRIMARY => continue,
            result => return result,
        }
    }
    Err(GpuError::NoAdapter(String::new()))
}

fn request_from(backends: wgpu::Backends, limits: &wgpu::Limits) -> Result<GpuContext, GpuError> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
    let found: Vec<String> = adapters
        .iter()
        .map(|a| {
            let info = a.get_info();
            format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
        })
        .collect();
    adapters.retain(|a| {
        a.get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
            && limits.check_limits(&a.limits())
    });
    adapters.sort_by_key(|a| {
        let info = a.get_info();
        rank(info.device_type, info.backend)
    });
    let Some(adapter) = adapters.into_iter().next() else {
        let seen = if found.is_empty() {
            String::from(" (no adapter at all)")
        } else {
            format!(" (found: {})", found.join(", "))
        };
        return Err(GpuError::NoAdapter(seen));
    };
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("meshsmooth"),
        required_limits: limits.clone(),
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
        .map_err(|e| GpuError::Device(e.to_string()))?;
    Ok(GpuContext {
        adapter_info: adapter.get_info(),
        device,
        queue,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wgpu::{Backend, DeviceType};

    #[test]
    fn real_gpus_come_before_software_adapters() {
        let mut found = [
            (DeviceType::Cpu, Backend::Vulkan),
            (DeviceType::IntegratedGpu, Backend::Gl),
            (DeviceType::Cpu, Backend::Gl),
            (DeviceType::DiscreteGpu, Backend::Vulkan),
            (DeviceType::IntegratedGpu, Backend::Vulkan),
        ];
        found.sort_by_key(|&(t, b)| rank(t, b));
        assert_eq!(
            found,
            [
                (DeviceType::DiscreteGpu, Backend::Vulkan),
                (DeviceType::IntegratedGpu, Backend::Vulkan),
                (DeviceType::IntegratedGpu, Backend::Gl),
                (DeviceType::Cpu, Backend::Vulkan),
                (DeviceType::Cpu, Backend::Gl),
            ]
        );
    }
}
