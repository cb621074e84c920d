//! glTF 2.0: .glb and .gltf with embedded or data-URI buffers.
//!
//! The `gltf` crate (without its `import` feature, which pulls in image decoding and file
//! access) deserialises and validates the JSON document against the specification's schema;
//! the GLB container, buffers, accessors and the node hierarchy are read here from bytes,
//! with every offset checked, so that no input can panic or claim unbounded memory.

mod accessor;
mod assemble;
mod glb;
mod meshopt;
mod nodes;
mod scene;

pub use nodes::{read_scene, GltfNode, GltfScene};
pub use scene::Mat4;

use ::gltf::json::mesh::Semantic;
use ::gltf::json::validation::Checked;
use ::gltf::json::Root;

use super::{Format, LoadError, Location};
use crate::mesh::Mesh;

/// Reads the triangle primitives of the default scene (else scene 0, else every root node),
/// placed by their nodes' transforms, merged into one mesh.
pub(super) fn parse(bytes: &[u8], format: Format) -> Result<Mesh, LoadError> {
    // The content decides, so a binary file named .gltf still reads.
    let (format, json, json_offset, bin) = if bytes.starts_with(b"glTF") {
        let g = glb::split(bytes)?;
        (Format::Glb, g.json, g.json_offset, g.bin)
    } else if format == Format::Glb {
        return Err(LoadError::BadMagic {
            format,
            detail: "the first four bytes are not 'glTF'".into(),
        });
    } else {
        (Format::Gltf, bytes, 0, None)
    };
    let root = document(json, json_offset, format)?;
    let compression = meshopt::Compression::parse(json, &root, format)?;
    let mut instances = scene::instances(&root, format)?;
    if written_here(&root) {
        // Our files keep millimetres inside the meshes (or on a quantization lattice that
        // the mesh's own node scales to them) and the frame on the root: read the positions
        // in the mesh node's frame, so that what was exported reopens where it was.
        for i in &mut instances {
            i.matrix = i.local;
        }
    }
    assemble::merge(&root, &compression, &instances, bin, format)
}

/// Whether the scene carries meshsmooth's record of its frame (a file written here).
fn written_here(root: &Root) -> bool {
    let scene = root.scene.map_or(0, |s| s.value());
    let Some(extras) = root.scenes.get(scene).and_then(|s| s.extras.as_deref()) else {
        return false;
    };
    serde_json::from_str::<serde_json::Value>(extras.get())
        .ok()
        .and_then(|v| v.get("meshsmooth")?.get("frame").cloned())
        .is_some()
}

/// Deserialises and validates the JSON document.
fn document(json: &[u8], json_offset: usize, format: Format) -> Result<Root, LoadError> {
    let mut root: Root =
        ::gltf::json::deserialize::from_slice(json).map_err(|e| LoadError::Syntax {
            format,
            location: json_error_location(json, json_offset, format, e.line(), e.column()),
            detail: e.to_string(),
        })?;
    check_required_extensions(&root, format)?;
    // Handled above; the crate would refuse any it does not implement itself.
    root.extensions_required.clear();

    // The crate's validation indexes the POSITION accessor before checking that it exists.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions));
            if let Some(a) = position.filter(|a| a.value() >= root.accessors.len()) {
                return Err(LoadError::Syntax {
                    format,
                    location: Location::Item("mesh", m),
                    detail: format!(
                        "primitive {p}: POSITION accessor {} does not exist",
                        a.value()
                    ),
                });
            }
        }
    }

    match ::gltf::Document::from_json(root) {
        Ok(doc) => Ok(doc.into_json()),
        Err(e) => {
            let location = match &e {
                ::gltf::Error::Validation(errors) => {
                    errors.first().and_then(|(path, _)| item_location(&path.0))
                }
                _ => None,
            };
            Err(LoadError::Syntax {
                format,
                location: location.unwrap_or(Location::Byte(json_offset)),
                detail: e.to_string(),
            })
        }
    }
}

/// Required extensions that change the geometry must be implemented here; those about
/// appearance (materials, textures, lights) do not touch the surface and are ignored.
fn check_required_extensions(root: &Root, format: Format) -> Result<(), LoadError> {
    const APPEARANCE: &[&str] = &[
        "KHR_materials_",
        "KHR_texture_",
        "EXT_texture_",
        "MSFT_texture_",
    ];
    for ext in &root.extensions_required {
        let readable = ext == "KHR_mesh_quantization"
            || ext == meshopt::NAME
            || ext == "KHR_lights_punctual"
            || APPEARANCE.iter().any(|p| ext.starts_with(p));
        if !readable {
            return Err(LoadError::Unsupported {
                format,
                detail: format!("the file requires the extension {ext}, which is not readable"),
            });
        }
    }
    Ok(())
}

/// Where a JSON parse error is: a line of a .gltf file, or a byte of a GLB file.
fn json_error_location(
    json: &[u8],
    json_offset: usize,
    format: Format,
    line: usize,
    column: usize,
) -> Location {
    if format == Format::Gltf {
        return Location::Line(line.max(1));
    }
    let line_start = json
        .split_inclusive(|&b| b == b'\n')
        .take(line.saturating_sub(1))
        .map(<[u8]>::len)
        .sum::<usize>();
    Location::Byte(json_offset + line_start + column.saturating_sub(1))
}

/// `meshes[3].primitives[0]...` -> mesh 3, for the top-level arrays a reader knows.
fn item_location(path: &str) -> Option<Location> {
    let (name, rest) = path.split_once('[')?;
    let index = rest.split_once(']')?.0.parse().ok()?;
    let what = match name {
        "accessors" => "accessor",
        "bufferViews" => "buffer view",
        "buffers" => "buffer",
        "meshes" => "mesh",
        "nodes" => "node",
        "scenes" => "scene",
        "materials" => "material",
        "textures" => "texture",
        "images" => "image",
        "samplers" => "sampler",
        "skins" => "skin",
        "animations" => "animation",
        "cameras" => "camera",
        _ => return None,
    };
    Some(Location::Item(what, index))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_paths_name_the_item() {
        assert_eq!(
            item_location("meshes[3].primitives[0].attributes"),
            Some(Location::Item("mesh", 3))
        );
        assert_eq!(
            item_location("bufferViews[12]"),
            Some(Location::Item("buffer view", 12))
        );
        assert_eq!(item_location("asset.version"), None);
    }

    #[test]
    fn json_errors_in_a_glb_point_at_bytes() {
        let json = b"{\n  \"asset\": x\n}";
        let loc = json_error_location(json, 20, Format::Glb, 2, 12);
        assert_eq!(loc, Location::Byte(20 + 2 + 11));
        assert_eq!(
            json_error_location(json, 0, Format::Gltf, 2, 12),
            Location::Line(2)
        );
    }
}
