//! The quality record a case glTF carries in `extras`, under [`CASE_KEY`]: per structure its
//! description, provenance (the source file's name, never its header), voxel size, filter, parameters, tau
//! and measures; per scene the case's title and description. Reading a case glTF back turns
//! the record and the meshes into the same case.

use serde_json::{json, Value};

use std::sync::Arc;

use super::{voxel_grid, Case, CaseImage, CaseStructure, Lesson, Smoothed};
use crate::io::{Affine, GltfNode, GltfScene, Mat4, StructureCodes};
use crate::mesh::Mesh;
use crate::metrics::Metrics;
use crate::segmentation::default_color;
use crate::smooth::{Filter, Params};
use crate::srgb;

/// The key of meshsmooth's record in a glTF `extras` object.
pub const CASE_KEY: &str = "meshsmooth";

/// A case glTF whose record cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CaseRecordError {
    #[error("the file holds no mesh")]
    Empty,
    #[error("structure '{name}': {detail}")]
    Structure { name: String, detail: String },
    #[error("the case's image: {0}")]
    Image(String),
    #[error("the case's lesson: {0}")]
    Lesson(String),
}

/// A structure's record: what the platform shows beside it and what reopening restores.
pub fn structure_record(s: &CaseStructure) -> Value {
    let diagonal = s.voxel_diagonal();
    let mut r = json!({
        "source": s.source,
        "label": s.label,
        "group": s.group,
        "description": s.description,
        "visible": s.visible,
        "color": s.color,
        "voxel_size_mm": s.voxel_size,
        "voxel_to_world": s.grid.map(|g| g.0),
        "codes": s.codes,
        "voxels": s.voxels,
        "voxel_diagonal_mm": diagonal,
        "filter": s.params.filter,
        "params": s.params.to_json(),
        "tau": s.tau,
        "smoothed": s.smoothed_now().is_some(),
        "vertices": s.original.vertex_count(),
        "triangles": s.original.triangle_count(),
    });
    if !s.names.is_empty() {
        r["names"] = json!(s.names);
    }
    if let Some(m) = s.smoothed_now().map(|m| &m.metrics) {
        let in_diagonals = |mm: f64| diagonal.map(|d| mm / d);
        r["volume_mm3"] = json!(m.volume);
        r["volume0_mm3"] = json!(m.volume0);
        r["volume_change"] = json!(m.volume_change);
        r["mean_error_mm"] = json!(m.mean_error);
        r["max_error_mm"] = json!(m.max_error);
        r["mean_error_voxel_diagonals"] = json!(in_diagonals(m.mean_error));
        r["max_error_voxel_diagonals"] = json!(in_diagonals(m.max_error));
        r["curvature_ratio"] = json!(m.score_terms().curvature_ratio);
        r["score"] = json!(m.score);
        r["metrics"] = json!(m);
    }
    r
}

/// The case a glTF scene holds: a case written here comes back as it was (names, colours,
/// groups, parameters, measures; the original from the morph target); any other glTF gives a
/// structure per placed mesh, named after its node, placed by its node's transform.
pub fn from_gltf_scene(scene: GltfScene, source: &str) -> Result<Case, CaseRecordError> {
    if scene.nodes.is_empty() {
        return Err(CaseRecordError::Empty);
    }
    let record = scene.extras.as_ref().and_then(|e| e.get(CASE_KEY));
    let text = |key: &str| {
        record
            .and_then(|r| r.get(key))
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_string()
    };
    // Our own files keep the data's millimetres inside the meshes, with the frame's
    // conversion on the root alone: the stored positions are the case's, bit for bit (or, in a
    // compressed file, on a lattice the structure's own node scales to millimetres).
    let ours = record.is_some();
    let image = match (record.and_then(|r| r.get("image")), scene.image_voxels) {
        (Some(r), Some(voxels)) => Some(Arc::new(
            CaseImage::from_record(r, voxels).map_err(CaseRecordError::Image)?,
        )),
        _ => None,
    };
    let lesson = lesson(record, &scene.marked).map_err(CaseRecordError::Lesson)?;
    let structures = scene
        .nodes
        .into_iter()
        .enumerate()
        .map(|(i, node)| structure(node, i, source, ours))
        .collect::<Result<_, _>>()?;
    let case = Case {
        title: text("title"),
        description: text("description"),
        structures,
        image,
        lesson,
    };
    case.lesson.check(&case).map_err(CaseRecordError::Lesson)?;
    Ok(case)
}

/// The lesson of a case written here: the steps and labels from their nodes' records (in the
/// nodes' order), the quiz from the scene's.
fn lesson(record: Option<&Value>, marked: &[Value]) -> Result<Lesson, String> {
    fn each<T: serde::de::DeserializeOwned>(marked: &[Value], key: &str) -> Result<Vec<T>, String> {
        (marked.iter().filter_map(|m| m.get(key)))
            .enumerate()
            .map(|(i, v)| {
                serde_json::from_value(v.clone()).map_err(|e| format!("{key} {}: {e}", i + 1))
            })
            .collect()
    }
    let quiz = match record.and_then(|r| r.get("quiz")) {
        Some(q) => Some(serde_json::from_value(q.clone()).map_err(|e| format!("quiz: {e}"))?),
        None => None,
    };
    Ok(Lesson {
        steps: each(marked, "step")?,
        labels: each(marked, "text_label")?,
        quiz,
    })
}

fn structure(
    node: GltfNode,
    ordinal: usize,
    source: &str,
    ours: bool,
) -> Result<CaseStructure, CaseRecordError> {
    let name = if node.name.is_empty() {
        format!("structure {}", ordinal + 1)
    } else {
        node.name.clone()
    };
    let fail = |detail: String| CaseRecordError::Structure {
        name: name.clone(),
        detail,
    };
    // Ours keep millimetres in the node's frame: a quantized mesh's node scales its lattice.
    let matrix = if ours { node.local } else { node.matrix };
    let (shown, original) = surfaces(&node, &matrix).map_err(|d| fail(d.into()))?;
    let color = node.base_color.map(|[r, g, b, a]| {
        [
            srgb::from_linear(r),
            srgb::from_linear(g),
            srgb::from_linear(b),
            a,
        ]
    });
    let fallback = default_color(ordinal);
    let mut s = CaseStructure::from_mesh(&name, shown.clone(), fallback);
    s.source = Some(source.to_string());
    if let Some(c) = color {
        s.color = c;
    }
    let Some(record) = node.extras.as_ref().and_then(|e| e.get(CASE_KEY)) else {
        return Ok(s);
    };
    read_looks(&mut s, record, &node, ours);
    read_smoothing(&mut s, record).map_err(fail)?;
    if let Some(names) = record.get("names").filter(|v| !v.is_null()) {
        s.names = super::names::from_json(names).map_err(fail)?;
    }
    let smoothed = record.get("smoothed").and_then(Value::as_bool) == Some(true);
    let metrics = record
        .get("metrics")
        .and_then(|m| serde_json::from_value::<Metrics>(m.clone()).ok());
    match (smoothed, original, metrics) {
        (true, Some(original), Some(metrics)) => {
            if original.vertex_count() != shown.vertex_count() {
                return Err(fail("the morph target does not match the surface".into()));
            }
            s.original = original;
            s.keep(Smoothed::new(shown.positions, metrics, node.local_error));
        }
        // Without its original (written without the morph target) the smoothed surface is
        // where the author goes on from.
        _ => s.original = shown,
    }
    let quantized = record
        .pointer("/quantization/max_error_mm")
        .and_then(Value::as_f64);
    if let (Some(grid), Some(error)) = (s.grid, quantized) {
        if let Some(exact) = voxel_grid::on_grid(&s.original.positions, &grid, error * 1.01) {
            s.original.positions = exact;
        }
    }
    Ok(s)
}

/// The node's surface as shown and, where it has a morph target, its original, both placed
/// by `matrix`; an original with a position that is not finite is dropped.
fn surfaces(node: &GltfNode, matrix: &Mat4) -> Result<(Mesh, Option<Mesh>), &'static str> {
    let shown = place(&node.mesh, matrix);
    let finite = |m: &Mesh| m.positions.iter().flatten().all(|v| v.is_finite());
    if !finite(&shown) {
        return Err("a position is not finite after the node's transform");
    }
    let original = node.morph_target.as_ref().and_then(|target| {
        let moved: Vec<[f32; 3]> = (node.mesh.positions.iter().zip(target))
            .map(|(p, d)| [p[0] + d[0], p[1] + d[1], p[2] + d[2]])
            .collect();
        Some(place(
            &Mesh::new(moved, node.mesh.triangles.clone()),
            matrix,
        ))
        .filter(finite)
    });
    Ok((shown, original))
}

/// What the record says of how the structure is shown and where it came from.
fn read_looks(s: &mut CaseStructure, record: &Value, node: &GltfNode, ours: bool) {
    if let Some(c) = floats::<4>(record.get("color")) {
        s.color = c.map(|v| v as f32);
    }
    s.visible = record
        .get("visible")
        .and_then(Value::as_bool)
        .unwrap_or(true);
    s.group = record
        .get("group")
        .and_then(Value::as_str)
        .map(str::to_string)
        .or_else(|| (ours && node.ancestors.len() >= 2).then(|| node.ancestors[1].clone()));
    s.description = (record.get("description").and_then(Value::as_str))
        .unwrap_or_default()
        .to_string();
    s.source = record
        .get("source")
        .and_then(Value::as_str)
        .map(str::to_string)
        .or(s.source.take());
    s.label = record.get("label").and_then(Value::as_i64);
    s.voxel_size = floats::<3>(record.get("voxel_size_mm"));
    s.grid = record.get("voxel_to_world").and_then(grid);
    s.codes = (record.get("codes").cloned())
        .and_then(|c| serde_json::from_value::<StructureCodes>(c).ok());
    s.voxels = record
        .get("voxels")
        .and_then(Value::as_u64)
        .and_then(|v| usize::try_from(v).ok());
}

/// The record's tau, filter and parameters.
fn read_smoothing(s: &mut CaseStructure, record: &Value) -> Result<(), String> {
    if let Some(tau) = record.get("tau").and_then(Value::as_f64) {
        s.tau = tau;
    }
    let filter = record
        .get("filter")
        .and_then(Value::as_str)
        .map(|f| Filter::from_name(f).ok_or_else(|| format!("unknown filter '{f}'")))
        .transpose()?
        .unwrap_or(s.params.filter);
    s.params = match record.get("params") {
        Some(p) => Params::defaults(filter).with_json(p)?,
        None => Params::defaults(filter),
    };
    Ok(())
}

/// A 3 x 4 matrix, row by row.
fn grid(value: &Value) -> Option<Affine> {
    let rows = value.as_array()?;
    if rows.len() != 3 {
        return None;
    }
    let mut m = [[0.0; 4]; 3];
    for (r, row) in m.iter_mut().zip(rows) {
        *r = floats::<4>(Some(row))?;
    }
    Some(Affine(m))
}

fn floats<const N: usize>(value: Option<&Value>) -> Option<[f64; N]> {
    let list = value?.as_array()?;
    if list.len() != N {
        return None;
    }
    let mut out = [0.0; N];
    for (o, v) in out.iter_mut().zip(list) {
        *o = v.as_f64().filter(|v| v.is_finite())?;
    }
    Some(out)
}

const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// The mesh placed by `m`, rounded once to f32; the identity keeps the exact bits, and a
/// mirroring transform has its triangles turned to keep them outward.
fn place(mesh: &Mesh, m: &Mat4) -> Mesh {
    if *m == IDENTITY {
        return mesh.clone();
    }
    let positions = mesh
        .positions
        .iter()
        .map(|p| {
            let [x, y, z] = p.map(f64::from);
            std::array::from_fn(|r| (m[0][r] * x + m[1][r] * y + m[2][r] * z + m[3][r]) as f32)
        })
        .collect();
    let det = m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
    let triangles = if det < 0.0 {
        mesh.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
    } else {
        mesh.triangles.clone()
    };
    Mesh::new(positions, triangles)
}
