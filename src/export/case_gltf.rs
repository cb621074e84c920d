//! The case glTF: one scene holding every structure of a case, as a learning platform shows it.
//!
//! A root node carries the data's RAS millimetres into glTF's metres with +Y up: it scales by
//! 1/1000 and turns superior to +Y and anterior to +Z (a viewer at +Z faces the patient), which
//! leaves the patient's left at +X, a proper rotation, so no winding changes. Under it a node
//! per group, and under those (or the root) a named node, mesh and material per structure.
//! Positions stay in millimetres inside the meshes, so reading an uncompressed case back is
//! exact; a compressed one (the default: see `compressed`) keeps them on a quantization lattice
//! that each structure's own node scales to millimetres.
//!
//! Each structure's node carries its quality record in `extras` (see `case::record`); the
//! original staircase can ride along as a morph target (a viewer's weight slides from the
//! segmentation to the smoothed surface, and a reopened case can be smoothed again), and the
//! local error as the vertex attribute `_LOCAL_ERROR`.

use base64::Engine as _;
use rayon::prelude::*;
use serde_json::{json, Value};

use super::case_lesson::{label_node, step_camera};
use super::compressed::{self, Lattice, Placement, Surfaces};
use super::glb::{
    container, floats, geometry, index_bytes, Builder, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, FLOAT,
    MESHOPT, TRIANGLES, UNSIGNED_INT,
};
use super::simplified::{
    record as simplification_record, simplify_structure, written, Simplification, Written,
};
use super::{check, ExportError, ExportOptions};
use crate::case::{structure_record, Case, CaseStructure, CASE_KEY};
use crate::mesh::{bounding_box, vertex_normals, Mesh};
use crate::simplify::Simplified;
use crate::srgb;

const QUANTIZATION: &str = "KHR_mesh_quantization";

/// Which frame the file's coordinates are in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneFrame {
    /// Metres with +Y up, as glTF defines (the root node converts RAS millimetres).
    Gltf,
    /// The data's own RAS millimetres, untouched (for pipelines that expect them).
    Millimetres,
}

impl SceneFrame {
    pub fn name(self) -> &'static str {
        match self {
            SceneFrame::Gltf => "gltf",
            SceneFrame::Millimetres => "millimetres",
        }
    }
}

/// `.glb`, or `.gltf` with its buffer embedded as a data URI.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    Glb,
    Gltf,
}

/// What a case glTF carries beyond the structures' surfaces, materials and records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaseGltfOptions {
    pub frame: SceneFrame,
    pub container: Container,
    /// The original surface as each smoothed structure's morph target.
    pub original_as_morph_target: bool,
    /// The local error (mm) as the vertex attribute `_LOCAL_ERROR`, where measured.
    pub local_error: bool,
    /// `KHR_materials_unlit`: colours show exactly as chosen, without lighting.
    pub unlit: bool,
    /// Quantized (`KHR_mesh_quantization`) and compressed (`EXT_meshopt_compression`); else
    /// float arrays as they are, for tools that cannot decode.
    pub compressed: bool,
    /// Simplified surfaces for the download; else each as smoothed.
    pub simplify: Option<Simplification>,
}

impl Default for CaseGltfOptions {
    fn default() -> Self {
        Self {
            frame: SceneFrame::Gltf,
            container: Container::Glb,
            original_as_morph_target: true,
            local_error: false,
            unlit: false,
            compressed: true,
            simplify: None,
        }
    }
}

/// The root node's matrix (column-major) from RAS millimetres to glTF metres, +Y up.
pub const RAS_MM_TO_GLTF: [f64; 16] = [
    -0.001, 0.0, 0.0, 0.0, // R -> -X
    0.0, 0.0, 0.001, 0.0, // A -> +Z
    0.0, 0.001, 0.0, 0.0, // S -> +Y
    0.0, 0.0, 0.0, 1.0,
];

/// A case glTF written one structure at a time: the CLI adds every structure at once, the page
/// one per frame, showing how far it got and the file's size so far.
pub struct CaseWriter {
    options: CaseGltfOptions,
    b: Builder,
    /// The root first (filled in at the end), then each structure, with a node per group
    /// after its first structure.
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    root_children: Vec<usize>,
    group_nodes: Vec<(String, usize)>,
    /// Each structure's node and the lattice it scales (where compressed): its labels' frame.
    structure_nodes: Vec<(usize, Option<Lattice>)>,
    /// Triangles in the case before simplification (a triangle budget's share of each).
    case_triangles: usize,
    triangles: usize,
}

impl CaseWriter {
    /// A writer for `case`; errors when it has no structure or would not fit a GLB.
    pub fn new(case: &Case, options: &CaseGltfOptions) -> Result<Self, ExportError> {
        if case.structures.is_empty() {
            return Err(ExportError::NoTriangles);
        }
        let estimate: u64 = (case.structures.iter())
            .map(|s| {
                s.original.vertex_count() as u64 * 44 + s.original.triangle_count() as u64 * 12
            })
            .sum();
        if estimate > u64::from(u32::MAX) {
            return Err(too_large());
        }
        case.lesson.check(case).map_err(ExportError::Lesson)?;
        Ok(Self {
            options: *options,
            b: Builder::default(),
            nodes: vec![json!({})],
            meshes: Vec::new(),
            materials: Vec::new(),
            root_children: Vec::new(),
            group_nodes: Vec::new(),
            structure_nodes: Vec::new(),
            case_triangles: (case.structures.iter())
                .map(|s| s.original.triangle_count())
                .sum(),
            triangles: 0,
        })
    }

    /// Structures written so far.
    pub fn structures(&self) -> usize {
        self.meshes.len()
    }

    /// Triangles written so far.
    pub fn triangles(&self) -> usize {
        self.triangles
    }

    /// Bytes of the binary buffer so far (the file adds its JSON to them).
    pub fn buffer_bytes(&self) -> usize {
        self.b.bin.len()
    }

    /// Writes the next structure, `s` (simplified first when the options say so).
    pub fn add(&mut self, s: &CaseStructure) -> Result<(), ExportError> {
        let part = Part::of(s, self.meshes.len(), &self.options, self.case_triangles)?;
        self.add_part(s, part);
        Ok(())
    }

    /// Adds structure `s`'s part, written for the next structure's place.
    fn add_part(&mut self, s: &CaseStructure, part: Part) {
        let Part {
            b,
            mut mesh,
            placement,
            simplified,
            triangles,
        } = part;
        let options = self.options;
        let index = self.meshes.len();
        shift_accessors(&mut mesh, self.b.append(b));
        self.triangles += triangles;
        self.meshes.push(mesh);
        self.materials.push(material(s, options.unlit));
        let mut record = structure_record(s);
        if let Some(how) = options.simplify {
            record["simplification"] = simplification_record(s, how, simplified.as_ref());
        }
        if let Some(color) = s.color.get(..3) {
            record["color"] = json!([color[0], color[1], color[2], s.color[3]]);
        }
        let mut node = json!({ "name": s.name, "mesh": index });
        let lattice = placement.as_ref().map(|p| p.lattice);
        if let Some(Placement { lattice, record: q }) = placement {
            // The lattice's stored integers to millimetres, under the root's frame.
            node["translation"] = json!(lattice.offset);
            node["scale"] = json!([lattice.step, lattice.step, lattice.step]);
            record["quantization"] = q;
        }
        node["extras"] = json!({ CASE_KEY: record });
        self.nodes.push(node);
        let node = self.nodes.len() - 1;
        self.structure_nodes.push((node, lattice));
        match s.group.as_deref() {
            None => self.root_children.push(node),
            Some(group) => match self.group_nodes.iter().find(|(g, _)| g == group) {
                Some(&(_, g)) => push_child(&mut self.nodes[g], node),
                None => {
                    self.nodes
                        .push(json!({ "name": group, "children": [node] }));
                    self.group_nodes
                        .push((group.to_string(), self.nodes.len() - 1));
                    self.root_children.push(self.nodes.len() - 1);
                }
            },
        }
    }

    /// The file, once every structure of `case` is written.
    pub fn finish(mut self, case: &Case) -> Result<Vec<u8>, ExportError> {
        let title = if case.title.is_empty() {
            "case"
        } else {
            &case.title
        };
        let mut root = json!({ "name": title, "children": self.root_children });
        if self.options.frame == SceneFrame::Gltf {
            root["matrix"] = json!(RAS_MM_TO_GLTF);
        }
        self.nodes[0] = root;
        self.add_labels(case);
        let (cameras, camera_nodes) = self.add_steps(case);
        let mut record = json!({
            "title": case.title,
            "description": case.description,
            "frame": self.options.frame.name(),
            "units": "mm",
            "structures": case.structures.len(),
        });
        if let Some(image) = &case.image {
            record["image"] = image.record(self.b.push_blob(&image.voxels));
        }
        if let Some(quiz) = &case.lesson.quiz {
            record["quiz"] = json!(quiz);
        }
        let scene = json!({
            "name": title,
            "nodes": std::iter::once(0).chain(camera_nodes).collect::<Vec<_>>(),
            "extras": { CASE_KEY: record },
        });
        let mut document = json!({
            "asset": { "version": "2.0", "generator": concat!("meshsmooth ", env!("CARGO_PKG_VERSION")) },
            "scene": 0,
            "scenes": [scene],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.b.accessors,
            "bufferViews": self.b.views,
        });
        if !cameras.is_empty() {
            document["cameras"] = json!(cameras);
        }
        finish(document, self.b, &self.options)
    }

    /// Each label's node under its structure's node.
    fn add_labels(&mut self, case: &Case) {
        for label in &case.lesson.labels {
            let structure = (case.structures.iter()).position(|s| s.name == label.structure);
            let Some(&(parent, lattice)) = structure.and_then(|i| self.structure_nodes.get(i))
            else {
                continue;
            };
            self.nodes.push(label_node(label, lattice));
            let node = self.nodes.len() - 1;
            if self.nodes[parent].get("children").is_none() {
                self.nodes[parent]["children"] = json!([]);
            }
            push_child(&mut self.nodes[parent], node);
        }
    }

    /// Each tour step's camera, and its node (for the scene's top level).
    fn add_steps(&mut self, case: &Case) -> (Vec<Value>, Vec<usize>) {
        let mut cameras = Vec::new();
        let mut nodes = Vec::new();
        for step in &case.lesson.steps {
            let (camera, node) = step_camera(step, cameras.len(), self.options.frame);
            cameras.push(camera);
            self.nodes.push(node);
            nodes.push(self.nodes.len() - 1);
        }
        (cameras, nodes)
    }
}

/// Serialises the case, its structures simplified and written in parallel where threads are.
pub fn write_case(case: &Case, options: &CaseGltfOptions) -> Result<Vec<u8>, ExportError> {
    let mut writer = CaseWriter::new(case, options)?;
    let parts: Vec<Result<Part, ExportError>> = (case.structures.par_iter().enumerate())
        .map(|(i, s)| Part::of(s, i, options, writer.case_triangles))
        .collect();
    for (s, part) in case.structures.iter().zip(parts) {
        writer.add_part(s, part?);
    }
    writer.finish(case)
}

/// A structure's share of the file, written on its own (on any thread): its arrays in a
/// builder of their own, its mesh naming them, where its lattice places it, and what
/// simplification made of it.
struct Part {
    b: Builder,
    mesh: Value,
    placement: Option<Placement>,
    simplified: Option<Simplified>,
    triangles: usize,
}

impl Part {
    /// Structure `s`'s part, for the structure and material numbered `index`.
    fn of(
        s: &CaseStructure,
        index: usize,
        options: &CaseGltfOptions,
        case_triangles: usize,
    ) -> Result<Part, ExportError> {
        let simplified =
            (options.simplify).and_then(|how| simplify_structure(s, how, case_triangles));
        let surfaces = written(s, simplified.as_ref(), options.local_error);
        let mut b = Builder::default();
        let (mesh, placement) = structure_mesh(&mut b, s, &surfaces, index, options)?;
        Ok(Part {
            b,
            mesh,
            placement,
            simplified,
            triangles: surfaces.shown.triangle_count(),
        })
    }
}

/// Moves the accessor indices a mesh's primitives name (attributes, indices, morph targets)
/// on by `by`: its part's accessors now follow the structures' before it.
fn shift_accessors(mesh: &mut Value, by: usize) {
    let bump = |v: &mut Value| {
        if let Some(i) = v.as_u64() {
            *v = json!(i as usize + by);
        }
    };
    let bump_all = |arrays: Option<&mut Value>| {
        for v in arrays
            .and_then(Value::as_object_mut)
            .into_iter()
            .flat_map(|m| m.values_mut())
        {
            bump(v);
        }
    };
    let primitives = mesh.get_mut("primitives").and_then(Value::as_array_mut);
    for primitive in primitives.into_iter().flatten() {
        if let Some(indices) = primitive.get_mut("indices") {
            bump(indices);
        }
        bump_all(primitive.get_mut("attributes"));
        let targets = primitive.get_mut("targets").and_then(Value::as_array_mut);
        for target in targets.into_iter().flatten() {
            bump_all(Some(target));
        }
    }
}

/// The document with its extensions and buffers, in its container.
fn finish(
    mut document: Value,
    b: Builder,
    options: &CaseGltfOptions,
) -> Result<Vec<u8>, ExportError> {
    let mut used = Vec::new();
    if options.compressed {
        used = vec![MESHOPT, QUANTIZATION];
        document["extensionsRequired"] = json!(used);
    }
    if options.unlit {
        used.push("KHR_materials_unlit");
    }
    if !used.is_empty() {
        document["extensionsUsed"] = json!(used);
    }
    // Compressed views declare their uncompressed place in a fallback buffer with no data.
    let fallback = options.compressed.then(
        || json!({ "byteLength": b.fallback, "extensions": { MESHOPT: { "fallback": true } } }),
    );
    match options.container {
        Container::Glb => {
            let buffers: Vec<Value> = std::iter::once(json!({ "byteLength": b.bin.len() }))
                .chain(fallback)
                .collect();
            document["buffers"] = json!(buffers);
            container(&document, b.bin).ok_or_else(too_large)
        }
        Container::Gltf => {
            let data = base64::engine::general_purpose::STANDARD.encode(&b.bin);
            let buffer = json!({
                "byteLength": b.bin.len(),
                "uri": format!("data:application/octet-stream;base64,{data}"),
            });
            let buffers: Vec<Value> = std::iter::once(buffer).chain(fallback).collect();
            document["buffers"] = json!(buffers);
            serde_json::to_vec_pretty(&document).map_err(|e| ExportError::TooLarge {
                format: "glTF",
                detail: e.to_string(),
            })
        }
    }
}

fn too_large() -> ExportError {
    ExportError::TooLarge {
        format: "GLB",
        detail: "the file would exceed the 4 GiB a GLB header can describe".into(),
    }
}

fn push_child(node: &mut Value, child: usize) {
    if let Some(children) = node["children"].as_array_mut() {
        children.push(json!(child));
    }
}

/// A structure's mesh: the surface as shown, its normals, and the optional morph target and
/// local error; compressed, with where its lattice places it.
fn structure_mesh(
    b: &mut Builder,
    s: &CaseStructure,
    w: &Written,
    material: usize,
    options: &CaseGltfOptions,
) -> Result<(Value, Option<Placement>), ExportError> {
    let shown = &w.shown;
    let normals = vertex_normals(&shown.positions, &shown.triangles);
    check(
        shown,
        &ExportOptions {
            normals: Some(&normals),
            ..Default::default()
        },
    )?;
    let morph = options.original_as_morph_target && s.smoothed_now().is_some();
    let local_error = w.local_error.as_deref();
    if options.compressed {
        let surfaces = Surfaces {
            shown,
            normals: &normals,
            original: morph.then_some(&w.original),
            local_error,
            voxel_diagonal: s.voxel_diagonal(),
        };
        let (primitive, placement) = compressed::structure_mesh(b, &surfaces, material)?;
        return Ok((mesh_of(s, primitive, morph), Some(placement)));
    }
    let mut attributes = geometry(b, shown, Some(&normals));
    let n = shown.vertex_count();
    if let Some(errors) = local_error {
        let bytes: Vec<u8> = errors.iter().flat_map(|v| v.to_le_bytes()).collect();
        attributes["_LOCAL_ERROR"] = json!(b.push(
            &bytes,
            ARRAY_BUFFER,
            json!({"componentType": FLOAT, "count": n, "type": "SCALAR"}),
        ));
    }
    let indices = b.push(
        &index_bytes(shown),
        ELEMENT_ARRAY_BUFFER,
        json!({"componentType": UNSIGNED_INT, "count": 3 * shown.triangle_count(), "type": "SCALAR"}),
    );
    let mut primitive = json!({
        "attributes": attributes, "indices": indices, "material": material, "mode": TRIANGLES,
    });
    if morph {
        primitive["targets"] = json!([morph_target(b, &w.original, shown, &normals)]);
    }
    Ok((mesh_of(s, primitive, morph), None))
}

/// The glTF mesh around a structure's primitive; with a morph target, its weight at the
/// smoothed surface and its name.
fn mesh_of(s: &CaseStructure, primitive: Value, morph: bool) -> Value {
    let mut mesh = json!({ "name": s.name });
    if morph {
        mesh["weights"] = json!([0.0]);
        mesh["extras"] = json!({ "targetNames": ["segmentation"] });
    }
    mesh["primitives"] = json!([primitive]);
    mesh
}

/// The original as displacements from the shown surface (positions and normals).
fn morph_target(b: &mut Builder, original: &Mesh, shown: &Mesh, normals: &[[f32; 3]]) -> Value {
    let delta = |a: &[[f32; 3]], b: &[[f32; 3]]| -> Vec<[f32; 3]> {
        a.iter()
            .zip(b)
            .map(|(p, q)| [p[0] - q[0], p[1] - q[1], p[2] - q[2]])
            .collect()
    };
    let moves: Vec<[f32; 3]> = original
        .positions
        .iter()
        .zip(&shown.positions)
        .map(|(o, s)| std::array::from_fn(|k| displacement(s[k], o[k])))
        .collect();
    let (min, max) = bounding_box(&moves).unwrap_or_default();
    let position = b.push(
        &floats(&moves),
        ARRAY_BUFFER,
        json!({"componentType": FLOAT, "count": moves.len(), "type": "VEC3",
               "min": min.map(f64::from), "max": max.map(f64::from)}),
    );
    let unit = super::glb::unit_normals(&vertex_normals(&original.positions, &original.triangles));
    let turns = delta(&unit, &super::glb::unit_normals(normals));
    let normal = b.push(
        &floats(&turns),
        ARRAY_BUFFER,
        json!({"componentType": FLOAT, "count": turns.len(), "type": "VEC3"}),
    );
    json!({ "POSITION": position, "NORMAL": normal })
}

/// The f32 step from `shown` to `original` that a reader adding it in f32 lands exactly on
/// `original` with, where one exists (the plain difference misses by an ulp now and then; near
/// zero no step may hit it, and the nearest is kept).
fn displacement(shown: f32, original: f32) -> f32 {
    let d = original - shown;
    [d, d.next_up(), d.next_down()]
        .into_iter()
        .find(|&step| shown + step == original)
        .unwrap_or(d)
}

/// A structure's material: its colour as glTF's linear base colour, blended when translucent.
fn material(s: &CaseStructure, unlit: bool) -> Value {
    let [r, g, b, a] = s.color;
    let alpha = a.clamp(0.0, 1.0);
    let mut m = json!({
        "name": s.name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [srgb::to_linear(r), srgb::to_linear(g), srgb::to_linear(b), alpha],
            "metallicFactor": 0.0,
            "roughnessFactor": 0.6,
        },
        "doubleSided": alpha < 1.0,
    });
    if alpha < 1.0 {
        m["alphaMode"] = json!("BLEND");
    }
    if unlit {
        m["extensions"] = json!({ "KHR_materials_unlit": {} });
    }
    m
}
