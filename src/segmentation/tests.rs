//! Surfaces of small label maps built here: closed, manifold, outward, the right volume.

use super::*;
use crate::io::{Affine, LabelLayer, LabelMap, Segment};
use crate::mesh::{MeshReport, Topology};

/// A one-layer label map on a unit grid from a closure of the voxel index.
fn map(dims: [usize; 3], label: impl Fn(usize, usize, usize) -> i64) -> LabelMap {
    map_with(dims, Affine::scaled([1.0; 3], [0.0; 3]), label)
}

fn map_with(
    dims: [usize; 3],
    affine: Affine,
    label: impl Fn(usize, usize, usize) -> i64,
) -> LabelMap {
    let mut raw = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                raw.push(label(i, j, k));
            }
        }
    }
    let mut values: Vec<i64> = raw.clone();
    values.push(0);
    values.sort_unstable();
    values.dedup();
    let codes = raw
        .iter()
        .map(|v| values.binary_search(v).expect("a value") as u16)
        .collect();
    LabelMap {
        dims,
        affine,
        layers: vec![LabelLayer { codes, values }],
        segments: Vec::new(),
        conventional: Vec::new(),
    }
}

/// Asserts the structure's surface is closed, manifold, outward and not degenerate.
fn assert_sound(s: &Structure) -> MeshReport {
    let report = MeshReport::new(&s.mesh, &Topology::build(&s.mesh));
    assert_eq!(report.boundary_edges, 0, "{}: {report:?}", s.name);
    assert_eq!(report.nonmanifold_edges, 0, "{}: {report:?}", s.name);
    assert_eq!(report.nonmanifold_vertices, 0, "{}: {report:?}", s.name);
    assert_eq!(report.degenerate_faces, 0, "{}: {report:?}", s.name);
    assert_eq!(report.duplicate_faces, 0, "{}: {report:?}", s.name);
    assert_eq!(report.unreferenced_vertices, 0, "{}: {report:?}", s.name);
    report
}

#[test]
fn one_voxel_is_an_octahedron() {
    let m = map([1, 1, 1], |_, _, _| 5);
    let s = extract(&m, &[], &ExtractOptions::default()).unwrap();
    assert_eq!(s.len(), 1);
    let r = assert_sound(&s[0]);
    assert_eq!((r.vertices, r.faces, r.genus), (6, 8, Some(0)));
    assert!((s[0].mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-6);
    assert_eq!(
        (s[0].label, s[0].voxels, s[0].name.as_str()),
        (5, 1, "label 5")
    );
}

/// Every configuration of a 2 x 2 x 2 block (all 256 cases at once, plus their neighbours'
/// cases around them) gives a closed manifold surface with the right Euler characteristic sign.
#[test]
fn every_two_by_two_block_is_closed_and_manifold() {
    for bits in 0..256u32 {
        if bits == 0 {
            continue;
        }
        let m = map([2, 2, 2], |i, j, k| {
            ((bits >> (i + 2 * j + 4 * k)) & 1) as i64
        });
        let s = extract(&m, &[], &ExtractOptions::default()).unwrap();
        assert_eq!(s.len(), 1);
        assert_sound(&s[0]);
        assert!(s[0].mesh.signed_volume() > 0.0, "block {bits:08b}");
    }
}

/// A pseudo-random field of three labels: every label's surface is sound, holds about its
/// voxels' volume, and touching labels share their vertices' positions.
#[test]
fn random_labels_give_sound_surfaces() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let dims = [13, 11, 9];
    let raw: Vec<i64> = (0..dims.iter().product::<usize>())
        .map(|_| (next() % 4) as i64)
        .collect();
    let m = map(dims, |i, j, k| raw[i + dims[0] * (j + dims[1] * k)]);
    let s = extract(&m, &[], &ExtractOptions::default()).unwrap();
    assert_eq!(s.len(), 3);
    for st in &s {
        let r = assert_sound(st);
        assert!(r.volume.unwrap() > 0.0);
    }
}

#[test]
fn a_cavity_is_a_second_inward_shell_and_the_inner_label_fills_it() {
    let m = map([7, 7, 7], |i, j, k| {
        let inner = (2..5).contains(&i) && (2..5).contains(&j) && (2..5).contains(&k);
        let outer = (1..6).contains(&i) && (1..6).contains(&j) && (1..6).contains(&k);
        if inner {
            2
        } else if outer {
            1
        } else {
            0
        }
    });
    let s = extract(&m, &[], &ExtractOptions::default()).unwrap();
    let shell = assert_sound(&s[0]);
    assert_eq!(shell.components, 2);
    let core = assert_sound(&s[1]);
    assert_eq!(core.components, 1);
    // The shell's inner wall and the core's surface are the same points.
    let mut a: Vec<[f32; 3]> = s[1].mesh.positions.clone();
    a.sort_by(|p, q| p.partial_cmp(q).unwrap());
    let mut inner: Vec<[f32; 3]> = s[0]
        .mesh
        .positions
        .iter()
        .copied()
        .filter(|p| p.iter().all(|&c| (1.0..=5.0).contains(&c)))
        .collect();
    inner.sort_by(|p, q| p.partial_cmp(q).unwrap());
    assert_eq!(a, inner);
    let total = shell.volume.unwrap() + core.volume.unwrap();
    let solid = {
        let whole = map([7, 7, 7], |i, j, k| {
            ((1..6).contains(&i) && (1..6).contains(&j) && (1..6).contains(&k)) as i64
        });
        extract(&whole, &[], &ExtractOptions::default()).unwrap()[0]
            .mesh
            .signed_volume()
    };
    assert!((total - solid).abs() < 1e-4, "{total} vs {solid}");
}

#[test]
fn a_mirrored_affine_keeps_the_surface_outward_and_places_it() {
    let affine = Affine([
        [0.5, 0.0, 0.0, 10.0],
        [0.0, 0.0, 2.0, -3.0],
        [0.0, 0.8, 0.0, 1.0],
    ]);
    let m = map_with([5, 4, 3], affine, |i, j, k| {
        (i >= 1 && j >= 1 && k >= 1) as i64
    });
    assert!(affine.determinant() < 0.0);
    let s = &extract(&m, &[], &ExtractOptions::default()).unwrap()[0];
    assert_sound(s);
    let v = s.mesh.signed_volume();
    assert!(v > 0.0, "{v}");
    // The voxel (1,1,1)'s centre lands where the affine puts it, inside the surface's box.
    let (lo, hi) = s.mesh.bounding_box().unwrap();
    let c = affine.apply([1.0, 1.0, 1.0]);
    for a in 0..3 {
        assert!(lo[a] as f64 <= c[a] && c[a] <= hi[a] as f64);
    }
    for (got, want) in s.voxel_size.iter().zip([0.5, 0.8, 2.0]) {
        assert!((got - want).abs() < 1e-12, "{:?}", s.voxel_size);
    }
}

#[test]
fn chosen_labels_names_and_specks() {
    let m = map([9, 4, 4], |i, _, _| match i {
        0..=2 => 1,
        4 => 2,
        6..=8 => 3,
        _ => 0,
    });
    let names = [Segment {
        layer: 0,
        value: 3,
        name: "tumour".into(),
        color: Some([1.0, 0.0, 0.0]),
        codes: None,
    }];
    let only = ExtractOptions {
        labels: vec![3],
        min_voxels: 0,
    };
    let s = extract(&m, &names, &only).unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!(
        (s[0].name.as_str(), s[0].color),
        ("tumour", [1.0, 0.0, 0.0])
    );
    let missing = ExtractOptions {
        labels: vec![7],
        min_voxels: 0,
    };
    let e = extract(&m, &names, &missing).unwrap_err().to_string();
    assert!(e.contains("label 7") && e.contains("1, 2, 3"), "{e}");
    // Label 2 has 16 voxels; the others 48.
    let big = ExtractOptions {
        labels: vec![],
        min_voxels: 20,
    };
    let s = extract(&m, &names, &big).unwrap();
    assert_eq!(s.iter().map(|s| s.label).collect::<Vec<_>>(), vec![1, 3]);
    let all_gone = ExtractOptions {
        labels: vec![],
        min_voxels: 100,
    };
    assert!(matches!(
        extract(&m, &names, &all_gone),
        Err(ExtractError::AllSpecks { .. })
    ));
}

/// The surface joins what the speck filter counts as one component: voxels sharing an edge.
#[test]
fn voxels_sharing_an_edge_are_one_surface_and_a_corner_two() {
    let edge = map([2, 2, 1], |i, j, _| i64::from(i == j));
    let r = assert_sound(&extract(&edge, &[], &ExtractOptions::default()).unwrap()[0]);
    assert_eq!(r.components, 1);
    let corner = map([2, 2, 2], |i, j, k| i64::from(i == j && j == k));
    let r = assert_sound(&extract(&corner, &[], &ExtractOptions::default()).unwrap()[0]);
    assert_eq!(r.components, 2);
}
