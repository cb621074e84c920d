//! The 3D view's shader (shaders/render.wgsl) as the web app loads it: valid WGSL, its `View`
//! struct laid out like the Rust record, and translatable to GLSL ES 3.00, as wgpu does when
//! eframe falls back to WebGL2. No GPU needed.

use meshsmooth::view::{SliceUniforms, ViewUniforms, RENDER_SHADER};

const ENTRY_POINTS: [(&str, naga::ShaderStage); 11] = [
    ("vs_surface", naga::ShaderStage::Vertex),
    ("fs_surface", naga::ShaderStage::Fragment),
    ("fs_surface_cut", naga::ShaderStage::Fragment),
    ("fs_surface_capped", naga::ShaderStage::Fragment),
    ("fs_translucent", naga::ShaderStage::Fragment),
    ("vs_slice", naga::ShaderStage::Vertex),
    ("fs_slice", naga::ShaderStage::Fragment),
    ("vs_wire", naga::ShaderStage::Vertex),
    ("fs_wire", naga::ShaderStage::Fragment),
    ("vs_composite", naga::ShaderStage::Vertex),
    ("fs_composite", naga::ShaderStage::Fragment),
];

fn parse_and_validate(source: &str) -> (naga::Module, naga::valid::ModuleInfo) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("render.wgsl does not parse:\n{}", e.emit_to_string(source)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| {
        panic!(
            "render.wgsl does not validate:\n{}",
            e.emit_to_string(source)
        )
    });
    (module, info)
}

#[test]
fn the_render_shader_validates_with_its_entry_points() {
    let (module, _) = parse_and_validate(RENDER_SHADER);
    let mut found: Vec<(&str, naga::ShaderStage)> = module
        .entry_points
        .iter()
        .map(|e| (e.name.as_str(), e.stage))
        .collect();
    found.sort_by_key(|(name, _)| *name);
    let mut expected = ENTRY_POINTS.to_vec();
    expected.sort_by_key(|(name, _)| *name);
    assert_eq!(found, expected);
}

#[test]
fn the_view_struct_matches_the_rust_record() {
    let (module, _) = parse_and_validate(RENDER_SHADER);
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some("View"))
        .expect("render.wgsl declares `struct View`");
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("View is not a struct");
    };
    assert_eq!(*span as usize, std::mem::size_of::<ViewUniforms>());
    let offsets: Vec<(&str, u32)> = members
        .iter()
        .map(|m| (m.name.as_deref().unwrap_or(""), m.offset))
        .collect();
    let rust = [
        ("view_proj", std::mem::offset_of!(ViewUniforms, view_proj)),
        ("eye", std::mem::offset_of!(ViewUniforms, eye)),
        ("light", std::mem::offset_of!(ViewUniforms, light)),
        ("base_color", std::mem::offset_of!(ViewUniforms, base_color)),
        ("back_tint", std::mem::offset_of!(ViewUniforms, back_tint)),
        ("wire_color", std::mem::offset_of!(ViewUniforms, wire_color)),
        ("background", std::mem::offset_of!(ViewUniforms, background)),
        ("clip", std::mem::offset_of!(ViewUniforms, clip)),
        ("flags", std::mem::offset_of!(ViewUniforms, flags)),
    ];
    let rust: Vec<(&str, u32)> = rust.iter().map(|&(n, o)| (n, o as u32)).collect();
    assert_eq!(offsets, rust);
}

#[test]
fn the_slice_struct_matches_the_rust_record() {
    let (module, _) = parse_and_validate(RENDER_SHADER);
    let (_, ty) = (module.types.iter())
        .find(|(_, ty)| ty.name.as_deref() == Some("Slice"))
        .expect("render.wgsl declares `struct Slice`");
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("Slice is not a struct");
    };
    assert_eq!(*span as usize, std::mem::size_of::<SliceUniforms>());
    let offsets: Vec<(&str, u32)> = (members.iter())
        .map(|m| (m.name.as_deref().unwrap_or(""), m.offset))
        .collect();
    let rust = [
        (
            "world_to_texture",
            std::mem::offset_of!(SliceUniforms, world_to_texture),
        ),
        ("corners", std::mem::offset_of!(SliceUniforms, corners)),
    ];
    let rust: Vec<(&str, u32)> = rust.iter().map(|&(n, o)| (n, o as u32)).collect();
    assert_eq!(offsets, rust);
}

#[test]
fn every_entry_point_translates_to_webgl2_glsl() {
    use naga::back::glsl;
    let (module, info) = parse_and_validate(RENDER_SHADER);
    let options = glsl::Options {
        version: glsl::Version::Embedded {
            version: 300,
            is_webgl: true,
        },
        writer_flags: glsl::WriterFlags::ADJUST_COORDINATE_SPACE,
        ..Default::default()
    };
    for (name, stage) in ENTRY_POINTS {
        let pipeline = glsl::PipelineOptions {
            shader_stage: stage,
            entry_point: name.to_string(),
            multiview: None,
        };
        let mut out = String::new();
        glsl::Writer::new(
            &mut out,
            &module,
            &info,
            &options,
            &pipeline,
            naga::proc::BoundsCheckPolicies::default(),
        )
        .and_then(|mut w| w.write())
        .unwrap_or_else(|e| panic!("{name} does not translate to GLSL ES 3.00: {e}"));
        assert!(out.starts_with("#version 300 es"), "{name}:\n{out}");
        // No storage buffers on WebGL2: the view's data is one uniform block.
        assert!(
            !out.contains("buffer "),
            "{name} uses a storage buffer:\n{out}"
        );
    }
}
