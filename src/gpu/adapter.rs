//! What kind of adapter a device came from, where that changes how to use it.

/// Whether `info` describes a software rasteriser (SwiftShader, llvmpipe, lavapipe, WARP), where
/// the CPU runs every shader: the app draws without multisampling there and keeps its
/// background work on its own CPU engine. The browser reports one as its fallback adapter
/// (mapped to [`wgpu::DeviceType::Cpu`]) or only by name.
pub fn is_software_adapter(info: &wgpu::AdapterInfo) -> bool {
    const NAMES: [&str; 4] = [
        "swiftshader",
        "llvmpipe",
        "lavapipe",
        "microsoft basic render",
    ];
    let name = info.name.to_lowercase();
    info.device_type == wgpu::DeviceType::Cpu || NAMES.iter().any(|n| name.contains(n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(name: &str, device_type: wgpu::DeviceType) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: name.into(),
            vendor: 0,
            device: 0,
            device_type,
            device_pci_bus_id: String::new(),
            driver: String::new(),
            driver_info: String::new(),
            backend: wgpu::Backend::BrowserWebGpu,
            subgroup_min_size: 0,
            subgroup_max_size: 0,
            transient_saves_memory: None,
            limit_bucket: None,
        }
    }

    #[test]
    fn software_adapters_are_known_by_kind_or_name() {
        use wgpu::DeviceType::*;
        assert!(is_software_adapter(&info("", Cpu)));
        assert!(is_software_adapter(&info(
            "SwiftShader Device (Subzero)",
            Other
        )));
        assert!(is_software_adapter(&info(
            "llvmpipe (LLVM 19.1.7, 256 bits)",
            Other
        )));
        assert!(is_software_adapter(&info(
            "Microsoft Basic Render Driver",
            Other
        )));
        assert!(!is_software_adapter(&info(
            "NVIDIA H100 80GB HBM3",
            DiscreteGpu
        )));
        assert!(!is_software_adapter(&info("", Other)));
    }
}
