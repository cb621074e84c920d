//! Label maps from ../shared/data become named structure surfaces: the same from NIfTI and
//! from 3D Slicer's .seg.nrrd, closed and manifold, holding their voxels' volume, where the
//! phantom's analytic shapes are, and through any affine.

use meshsmooth::mesh::{MeshReport, Topology};
use meshsmooth::segmentation::{self, NamedBytes, OpenOptions, Structure};
use serde_json::Value;

#[path = "common/label_maps.rs"]
mod label_maps;
#[path = "common/nifti.rs"]
mod nifti;

use label_maps::{inside_shape, open, read};

/// Closed, manifold, outward, no degenerate or duplicate faces; returns the report.
fn assert_sound(file: &str, s: &Structure) -> MeshReport {
    let r = MeshReport::new(&s.mesh, &Topology::build(&s.mesh));
    let what = format!("{file}: {} (label {}): {r:?}", s.name, s.label);
    assert_eq!(r.boundary_edges, 0, "{what}");
    assert_eq!(r.nonmanifold_edges, 0, "{what}");
    assert_eq!(r.nonmanifold_vertices, 0, "{what}");
    assert_eq!(r.degenerate_faces, 0, "{what}");
    assert_eq!(r.duplicate_faces, 0, "{what}");
    assert!(r.volume.expect("closed") > 0.0, "{what}");
    r
}

/// Surface volume against voxel count times voxel volume, for structures of 1,000 voxels or more.
fn assert_volumes(file: &str, structures: &[Structure]) -> f64 {
    let mut worst: f64 = 0.0;
    for s in structures.iter().filter(|s| s.voxels >= 1000) {
        let ratio = s.mesh.signed_volume() / s.voxel_volume();
        worst = worst.max((ratio - 1.0).abs());
        assert!(
            (ratio - 1.0).abs() <= 0.03,
            "{file}: {} holds {ratio:.4} of its voxels' volume",
            s.name
        );
    }
    worst
}

#[test]
fn every_shared_label_map_gives_closed_manifold_surfaces_with_their_voxels_volume() {
    let maps = [
        "labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz",
        "labelmaps/case_phantom_shared.nii.gz",
        "labelmaps/case_phantom_shared.seg.nrrd",
        "segmentations/seg_mni152_brainmask_2mm_mask.nii.gz",
        "segmentations/seg_mni152_gm_plus_wm_p0.5_1mm_mask.nii.gz",
        "synthetic/bent_tube_r3.5_mask.nii.gz",
        "synthetic/ellipsoid_30_20_12_mask.nii.gz",
        "synthetic/sphere_r20_mask.nii.gz",
        "synthetic/torus_R24_r8_mask.nii.gz",
    ];
    for file in maps {
        let structures = open(file, None);
        for s in &structures {
            assert_sound(file, s);
        }
        let worst = assert_volumes(file, &structures);
        println!(
            "{file}: {} structures, worst volume difference {:.2}%",
            structures.len(),
            100.0 * worst
        );
    }
}

#[test]
fn the_jhu_atlas_gives_its_48_named_tracts() {
    let s = open(
        "labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz",
        Some("labelmaps/JHU-WhiteMatter-labels-1mm.nii.txt"),
    );
    assert_eq!(s.len(), 48);
    assert_eq!(s[0].label, 1);
    assert_eq!(s[0].name, "Middle_cerebellar_peduncle");
    assert_eq!(s[47].label, 48);
    // 1 mm voxels: the legend's unit and the bound's default come with the structure.
    assert!((s[0].voxel_diagonal() - 3f64.sqrt()).abs() < 1e-9);
    // Without a table the labels are numbered and coloured by default, each its own colour
    // among its neighbours.
    let plain = open("labelmaps/JHU-WhiteMatter-labels-1mm.nii.gz", None);
    assert_eq!(plain[4].name, "label 5");
    assert_ne!(plain[4].color, plain[5].color);
}

#[test]
fn the_phantom_reads_the_same_from_nifti_and_seg_nrrd() {
    let table = Some("labelmaps/case_phantom_shared_labels.txt");
    let nifti = open("labelmaps/case_phantom_shared.nii.gz", table);
    let nrrd = open("labelmaps/case_phantom_shared.seg.nrrd", None);
    assert_eq!(nifti.len(), 4);
    assert_eq!(nifti.len(), nrrd.len());
    for (a, b) in nifti.iter().zip(&nrrd) {
        assert_eq!((a.label, &a.name, a.voxels), (b.label, &b.name, b.voxels));
        for k in 0..3 {
            assert!((a.color[k] - b.color[k]).abs() <= 1.0 / 255.0, "{}", a.name);
            assert!((a.voxel_size[k] - b.voxel_size[k]).abs() < 1e-9);
        }
        assert_eq!(a.mesh.triangles, b.mesh.triangles, "{}", a.name);
        assert_eq!(a.mesh.positions.len(), b.mesh.positions.len());
        for (p, q) in a.mesh.positions.iter().zip(&b.mesh.positions) {
            for k in 0..3 {
                assert!((p[k] - q[k]).abs() <= 1e-4, "{}: {p:?} vs {q:?}", a.name);
            }
        }
    }
    let names: Vec<&str> = nifti.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["liver", "portal_vein", "tumor", "right_kidney"]);
}

/// Every vertex of every phantom structure has the structure's true surface within half a
/// voxel diagonal: the ball of that radius around it holds points inside and outside the
/// structure (its shape less the shapes listed after it, which the label map carves out).
#[test]
fn the_phantom_surfaces_lie_within_half_a_voxel_diagonal_of_the_analytic_shapes() {
    let truth: Value =
        serde_json::from_slice(&read("labelmaps/case_phantom_shared.json")).expect("JSON");
    let a = &truth["affine_ras"];
    let m: [[f64; 4]; 3] =
        std::array::from_fn(|r| std::array::from_fn(|c| a[r][c].as_f64().expect("n")));
    let spacing: [f64; 3] = std::array::from_fn(|k| truth["spacing_mm"][k].as_f64().expect("n"));
    // The phantom's affine is diagonal: world -> voxel index -> phantom mm.
    let phantom = |w: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| (w[k] - m[k][3]) / m[k][k] * spacing[k])
    };
    let shapes = truth["structures"].as_array().expect("structures");
    let structures = open("labelmaps/case_phantom_shared.nii.gz", None);
    let radius = 0.5 * spacing.iter().map(|s| s * s).sum::<f64>().sqrt();
    let mut directions = Vec::new();
    for x in -2..=2 {
        for y in -2..=2 {
            for z in -2..=2 {
                let d = [x as f64, y as f64, z as f64];
                let n = d.iter().map(|c| c * c).sum::<f64>().sqrt();
                if n > 0.0 {
                    directions.push(d.map(|c| c / n));
                }
            }
        }
    }
    for (index, s) in structures.iter().enumerate() {
        assert_eq!(
            s.voxels as u64,
            shapes[index]["voxels"].as_u64().expect("voxels")
        );
        let inside = |w: [f64; 3]| {
            let p = phantom(w);
            inside_shape(&shapes[index]["shape"], p)
                && !shapes[index + 1..]
                    .iter()
                    .any(|later| inside_shape(&later["shape"], p))
        };
        let mut far = 0;
        for q in &s.mesh.positions {
            let v = q.map(f64::from);
            let (mut seen_in, mut seen_out) = (false, false);
            for d in &directions {
                for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
                    let p: [f64; 3] = std::array::from_fn(|k| v[k] + f * radius * d[k]);
                    if inside(p) {
                        seen_in = true;
                    } else {
                        seen_out = true;
                    }
                }
            }
            if !(seen_in && seen_out) {
                far += 1;
            }
        }
        assert_eq!(
            far, 0,
            "{}: {far} vertices farther than {radius:.3} mm from the truth",
            s.name
        );
    }
}

/// A NIfTI-1 file of `dims` uint8 labels with the given sform (code 2) and qform code 0.
fn nifti_bytes(dims: [usize; 3], sform: [[f32; 4]; 3], voxels: &[u8]) -> Vec<u8> {
    let mut bytes = nifti::nifti_header(dims, sform, [1.0; 3]);
    bytes.extend_from_slice(voxels);
    bytes
}

/// The same label map on a plain grid and through an oblique, mirrored sform: the second's
/// surface is the first's mapped through the affine, still closed and outward.
#[test]
fn an_oblique_mirrored_affine_moves_the_surface_with_it() {
    let dims = [6, 5, 4];
    let voxels: Vec<u8> = (0..dims.iter().product::<usize>())
        .map(|v| {
            let (i, j, k) = (v % 6, (v / 6) % 5, v / 30);
            u8::from(
                (1..5).contains(&i)
                    && (1..4).contains(&j)
                    && (1..3).contains(&k)
                    && (i + j + k) % 5 != 0,
            )
        })
        .collect();
    let (c, s) = (0.8f32, 0.6f32);
    // Rotation about z, x mirrored, anisotropic spacing, an offset.
    let oblique = [
        [-0.7 * c, -1.1 * s, 0.0, 12.5],
        [-0.7 * s, 1.1 * c, 0.0, -40.0],
        [0.0, 0.0, 2.5, 7.0],
    ];
    let plain = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    let extract = |sform: [[f32; 4]; 3]| {
        let bytes = nifti_bytes(dims, sform, &voxels);
        let s = segmentation::open(
            &[NamedBytes {
                name: "t.nii",
                bytes: &bytes,
            }],
            None,
            &OpenOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        s.into_iter().next().expect("one structure")
    };
    let (a, b) = (extract(plain), extract(oblique));
    assert_sound("plain", &a);
    assert_sound("oblique", &b);
    assert_eq!(a.mesh.positions.len(), b.mesh.positions.len());
    for (p, q) in a.mesh.positions.iter().zip(&b.mesh.positions) {
        let want: [f64; 3] = std::array::from_fn(|r| {
            (0..3)
                .map(|k| oblique[r][k] as f64 * p[k] as f64)
                .sum::<f64>()
                + oblique[r][3] as f64
        });
        for k in 0..3 {
            assert!((q[k] as f64 - want[k]).abs() < 1e-4, "{q:?} vs {want:?}");
        }
    }
    let det = 0.7 * 1.1 * 2.5;
    assert!((b.mesh.signed_volume() / a.mesh.signed_volume() - det).abs() < 1e-4);
    for (got, want) in b.voxel_size.iter().zip([0.7, 1.1, 2.5]) {
        assert!((got - want).abs() < 1e-6);
    }
}

#[test]
fn several_mask_files_are_one_structure_each_named_by_the_file() {
    let files = [
        "synthetic/sphere_r20_mask.nii.gz",
        "synthetic/bent_tube_r3.5_mask.nii.gz",
    ];
    let contents: Vec<Vec<u8>> = files.iter().map(|f| read(f)).collect();
    let named: Vec<NamedBytes> = files
        .iter()
        .zip(&contents)
        .map(|(name, bytes)| NamedBytes { name, bytes })
        .collect();
    let s =
        segmentation::open(&named, None, &OpenOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = s.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["Sphere r20 mask", "Bent tube r3.5 mask"]);
    assert_ne!(s[0].color, s[1].color);
    for st in &s {
        assert_sound("masks", st);
    }
}
