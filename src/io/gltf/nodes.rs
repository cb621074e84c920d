//! A glTF scene read node by node: each placed mesh with its node's name, the names of the
//! nodes above it, its world transform, material colour, first morph target, `_LOCAL_ERROR`
//! and `extras`, its positions as stored (not transformed), so that a case written here reads
//! back bit for bit. What a case is made of them is the case module's business.

use std::borrow::Cow;

use ::gltf::json::mesh::Semantic;
use ::gltf::json::validation::Checked;
use ::gltf::json::Root;
use serde_json::Value;

use super::accessor::{layout, load_buffers, read_vectors, view_bytes, Layout};
use super::assemble::merge_loaded;
use super::meshopt::Compression;
use super::scene::{instances, Instance, Mat4, IDENTITY};
use super::{glb, Format, LoadError, Location};
use crate::mesh::Mesh;

/// The meshes of a glTF scene, one per node that places one.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfScene {
    /// The scene's `extras`.
    pub extras: Option<Value>,
    pub nodes: Vec<GltfNode>,
    /// The bytes of the buffer view a case's image names (`extras.meshsmooth.image.bufferView`).
    pub image_voxels: Option<Vec<u8>>,
    /// What meshsmooth's own nodes without a mesh hold (`extras.meshsmooth`: a tour step's
    /// camera, a label), in the nodes' order.
    pub marked: Vec<Value>,
}

/// One node's mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfNode {
    /// The node's name, else its mesh's, else empty.
    pub name: String,
    /// The names of the nodes above it, outermost first (empty for unnamed ones).
    pub ancestors: Vec<String>,
    /// Node space to the scene's world (column-major, `m[column][row]`).
    pub matrix: Mat4,
    /// The node's own transform, the part of `matrix` below its parent (in a case written
    /// here, the quantization lattice to millimetres; else the identity).
    pub local: Mat4,
    /// Every triangle primitive of the mesh, positions in node space as stored.
    pub mesh: Mesh,
    /// The first morph target's position displacements (a one-primitive mesh only).
    pub morph_target: Option<Vec<[f32; 3]>>,
    /// The `_LOCAL_ERROR` attribute (a one-primitive mesh only).
    pub local_error: Option<Vec<f32>>,
    /// The first primitive's material: its base colour factor (linear) and its name.
    pub base_color: Option<[f32; 4]>,
    pub extras: Option<Value>,
}

/// Reads the scene of a `.glb` or `.gltf` (the bytes decide).
pub fn read_scene(bytes: &[u8], format: Format) -> Result<GltfScene, LoadError> {
    let (format, json, json_offset, bin) = if bytes.starts_with(b"glTF") {
        let g = glb::split(bytes)?;
        (Format::Glb, g.json, g.json_offset, g.bin)
    } else {
        (format, bytes, 0, None)
    };
    let root = super::document(json, json_offset, format)?;
    let compression = Compression::parse(json, &root, format)?;
    let placed = instances(&root, format)?;
    // Every buffer and decoded view but the fallbacks, which hold no data.
    let needed: Vec<bool> = (0..compression.buffer_count())
        .map(|i| !compression.is_fallback(i))
        .collect();
    let buffers = load_buffers(&root, &compression, bin, &needed, format)?;
    let parents = parents(&root);
    let document = (&root, &compression);
    let nodes = (placed.iter())
        .map(|instance| read_node(document, &parents, &buffers, instance, format))
        .collect::<Result<_, _>>()?;
    let scene = root.scene.map_or(0, |s| s.value());
    let extras = root
        .scenes
        .get(scene)
        .and_then(|s| raw_json(s.extras.as_deref()));
    let image_view = (extras.as_ref()).and_then(|e| {
        e.get("meshsmooth")?
            .get("image")?
            .get("bufferView")?
            .as_u64()
    });
    let image_voxels = match image_view {
        Some(view) => {
            let view = usize::try_from(view).unwrap_or(usize::MAX);
            Some(view_bytes(&root, &compression, &buffers, view, format)?.to_vec())
        }
        None => None,
    };
    let marked = (root.nodes.iter())
        .filter(|n| n.mesh.is_none())
        .filter_map(|n| {
            raw_json(n.extras.as_deref())?
                .get_mut("meshsmooth")
                .map(Value::take)
        })
        .collect();
    Ok(GltfScene {
        extras,
        nodes,
        image_voxels,
        marked,
    })
}

/// One placed mesh of the scene as a node: its mesh in its own frame, its morph target and
/// local error where it has one primitive, its material's colour, names and extras.
fn read_node(
    (root, compression): (&Root, &Compression),
    parents: &[Option<usize>],
    buffers: &[Option<Cow<[u8]>>],
    instance: &Instance,
    format: Format,
) -> Result<GltfNode, LoadError> {
    let local = Instance {
        matrix: IDENTITY,
        ..instance.clone()
    };
    let mesh = merge_loaded(
        root,
        compression,
        std::slice::from_ref(&local),
        buffers,
        format,
    )?;
    let gltf_mesh = &root.meshes[instance.mesh];
    let node = &root.nodes[instance.node];
    let single = match gltf_mesh.primitives.as_slice() {
        [p] => Some(p),
        _ => None,
    };
    let data = |l: &Layout| -> Result<&[u8], LoadError> {
        buffers
            .get(l.buffer)
            .and_then(|b| b.as_deref())
            .ok_or_else(|| bad(format, "buffer", l.buffer, "was not loaded".into()))
    };
    let per_vertex = |index: usize, what: &str| {
        let l = layout(root, compression, index, format)?;
        one_per_vertex(l, mesh.vertex_count(), (index, what), format)
    };
    let morph_target = match single.and_then(|p| p.targets.as_ref()?.first()?.positions) {
        Some(a) => {
            let l = per_vertex(a.value(), "the morph target")?;
            Some(finite(
                read_vectors::<3>(&l, data(&l)?, format)?,
                &l,
                format,
            )?)
        }
        None => None,
    };
    let error_key = Checked::Valid(Semantic::Extras("LOCAL_ERROR".into()));
    let local_error = match single.and_then(|p| p.attributes.get(&error_key)) {
        Some(a) => {
            let l = per_vertex(a.value(), "_LOCAL_ERROR")?;
            let values = read_vectors::<1>(&l, data(&l)?, format)?;
            Some(values.into_iter().map(|[v]| v).collect())
        }
        None => None,
    };
    let base_color = single
        .and_then(|p| p.material)
        .and_then(|m| root.materials.get(m.value()))
        .map(|m| m.pbr_metallic_roughness.base_color_factor.0);
    Ok(GltfNode {
        name: node
            .name
            .clone()
            .or_else(|| gltf_mesh.name.clone())
            .unwrap_or_default(),
        ancestors: ancestor_names(root, parents, instance.node),
        matrix: instance.matrix,
        local: instance.local,
        mesh,
        morph_target,
        local_error,
        base_color,
        extras: raw_json(node.extras.as_deref()),
    })
}

/// `l`, when it has one entry per vertex of a mesh of `vertices`.
fn one_per_vertex(
    l: Layout,
    vertices: usize,
    (index, what): (usize, &str),
    format: Format,
) -> Result<Layout, LoadError> {
    if l.count != vertices {
        let detail = format!("{what} has {} entries for {vertices} vertices", l.count);
        return Err(bad(format, "accessor", index, detail));
    }
    Ok(l)
}

fn bad(format: Format, what: &'static str, index: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format,
        location: Location::Item(what, index),
        detail,
    }
}

fn finite(values: Vec<[f32; 3]>, l: &Layout, format: Format) -> Result<Vec<[f32; 3]>, LoadError> {
    match values.iter().flatten().find(|v| !v.is_finite()) {
        Some(v) => Err(LoadError::NonFinite {
            format,
            location: Location::Item("accessor", l.accessor),
            value: v.to_string(),
        }),
        None => Ok(values),
    }
}

fn raw_json(raw: Option<&serde_json::value::RawValue>) -> Option<Value> {
    serde_json::from_str(raw?.get()).ok()
}

/// Each node's parent (the hierarchy was checked to be a forest by [`instances`]).
fn parents(root: &Root) -> Vec<Option<usize>> {
    let mut parent = vec![None; root.nodes.len()];
    for (i, node) in root.nodes.iter().enumerate() {
        for c in node.children.iter().flatten() {
            if let Some(p) = parent.get_mut(c.value()) {
                *p = Some(i);
            }
        }
    }
    parent
}

fn ancestor_names(root: &Root, parents: &[Option<usize>], node: usize) -> Vec<String> {
    let mut names = Vec::new();
    let mut at = parents[node];
    // A forest: at most as many steps as nodes.
    while let Some(p) = at.filter(|_| names.len() < root.nodes.len()) {
        names.push(root.nodes[p].name.clone().unwrap_or_default());
        at = parents[p];
    }
    names.reverse();
    names
}
