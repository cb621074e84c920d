//! A GLB of several named, coloured surfaces (the structures of a segmentation): a root node
//! that carries the data's frame into glTF's, and under it a named node, mesh and material per
//! surface.
//!
//! Data come in RAS millimetres; glTF viewers read metres with +Y up. The root node scales by
//! 1/1000 and turns superior to +Y and anterior to +Z (a viewer at +Z faces the patient), which
//! leaves the patient's left at +X: a proper rotation, so no winding changes.

use serde_json::{json, Value};

use super::glb::{
    container, geometry, index_bytes, Builder, ELEMENT_ARRAY_BUFFER, TRIANGLES, UNSIGNED_INT,
};
use super::{check, ExportError, ExportOptions};
use crate::mesh::Mesh;

/// Which frame the file's coordinates are in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneFrame {
    /// Metres with +Y up, as glTF defines (the root node converts RAS millimetres).
    Gltf,
    /// The data's own RAS millimetres, untouched (for pipelines that expect them).
    Millimetres,
}

/// One surface of a scene.
#[derive(Clone, Debug)]
pub struct SceneMesh<'a> {
    pub name: &'a str,
    /// Display (sRGB) colour and opacity, each in [0, 1].
    pub color: [f32; 4],
    pub mesh: &'a Mesh,
    /// Unit per-vertex normals (written when given).
    pub normals: Option<&'a [[f32; 3]]>,
    /// JSON kept as the node's `extras`.
    pub extras: Option<Value>,
}

/// The root node's matrix (column-major) from RAS millimetres to glTF metres, +Y up.
const RAS_MM_TO_GLTF: [f64; 16] = [
    -0.001, 0.0, 0.0, 0.0, // R -> -X
    0.0, 0.0, 0.001, 0.0, // A -> +Z
    0.0, 0.001, 0.0, 0.0, // S -> +Y
    0.0, 0.0, 0.0, 1.0,
];

/// Converts a display (sRGB) channel to glTF's linear factor.
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Serialises the surfaces as one GLB; `extras` goes on the scene.
pub fn write_scene_glb(
    items: &[SceneMesh],
    extras: Option<Value>,
    frame: SceneFrame,
) -> Result<Vec<u8>, ExportError> {
    let mut b = Builder::default();
    let mut nodes = vec![json!({})];
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    for item in items {
        let options = ExportOptions {
            normals: item.normals,
            ..Default::default()
        };
        check(item.mesh, &options)?;
        let index = meshes.len();
        meshes.push(json!({
            "name": item.name,
            "primitives": [primitive(&mut b, item, index)],
        }));
        materials.push(material(item));
        let mut node = json!({ "name": item.name, "mesh": index });
        if let Some(extras) = &item.extras {
            node["extras"] = extras.clone();
        }
        nodes.push(node);
    }
    let mut root = json!({
        "name": "segmentation",
        "children": (1..nodes.len()).collect::<Vec<_>>(),
    });
    if frame == SceneFrame::Gltf {
        root["matrix"] = json!(RAS_MM_TO_GLTF);
    }
    nodes[0] = root;
    let mut scene = json!({ "nodes": [0] });
    if let Some(extras) = extras {
        scene["extras"] = extras;
    }
    let document = json!({
        "asset": { "version": "2.0", "generator": "meshsmooth" },
        "scene": 0,
        "scenes": [scene],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{ "byteLength": b.bin.len() }],
    });
    container(&document, b.bin).ok_or_else(|| ExportError::TooLarge {
        format: "GLB",
        detail: "the file would exceed the 4 GiB a GLB header can describe".into(),
    })
}

/// The triangle primitive of one surface, its arrays appended to the BIN chunk.
fn primitive(b: &mut Builder, item: &SceneMesh, material: usize) -> Value {
    let attributes = geometry(b, item.mesh, item.normals);
    let indices = b.push(
        &index_bytes(item.mesh),
        ELEMENT_ARRAY_BUFFER,
        json!({"componentType": UNSIGNED_INT, "count": 3 * item.mesh.triangle_count(), "type": "SCALAR"}),
    );
    json!({ "attributes": attributes, "indices": indices, "material": material, "mode": TRIANGLES })
}

/// A surface's material: its colour as glTF's linear base colour, blended when translucent.
fn material(item: &SceneMesh) -> Value {
    let [r, g, b, a] = item.color;
    let alpha = a.clamp(0.0, 1.0);
    let mut m = json!({
        "name": item.name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), alpha],
            "metallicFactor": 0.0,
            "roughnessFactor": 0.6,
        },
    });
    if alpha < 1.0 {
        m["alphaMode"] = json!("BLEND");
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Mesh {
        Mesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    fn document(bytes: &[u8]) -> Value {
        let len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
        serde_json::from_slice(&bytes[20..20 + len]).expect("JSON")
    }

    #[test]
    fn a_node_mesh_and_material_per_surface_under_a_converting_root() {
        let (a, b) = (tetra(), tetra());
        let items = [
            SceneMesh {
                name: "liver",
                color: [1.0, 0.5, 0.0, 1.0],
                mesh: &a,
                normals: None,
                extras: Some(json!({"label": 1})),
            },
            SceneMesh {
                name: "tumour",
                color: [0.0, 0.0, 0.0, 0.5],
                mesh: &b,
                normals: None,
                extras: None,
            },
        ];
        let doc = document(&write_scene_glb(&items, None, SceneFrame::Gltf).expect("writes"));
        assert_eq!(doc["nodes"][0]["children"], json!([1, 2]));
        assert_eq!(doc["nodes"][0]["matrix"][1], json!(0.0));
        assert_eq!(doc["nodes"][1]["name"], "liver");
        assert_eq!(doc["nodes"][1]["extras"]["label"], 1);
        assert_eq!(doc["meshes"][1]["name"], "tumour");
        let liver = &doc["materials"][0];
        assert_eq!(liver["pbrMetallicRoughness"]["baseColorFactor"][0], 1.0);
        let half = liver["pbrMetallicRoughness"]["baseColorFactor"][1]
            .as_f64()
            .expect("a number");
        assert!(
            (half - 0.214).abs() < 1e-3,
            "sRGB 0.5 is linear 0.214: {half}"
        );
        assert!(liver.get("alphaMode").is_none());
        assert_eq!(doc["materials"][1]["alphaMode"], "BLEND");
        let raw = document(&write_scene_glb(&items, None, SceneFrame::Millimetres).expect("ok"));
        assert!(raw["nodes"][0].get("matrix").is_none());
    }

    #[test]
    fn the_root_turns_superior_up_and_anterior_forward_without_mirroring() {
        let m = |v: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|r| (0..3).map(|c| RAS_MM_TO_GLTF[4 * c + r] * v[c]).sum())
        };
        assert_eq!(m([0.0, 0.0, 1000.0]), [0.0, 1.0, 0.0]);
        assert_eq!(m([0.0, 1000.0, 0.0]), [0.0, 0.0, 1.0]);
        assert_eq!(m([1000.0, 0.0, 0.0]), [-1.0, 0.0, 0.0]);
        let c = |i: usize| {
            [
                RAS_MM_TO_GLTF[4 * i],
                RAS_MM_TO_GLTF[4 * i + 1],
                RAS_MM_TO_GLTF[4 * i + 2],
            ]
        };
        let (x, y, z) = (c(0), c(1), c(2));
        let det = x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0])
            + x[2] * (y[0] * z[1] - y[1] * z[0]);
        assert!(det > 0.0);
    }
}
