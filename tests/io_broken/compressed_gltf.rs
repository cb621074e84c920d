//! Broken compressed case glTFs (EXT_meshopt_compression, KHR_mesh_quantization): views that
//! lie about their sizes, corrupt streams and what is not read are refused, naming the view,
//! before anything of the size they claim is allocated.

use super::*;

#[path = "../common/glb.rs"]
mod glb_file;
use glb_file::glb;

/// A compressed case GLB of a tetrahedron, as `case build` writes it: its JSON and BIN chunk.
fn compressed_case() -> (serde_json::Value, Vec<u8>) {
    use meshsmooth::case::{Case, CaseStructure};
    use meshsmooth::export::{write_case, CaseGltfOptions};
    let mesh = meshsmooth::mesh::Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
            [0.0, 0.0, 10.0],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let mut case = Case::default();
    case.structures
        .push(CaseStructure::from_mesh("tetra", mesh, [1.0, 0.0, 0.0]));
    let bytes = write_case(&case, &CaseGltfOptions::default()).expect("writes");
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
    let doc = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON");
    let bin_at = 20 + json_len;
    let bin_len = u32::from_le_bytes(bytes[bin_at..bin_at + 4].try_into().expect("4")) as usize;
    (doc, bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec())
}

/// The buffer view of the mesh's POSITION accessor.
fn position_view(doc: &serde_json::Value) -> usize {
    view_of(
        doc,
        &doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"],
    )
}

/// The buffer view of `accessor` (an accessor's index in the document).
fn view_of(doc: &serde_json::Value, accessor: &serde_json::Value) -> usize {
    let a = accessor.as_u64().expect("an accessor");
    doc["accessors"][a as usize]["bufferView"]
        .as_u64()
        .expect("view") as usize
}

#[test]
fn a_compressed_case_reads_back_quantized() {
    let (doc, bin) = compressed_case();
    let mesh = load_as(&glb(&doc, &bin), Format::Glb).expect("reads");
    assert_eq!(mesh.vertex_count(), 4);
    // 10 mm on a power-of-two lattice: the corners are lattice points, read back exactly (in
    // the order the codecs prefer).
    assert!(mesh.positions.contains(&[10.0, 0.0, 0.0]));
    assert!(mesh.positions.contains(&[0.0, 0.0, 10.0]));
}

#[test]
fn compressed_views_that_lie_about_their_size_fail_before_allocating() {
    let (doc, bin) = compressed_case();
    let view = position_view(&doc);

    // A count that does not fill the view.
    let mut d = doc.clone();
    d["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["count"] = 3.into();
    let e = error_at(
        &glb(&d, &bin),
        Format::Glb,
        "Syntax",
        Location::Item("buffer view", view),
    );
    says(&e, "byteLength");

    // A billion elements, the view and the fallback buffer declaring room for them: the
    // compressed bytes cannot hold them, and nothing that large is allocated.
    let mut d = doc.clone();
    let count = 1u64 << 30;
    d["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["count"] = count.into();
    d["bufferViews"][view]["byteLength"] = (8 * count).into();
    d["bufferViews"][view]["byteOffset"] = 0.into();
    d["buffers"][1]["byteLength"] = (8 * count).into();
    let e = error_at(
        &glb(&d, &bin),
        Format::Glb,
        "Syntax",
        Location::Item("buffer view", view),
    );
    says(&e, "cannot hold");

    // Compressed bytes past the end of the BIN chunk's buffer.
    let mut d = doc.clone();
    d["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["byteOffset"] =
        (bin.len() as u64).into();
    let e = error_at(
        &glb(&d, &bin),
        Format::Glb,
        "Syntax",
        Location::Item("buffer view", view),
    );
    says(&e, "past the end of buffer 0");

    // A stride the attribute codec cannot have.
    let mut d = doc.clone();
    d["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6.into();
    error_at(
        &glb(&d, &bin),
        Format::Glb,
        "Syntax",
        Location::Item("buffer view", view),
    );
}

#[test]
fn corrupt_or_unreadable_compressed_data_is_refused_naming_the_view() {
    let (doc, bin) = compressed_case();
    let view = position_view(&doc);
    let at = doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["byteOffset"]
        .as_u64()
        .expect("offset") as usize;

    // The attribute stream's header byte is not 0xa0.
    let mut broken = bin.clone();
    broken[at] = 0x55;
    let e = error_at(
        &glb(&doc, &broken),
        Format::Glb,
        "Syntax",
        Location::Item("buffer view", view),
    );
    says(&e, "corrupt");

    // Every stream cut short or garbled in turn: an error, never a panic or a wrong mesh.
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    for _ in 0..200 {
        let mut broken = bin.clone();
        let i = (rng.next() as usize) % broken.len();
        broken[i] ^= (rng.next() as u8) | 1;
        let _ = load_as(&glb(&doc, &broken), Format::Glb);
    }

    // A filter the extension does not define: said so, not misread.
    let mut d = doc.clone();
    d["bufferViews"][view]["extensions"]["EXT_meshopt_compression"]["filter"] = "WAVELET".into();
    let e = error_kind(&glb(&d, &bin), Format::Glb, "Unsupported");
    says(&e, "WAVELET");

    // A filter on triangles, or one whose elements the stride cannot hold.
    let primitive = &doc["meshes"][0]["primitives"][0];
    let triangles = view_of(&doc, &primitive["indices"]);
    let mut d = doc.clone();
    d["bufferViews"][triangles]["extensions"]["EXT_meshopt_compression"]["filter"] =
        "OCTAHEDRAL".into();
    let e = error_kind(&glb(&d, &bin), Format::Glb, "Unsupported");
    says(&e, "OCTAHEDRAL");
    let normals = view_of(&doc, &primitive["attributes"]["NORMAL"]);
    let mut d = doc.clone();
    d["bufferViews"][normals]["extensions"]["EXT_meshopt_compression"]["filter"] =
        "QUATERNION".into();
    let e = error_at(
        &glb(&d, &bin),
        Format::Glb,
        "Syntax",
        Location::Item("buffer view", normals),
    );
    says(&e, "QUATERNION");

    // A view that is not compressed cannot read the fallback buffer, which has no data.
    let mut d = doc.clone();
    d["bufferViews"][view]
        .as_object_mut()
        .expect("view")
        .remove("extensions");
    let e = error_at(
        &glb(&d, &bin),
        Format::Glb,
        "Syntax",
        Location::Item("buffer", 1),
    );
    says(&e, "fallback");
}
