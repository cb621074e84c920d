//! GLB (binary glTF 2.0): one mesh with one triangle primitive. POSITION (with the min/max the
//! specification requires), NORMAL and COLOR_0 when given, u32 indices, one buffer in the BIN
//! chunk. The JSON is built with serde_json; nothing from any input file is written.

use serde_json::{json, Value};

use super::case_gltf::{SceneFrame, RAS_MM_TO_GLTF};
use super::{meshopt, ExportError, ExportOptions};
use crate::case::CASE_KEY;
use crate::mesh::{bounding_box, Mesh};

pub(super) const ARRAY_BUFFER: u32 = 34962;
pub(super) const ELEMENT_ARRAY_BUFFER: u32 = 34963;
pub(super) const FLOAT: u32 = 5126;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_SHORT: u32 = 5123;
/// The compression extension's name, in views, buffers and the extension lists.
pub(super) const MESHOPT: &str = "EXT_meshopt_compression";
pub(super) const UNSIGNED_INT: u32 = 5125;
pub(super) const TRIANGLES: u32 = 4;

/// The BIN chunk being built, with one buffer view and accessor per array.
#[derive(Default)]
pub(super) struct Builder {
    pub(super) bin: Vec<u8>,
    pub(super) views: Vec<Value>,
    pub(super) accessors: Vec<Value>,
    /// The length of the fallback buffer (1) that compressed views declare their place in.
    pub(super) fallback: usize,
}

impl Builder {
    /// Appends `bytes` as a new buffer view (4-byte aligned) and returns the accessor index of
    /// `accessor`, which gets the view filled in.
    pub(super) fn push(&mut self, bytes: &[u8], target: u32, mut accessor: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = self.views.len();
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
            "target": target,
        }));
        self.bin.extend_from_slice(bytes);
        accessor["bufferView"] = json!(view);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Appends `bytes` as a buffer view of its own, read by no accessor (a blob an extension
    /// or `extras` names); returns the view's index.
    pub(super) fn push_blob(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
        }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }
}

impl Builder {
    /// Appends `part`, built on its own (a structure written on another thread): its bytes
    /// after this builder's, 4-byte aligned as a push would place them, its views and
    /// accessors after these. Returns how far its accessor indices moved.
    pub(super) fn append(&mut self, part: Builder) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let (bin, fallback, views) = (self.bin.len(), self.fallback, self.views.len());
        let shift = |v: &mut Value, by: usize| {
            if let Some(offset) = v["byteOffset"].as_u64() {
                v["byteOffset"] = json!(offset as usize + by);
            }
        };
        for mut view in part.views {
            let by = match view["buffer"].as_u64() {
                Some(1) => fallback,
                _ => bin,
            };
            shift(&mut view, by);
            if let Some(compressed) = view.pointer_mut(&format!("/extensions/{MESHOPT}")) {
                shift(compressed, bin);
            }
            self.views.push(view);
        }
        let accessors = self.accessors.len();
        for mut accessor in part.accessors {
            if let Some(view) = accessor["bufferView"].as_u64() {
                accessor["bufferView"] = json!(view as usize + views);
            }
            self.accessors.push(accessor);
        }
        self.bin.extend_from_slice(&part.bin);
        self.fallback += part.fallback;
        accessors
    }
}

impl Builder {
    /// Appends `raw` (elements of `stride` bytes) compressed as `EXT_meshopt_compression`'s
    /// attributes; returns the accessor index of `accessor`.
    pub(super) fn push_attributes(
        &mut self,
        raw: &[u8],
        stride: usize,
        accessor: Value,
    ) -> Result<usize, ExportError> {
        self.push_filtered_attributes(raw, stride, accessor, "NONE")
    }

    /// [`Self::push_attributes`] for data `filter` (one of the extension's) has encoded.
    pub(super) fn push_filtered_attributes(
        &mut self,
        raw: &[u8],
        stride: usize,
        accessor: Value,
        filter: &str,
    ) -> Result<usize, ExportError> {
        let data = meshopt::encode_attributes(raw, stride).ok_or_else(codec_failed)?;
        let mut view = self.compressed_view(raw.len(), &data, stride, "ATTRIBUTES");
        if filter != "NONE" {
            view["extensions"][MESHOPT]["filter"] = json!(filter);
        }
        view["byteStride"] = json!(stride);
        view["target"] = json!(ARRAY_BUFFER);
        Ok(self.add(view, accessor))
    }

    /// Appends a triangle list's indices compressed as `EXT_meshopt_compression`'s triangles,
    /// 16-bit where the vertices allow; returns the accessor index.
    pub(super) fn push_triangles(
        &mut self,
        indices: &[u32],
        vertex_count: usize,
    ) -> Result<usize, ExportError> {
        let data = meshopt::encode_triangles(indices, vertex_count).ok_or_else(codec_failed)?;
        let (stride, component) = if vertex_count <= 1 << 16 {
            (2, UNSIGNED_SHORT)
        } else {
            (4, UNSIGNED_INT)
        };
        let mut view = self.compressed_view(indices.len() * stride, &data, stride, "TRIANGLES");
        view["target"] = json!(ELEMENT_ARRAY_BUFFER);
        let accessor =
            json!({"componentType": component, "count": indices.len(), "type": "SCALAR"});
        Ok(self.add(view, accessor))
    }

    /// A view of `raw_len` bytes in the fallback buffer whose data is `data` in buffer 0.
    fn compressed_view(&mut self, raw_len: usize, data: &[u8], stride: usize, mode: &str) -> Value {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = json!({
            "buffer": 1,
            "byteOffset": self.fallback,
            "byteLength": raw_len,
            "extensions": { MESHOPT: {
                "buffer": 0,
                "byteOffset": self.bin.len(),
                "byteLength": data.len(),
                "byteStride": stride,
                "mode": mode,
                "count": raw_len / stride,
            }},
        });
        self.bin.extend_from_slice(data);
        self.fallback += raw_len.next_multiple_of(4);
        view
    }

    fn add(&mut self, view: Value, mut accessor: Value) -> usize {
        accessor["bufferView"] = json!(self.views.len());
        self.views.push(view);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }
}

fn codec_failed() -> ExportError {
    ExportError::TooLarge {
        format: "glTF",
        detail: "the meshopt encoder refused the data".into(),
    }
}

pub(super) fn floats(values: &[[f32; 3]]) -> Vec<u8> {
    values
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// The specification requires NORMAL to be unit length. Normals within rounding of unit length
/// are kept bit for bit; others are rescaled, and a zero normal (a vertex with no incident
/// area) becomes +Z.
fn unit_normal(n: [f32; 3]) -> [f32; 3] {
    let len = n.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>().sqrt();
    if (len - 1.0).abs() <= 1e-4 {
        n
    } else if len > 0.0 {
        n.map(|v| (f64::from(v) / len) as f32)
    } else {
        [0.0, 0.0, 1.0]
    }
}

pub(super) fn write(mesh: &Mesh, options: &ExportOptions) -> Result<Vec<u8>, ExportError> {
    let n = mesh.vertex_count();
    let too_large = || ExportError::TooLarge {
        format: "GLB",
        detail: "the file would exceed the 4 GiB a GLB header can describe".into(),
    };
    // A GLB's total length is a u32: check before building anything that large.
    let estimate = (n as u64) * (12 + 12 + 4) + mesh.triangle_count() as u64 * 12 + 4096;
    if estimate > u64::from(u32::MAX) {
        return Err(too_large());
    }
    let mut b = Builder {
        bin: Vec::with_capacity(estimate as usize),
        ..Default::default()
    };
    let mut attributes = geometry(&mut b, mesh, options.normals);
    if let Some(colors) = options.colors {
        attributes["COLOR_0"] = json!(b.push(
            colors.as_flattened(),
            ARRAY_BUFFER,
            json!({"componentType": UNSIGNED_BYTE, "normalized": true, "count": n, "type": "VEC4"}),
        ));
    }
    let indices = b.push(
        &index_bytes(mesh),
        ELEMENT_ARRAY_BUFFER,
        json!({"componentType": UNSIGNED_INT, "count": 3 * mesh.triangle_count(), "type": "SCALAR"}),
    );

    let mut gltf_mesh = json!({
        "primitives": [{ "attributes": attributes, "indices": indices, "mode": TRIANGLES }],
    });
    if let Some(extras) = &options.extras {
        gltf_mesh["extras"] = extras.clone();
    }
    // Like a case: millimetres inside the mesh, the frame on a root node, and a record saying
    // so, which lets the reader here give the stored positions back.
    let (frame, nodes) = if options.millimetres {
        (SceneFrame::Millimetres, json!([{ "mesh": 0 }]))
    } else {
        (
            SceneFrame::Gltf,
            json!([{ "matrix": RAS_MM_TO_GLTF, "children": [1] }, { "mesh": 0 }]),
        )
    };
    let document = json!({
        "asset": { "version": "2.0", "generator": "meshsmooth" },
        "scene": 0,
        "scenes": [{ "nodes": [0], "extras": { CASE_KEY: { "frame": frame.name(), "units": "mm" } } }],
        "nodes": nodes,
        "meshes": [gltf_mesh],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{ "byteLength": b.bin.len() }],
    });
    container(&document, b.bin).ok_or_else(too_large)
}

/// Appends a mesh's POSITION (with the min/max the specification requires) and, when given,
/// its NORMAL (made unit) to the BIN chunk; returns the primitive's attributes.
pub(super) fn geometry(b: &mut Builder, mesh: &Mesh, normals: Option<&[[f32; 3]]>) -> Value {
    let n = mesh.vertex_count();
    let (min, max) = bounding_box(&mesh.positions).unwrap_or_default();
    // Min/max as the f64 of each f32, so a reader comparing in either precision sees them equal.
    let bound = |v: [f32; 3]| v.map(f64::from);
    let position = b.push(
        &floats(&mesh.positions),
        ARRAY_BUFFER,
        json!({"componentType": FLOAT, "count": n, "type": "VEC3",
               "min": bound(min), "max": bound(max)}),
    );
    let mut attributes = json!({ "POSITION": position });
    if let Some(normals) = normals {
        attributes["NORMAL"] = json!(b.push(
            &floats(&unit_normals(normals)),
            ARRAY_BUFFER,
            json!({"componentType": FLOAT, "count": n, "type": "VEC3"}),
        ));
    }
    attributes
}

/// Normals made unit length, as the specification requires of NORMAL.
pub(super) fn unit_normals(normals: &[[f32; 3]]) -> Vec<[f32; 3]> {
    normals.iter().map(|&v| unit_normal(v)).collect()
}

/// The indices of a mesh's triangles as little-endian u32s.
pub(super) fn index_bytes(mesh: &Mesh) -> Vec<u8> {
    mesh.triangles
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// The GLB container around a JSON document and its BIN chunk; `None` past the 4 GiB its
/// header can describe.
pub(super) fn container(document: &Value, mut bin: Vec<u8>) -> Option<Vec<u8>> {
    let mut json = document.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let total32 = u32::try_from(total).ok()?;

    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(total32.to_le_bytes());
    for (kind, data) in [(b"JSON", &json), (b"BIN\0", &bin)] {
        // Each chunk is shorter than the total checked above.
        out.extend((data.len() as u32).to_le_bytes());
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pushes of every kind, with lengths that leave the buffer unaligned.
    fn push_some(b: &mut Builder, seed: u8) -> Vec<usize> {
        let raw: Vec<u8> = (0..96u8).map(|i| i.wrapping_mul(seed)).collect();
        let accessor = json!({"componentType": FLOAT, "count": 1, "type": "SCALAR"});
        vec![
            b.push(&raw[..7], ARRAY_BUFFER, accessor.clone()),
            b.push_attributes(&raw[..48], 12, accessor.clone())
                .expect("encodes"),
            b.push_triangles(&[0, 1, 2, 2, 1, 3], 4).expect("encodes"),
            b.push(&raw[..5], ELEMENT_ARRAY_BUFFER, accessor),
        ]
    }

    /// A part built on its own and appended lays out bytes, views and accessors as pushing
    /// the same arrays after the others would.
    #[test]
    fn an_appended_part_is_laid_out_as_if_pushed_in_turn() {
        let mut in_turn = Builder::default();
        push_some(&mut in_turn, 3);
        let second = push_some(&mut in_turn, 7);
        let mut joined = Builder::default();
        push_some(&mut joined, 3);
        let mut part = Builder::default();
        let own = push_some(&mut part, 7);
        let by = joined.append(part);
        assert_eq!(own.iter().map(|i| i + by).collect::<Vec<_>>(), second);
        assert_eq!(joined.bin, in_turn.bin);
        assert_eq!(joined.views, in_turn.views);
        assert_eq!(joined.accessors, in_turn.accessors);
        assert_eq!(joined.fallback, in_turn.fallback);
    }

    #[test]
    fn container_is_aligned_and_json_describes_the_bin_chunk() {
        let mesh = Mesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, -2.5]],
            vec![[0, 1, 2]],
        );
        let colors = [[255, 0, 0, 255]; 3];
        let options = ExportOptions {
            colors: Some(&colors),
            extras: Some(json!({"filter": "taubin"})),
            ..Default::default()
        };
        let bytes = write(&mesh, &options).expect("writes");
        assert_eq!(&bytes[..8], b"glTF\x02\0\0\0");
        assert_eq!(
            u32::from_le_bytes(bytes[8..12].try_into().expect("4")) as usize,
            bytes.len()
        );
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
        assert_eq!(json_len % 4, 0);
        assert_eq!(&bytes[16..20], b"JSON");
        let doc: Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON");
        let bin_at = 20 + json_len;
        assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
        let bin_len = u32::from_le_bytes(bytes[bin_at..bin_at + 4].try_into().expect("4"));
        assert_eq!(bin_len % 4, 0);
        assert_eq!(doc["buffers"][0]["byteLength"], json!(bin_len));
        assert_eq!(doc["asset"]["generator"], "meshsmooth");
        assert_eq!(doc["meshes"][0]["extras"]["filter"], "taubin");
        assert_eq!(doc["accessors"][0]["min"], json!([0.0, 0.0, -2.5]));
        assert_eq!(doc["accessors"][0]["max"], json!([1.0, 1.0, 0.0]));
        let attributes = &doc["meshes"][0]["primitives"][0]["attributes"];
        assert!(attributes.get("NORMAL").is_none());
        let color = &doc["accessors"][attributes["COLOR_0"].as_u64().expect("index") as usize];
        assert_eq!(color["normalized"], true);
        for view in doc["bufferViews"].as_array().expect("views") {
            assert_eq!(view["byteOffset"].as_u64().expect("offset") % 4, 0);
        }
    }

    #[test]
    fn normals_are_made_unit_only_when_they_are_not() {
        let almost = [0.0, 0.6, 0.800_000_1];
        assert_eq!(unit_normal(almost), almost);
        assert_eq!(unit_normal([0.0, 0.0, 0.0]), [0.0, 0.0, 1.0]);
        assert_eq!(unit_normal([0.0, 2.0, 0.0]), [0.0, 1.0, 0.0]);
    }
}
