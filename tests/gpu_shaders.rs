//! Every WGSL file under shaders/ validated with naga, as the runtime assembles and loads it
//! (no GPU needed).

use meshsmooth::gpu::shaders::{KERNELS, PRELUDE_FILES};
use meshsmooth::gpu::WORKGROUP_SIZE;

fn validate(name: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name} does not parse:\n{}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name} does not validate:\n{}", e.emit_to_string(source)));
    module
}

#[test]
fn every_kernel_validates_with_its_entry_points_and_workgroup_size() {
    for kernel in KERNELS {
        let module = validate(kernel.file, &kernel.source());
        let mut found: Vec<&str> = module
            .entry_points
            .iter()
            .map(|e| e.name.as_str())
            .collect();
        found.sort_unstable();
        let mut expected = kernel.entry_points.to_vec();
        expected.sort_unstable();
        assert_eq!(found, expected, "{}", kernel.file);
        for entry in &module.entry_points {
            assert_eq!(entry.stage, naga::ShaderStage::Compute, "{}", entry.name);
            // The Rust side sizes its dispatches with WORKGROUP_SIZE.
            assert_eq!(
                entry.workgroup_size,
                [WORKGROUP_SIZE, 1, 1],
                "{}: {}",
                kernel.file,
                entry.name
            );
        }
    }
}

#[test]
fn every_wgsl_file_is_loaded_by_the_runtime() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders");
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .expect("shaders/ exists")
        .map(|e| {
            e.expect("readable entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|name| name.ends_with(".wgsl"))
        .collect();
    files.sort();
    let mut loaded: Vec<String> = KERNELS.iter().map(|k| k.file.to_string()).collect();
    loaded.extend(PRELUDE_FILES.iter().map(|f| f.to_string()));
    // The 3D view's shader; tests/render_shader.rs validates it.
    loaded.push("render.wgsl".to_string());
    loaded.sort();
    loaded.dedup();
    assert_eq!(files, loaded);
}

#[test]
fn a_broken_kernel_is_caught() {
    // The check above can fail: a kernel that writes a read-only binding does not validate.
    let source = KERNELS[0].source().replace(
        "moved[i] = vec4<f32>(out, 0.0);",
        "moved[i] = vec4<f32>(out, 0.0);\n    gathered[i] = vec4<f32>(out, 0.0);",
    );
    assert_ne!(source, KERNELS[0].source());
    let parsed = naga::front::wgsl::parse_str(&source);
    let valid = parsed.map(|m| {
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&m)
        .is_ok()
    });
    assert!(!matches!(valid, Ok(true)));
}
