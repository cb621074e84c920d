//! The image under the surfaces: a CT on the segmentation's grid is added to the case, checked,
//! windowed, carried through the case glTF, and its slice's edges lie where the surfaces cut.

use std::sync::Arc;

use meshsmooth::case::{self, from_gltf_scene, smooth_structure, Case, WindowPreset};
use meshsmooth::export::{write_case, CaseGltfOptions};
use std::io::Write;

use flate2::{write::GzEncoder, Compression};
use meshsmooth::io::{load_gltf_scene, load_label_map, LabelMap, LabelMapOptions};
use meshsmooth::session::Session;
use meshsmooth::worker::NamedFile;

/// [`Case::add_image`] of one file.
fn add_one(
    case: &mut Case,
    bytes: &[u8],
    name: &str,
    preset: WindowPreset,
    max_voxels: usize,
) -> Result<(), String> {
    case.add_image(&[(name, bytes)], name, preset, max_voxels)
}

/// [`Session::begin_image`] of one file.
fn begin_one(
    session: &mut Session,
    name: &str,
    bytes: Vec<u8>,
    preset: WindowPreset,
) -> Result<(), String> {
    let file = NamedFile {
        name: name.to_string(),
        bytes,
    };
    session.begin_image(vec![file], preset)
}

#[path = "common/label_maps.rs"]
mod label_maps;

#[path = "common/nifti.rs"]
mod nifti;

const PHANTOM: &str = "labelmaps/case_phantom_shared.nii.gz";

/// Hounsfield units by label: background, liver, portal vein, tumour, kidney. Far apart in the
/// soft-tissue window, so every boundary is an edge in the image.
const HU: [i16; 5] = [-150, 60, 220, -60, 150];

fn phantom_map() -> LabelMap {
    load_label_map(
        &label_maps::read(PHANTOM),
        PHANTOM,
        &LabelMapOptions::default(),
    )
    .expect("the phantom opens")
}

/// Each voxel of the phantom its label's HU, int16 little-endian.
fn phantom_hu(map: &LabelMap) -> Vec<u8> {
    let layer = &map.layers[0];
    (layer.codes.iter())
        .flat_map(|&code| HU[layer.values[code as usize] as usize].to_le_bytes())
        .collect()
}

/// A synthetic CT of the phantom as NIfTI on the label map's grid moved by `shift` mm.
fn phantom_ct(shift: [f32; 3]) -> Vec<u8> {
    phantom_ct_slices(shift, 0..phantom_map().dims[2])
}

/// [`phantom_ct`] cropped to `slices` along k, in place: its origin moved by whole slices, as a
/// CT cropped to the body (or a segmentation cropped to its segments) is.
fn phantom_ct_slices(shift: [f32; 3], slices: std::ops::Range<usize>) -> Vec<u8> {
    let map = phantom_map();
    let sform: [[f32; 4]; 3] = std::array::from_fn(|r| {
        let m = &map.affine.0[r];
        let origin = m[3] + slices.start as f64 * m[2];
        std::array::from_fn(|c| {
            if c == 3 {
                origin as f32 + shift[r]
            } else {
                m[c] as f32
            }
        })
    });
    let [i, j, _] = map.dims;
    let dims = [i, j, slices.len()];
    let mut bytes = nifti::nifti_header(dims, sform, map.spacing().map(|s| s as f32));
    bytes[70..72].copy_from_slice(&4i16.to_le_bytes()); // int16
    bytes[72..74].copy_from_slice(&16i16.to_le_bytes());
    let plane = i * j * 2;
    bytes.extend(&phantom_hu(&map)[slices.start * plane..slices.end * plane]);
    bytes
}

/// The same CT as 3D Slicer saves a volume: NRRD, gzip, in LPS.
fn phantom_ct_nrrd() -> Vec<u8> {
    let map = phantom_map();
    let lps = |v: [f64; 3]| format!("({},{},{})", -v[0], -v[1], v[2]);
    let column = |c: usize| std::array::from_fn(|r| map.affine.0[r][c]);
    let [i, j, k] = map.dims;
    let header = format!(
        "NRRD0004\n# made by tests/case_image.rs\ntype: short\ndimension: 3\n\
         space: left-posterior-superior\nsizes: {i} {j} {k}\n\
         space directions: {} {} {}\nkinds: domain domain domain\nendian: little\n\
         encoding: gzip\nspace origin: {}\n\n",
        lps(column(0)),
        lps(column(1)),
        lps(column(2)),
        lps(column(3)),
    );
    let mut gz = GzEncoder::new(header.into_bytes(), Compression::fast());
    gz.write_all(&phantom_hu(&map)).expect("gzip");
    gz.finish().expect("gzip")
}

fn phantom_with_image() -> Case {
    let mut case = label_maps::phantom_case();
    let ct = phantom_ct([0.0; 3]);
    add_one(
        &mut case,
        &ct,
        "scans/ct.nii",
        WindowPreset::CtSoftTissue,
        case::DEFAULT_IMAGE_VOXELS,
    )
    .expect("the CT lies on the phantom's grid");
    case
}

#[test]
fn the_image_is_windowed_and_read_back_from_the_case_gltf_as_written() {
    let case = phantom_with_image();
    let image = case.image.as_ref().expect("added");
    assert_eq!(image.source, "ct.nii", "the file's name only");
    assert_eq!(image.dims, [160, 140, 48]);
    // Soft tissue: -160 HU black, 240 HU white.
    let grey = |hu: f32| ((hu + 160.0) / 400.0 * 255.0).round() as u8;
    let mut levels: Vec<u8> = image.voxels.clone();
    levels.sort_unstable();
    levels.dedup();
    assert_eq!(levels, {
        let mut l: Vec<u8> = HU.iter().map(|&h| grey(f32::from(h))).collect();
        l.sort_unstable();
        l
    });
    let bytes = write_case(&case, &CaseGltfOptions::default()).expect("written");
    let scene = load_gltf_scene(&bytes, "case.glb").expect("reads");
    let back = from_gltf_scene(scene, "case.glb").expect("a case");
    assert_eq!(back.image, case.image);
    assert_eq!(back.structures.len(), case.structures.len());
}

#[test]
fn a_slicer_nrrd_volume_reads_as_the_same_image_as_the_nifti() {
    let nifti = phantom_with_image().image.expect("added");
    let mut case = label_maps::phantom_case();
    (add_one(
        &mut case,
        &phantom_ct_nrrd(),
        "scans/ct.nrrd",
        WindowPreset::CtSoftTissue,
        case::DEFAULT_IMAGE_VOXELS,
    ))
    .expect("the NRRD lies on the phantom's grid");
    let nrrd = case.image.expect("added");
    assert_eq!(nrrd.source, "ct.nrrd");
    assert_eq!((nrrd.dims, &nrrd.voxels), (nifti.dims, &nifti.voxels));
    let (a, b) = (nrrd.affine.0.as_flattened(), nifti.affine.0.as_flattened());
    assert!(
        a.iter().zip(b).all(|(a, b)| (a - b).abs() < 1e-6),
        "{a:?} {b:?}"
    );
}

#[test]
fn a_freesurfer_volume_reads_as_an_image_on_the_grid_of_its_segmentation() {
    // FreeSurfer's T1.mgz lies on its aseg.mgz's grid; the aseg itself stands in for it here.
    let aseg = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/phantom_aseg.mgz"
    ))
    .expect("the aseg MGZ");
    let mut case = label_maps::phantom_case();
    (add_one(&mut case, &aseg, "T1.mgz", WindowPreset::MriAuto, 1 << 24)).expect("on the grid");
    let image = case.image.expect("added");
    assert_eq!(
        (image.source.as_str(), image.dims),
        ("T1.mgz", [160, 140, 48])
    );
    let grid = phantom_map().affine;
    let (a, b) = (image.affine.0.as_flattened(), grid.0.as_flattened());
    assert!(
        a.iter().zip(b).all(|(a, b)| (a - b).abs() < 1e-4),
        "{a:?} {b:?}"
    );
    assert!(image.voxels.contains(&255) && image.voxels.contains(&0));
    let mut case = label_maps::phantom_case();
    let error = (add_one(&mut case, &aseg, "T1.stl", WindowPreset::MriAuto, 1 << 24))
        .expect_err("no image format");
    assert!(
        error.contains("cannot tell the image format of 'T1.stl'"),
        "{error}"
    );
}

/// The page's session reads the image in a worker against the open case's grids; a refusal
/// keeps the image it had.
#[test]
fn the_page_session_adds_the_image_keeps_it_on_a_refusal_and_removes_it() {
    let mut session = Session::default();
    let refused = begin_one(
        &mut session,
        "ct.nrrd",
        phantom_ct_nrrd(),
        WindowPreset::CtBone,
    );
    assert!(refused
        .expect_err("nothing open")
        .contains("open the segmentation first"));
    session.begin_open(
        "case_phantom_shared.seg.nrrd",
        label_maps::read("labelmaps/case_phantom_shared.seg.nrrd"),
    );
    session.poll_opening().expect("done").expect("opens");
    assert!(session.case().as_case().image.as_ref().is_none());
    let nrrd = phantom_ct_nrrd();
    (begin_one(
        &mut session,
        "scans/ct.nrrd",
        nrrd.clone(),
        WindowPreset::CtSoftTissue,
    ))
    .expect("asked");
    session.poll_opening().expect("done").expect("read");
    let image = session.case().as_case().image.clone().expect("added");
    let mut case = label_maps::phantom_case();
    add_one(
        &mut case,
        &nrrd,
        "ct.nrrd",
        WindowPreset::CtSoftTissue,
        1 << 24,
    )
    .expect("added");
    assert_eq!(Some(&image), case.image.as_ref());
    let moved = phantom_ct([0.0, 0.0, 1.0]);
    (begin_one(&mut session, "moved.nii", moved, WindowPreset::CtSoftTissue)).expect("asked");
    let error = session
        .poll_opening()
        .expect("done")
        .expect_err("moved 1 mm");
    assert!(
        error.starts_with("Cannot open the image moved.nii: the image does not lie")
            && error.contains("1.000 mm"),
        "{error}"
    );
    assert_eq!(
        session.case().as_case().image.as_ref(),
        Some(&image),
        "kept"
    );
    session.remove_image();
    assert!(session.case().as_case().image.as_ref().is_none());
}

#[test]
fn an_image_off_the_grid_or_without_a_segmentation_is_refused_and_the_case_kept() {
    let mut case = label_maps::phantom_case();
    let before = case.clone();
    let moved = phantom_ct([0.0, 0.0, 1.0]);
    let error = (add_one(
        &mut case,
        &moved,
        "ct.nii",
        WindowPreset::CtSoftTissue,
        1 << 24,
    ))
    .expect_err("moved 1 mm, 0.4 of a slice");
    assert!(
        error.starts_with("the image does not lie")
            && error.contains("offset 0.000, 0.000, 1.000 mm"),
        "{error}"
    );
    let error = (add_one(
        &mut case,
        b"not a nifti",
        "ct.nii",
        WindowPreset::CtBone,
        1 << 24,
    ))
    .expect_err("garbage");
    assert!(error.starts_with("NIfTI"), "{error}");
    assert_eq!(case, before);
    let mut surfaces = Case::default();
    let error = (add_one(
        &mut surfaces,
        &phantom_ct([0.0; 3]),
        "ct.nii",
        WindowPreset::CtBone,
        1 << 24,
    ))
    .expect_err("no grid");
    assert!(error.contains("no structure from a label map"), "{error}");
}

#[test]
fn an_image_cropped_on_the_segmentations_lattice_is_placed_where_it_lies() {
    let mut whole = label_maps::phantom_case();
    let ct = phantom_ct([0.0; 3]);
    add_one(
        &mut whole,
        &ct,
        "ct.nii",
        WindowPreset::CtSoftTissue,
        1 << 24,
    )
    .expect("the CT");
    let mut cropped = label_maps::phantom_case();
    let part = phantom_ct_slices([0.0; 3], 10..30);
    add_one(
        &mut cropped,
        &part,
        "part.nii",
        WindowPreset::CtSoftTissue,
        1 << 24,
    )
    .expect("whole slices of the grid");
    let (whole, cropped) = (whole.image.expect("added"), cropped.image.expect("added"));
    assert_eq!(cropped.dims, [whole.dims[0], whole.dims[1], 20]);
    // The same grey at the same places; none outside the crop.
    let grid = phantom_map().affine;
    for k in 10..30 {
        for (i, j) in [(40, 40), (80, 70), (120, 90), (10, 130)] {
            let p = grid.apply([i as f64, j as f64, k as f64]);
            assert_eq!(cropped.sample(p), whole.sample(p), "voxel ({i}, {j}, {k})");
        }
    }
    assert_eq!(cropped.sample(grid.apply([40.0, 40.0, 5.0])), None);
}

#[test]
fn every_grid_of_a_case_is_checked_not_only_the_first() {
    let mut case = label_maps::phantom_case();
    let last = case.structures.last_mut().expect("structures");
    let grid = last.grid.as_mut().expect("from a label map");
    grid.0[2][3] += 1.0;
    let name = last.name.clone();
    let before = case.clone();
    let error = (add_one(
        &mut case,
        &phantom_ct([0.0; 3]),
        "ct.nii",
        WindowPreset::CtSoftTissue,
        1 << 24,
    ))
    .expect_err("off the last structure's grid");
    assert!(
        error.contains("1.000 mm") && error.ends_with(&format!("the grid is {name}'s")),
        "{error}"
    );
    assert_eq!(case, before);
}

#[test]
fn a_large_image_is_reduced_to_the_voxels_asked_for_and_stays_in_place() {
    let mut case = label_maps::phantom_case();
    let ct = phantom_ct([0.0; 3]);
    add_one(
        &mut case,
        &ct,
        "ct.nii",
        WindowPreset::CtSoftTissue,
        100_000,
    )
    .expect("added");
    let image = case.image.clone().expect("added");
    // 160 x 140 x 48 by 3: 54 x 47 x 16 = 40,608 voxels.
    assert_eq!(image.dims, [54, 47, 16]);
    let full = phantom_with_image().image.expect("added");
    // The reduced grid's first cell is the mean of the full grid's first 3 x 3 x 3 voxels.
    let centre = image.affine.apply([0.0; 3]);
    let expected = full.affine.apply([1.0, 1.0, 1.0]);
    assert!(
        (0..3).all(|a| (centre[a] - expected[a]).abs() < 1e-9),
        "{centre:?} {expected:?}"
    );
}

/// Where each triangle of `positions` crosses the plane z = `z`: segments in the plane.
fn cut(positions: &[[f32; 3]], triangles: &[[u32; 3]], z: f64) -> Vec<([f64; 3], [f64; 3])> {
    let mut out = Vec::new();
    for t in triangles {
        let p = t.map(|v| positions[v as usize].map(f64::from));
        let mut ends = Vec::new();
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (za, zb) = (p[a][2] - z, p[b][2] - z);
            if (za < 0.0) != (zb < 0.0) {
                let s = za / (za - zb);
                ends.push(std::array::from_fn(|k| p[a][k] + s * (p[b][k] - p[a][k])));
            }
        }
        if let [a, b] = ends[..] {
            out.push((a, b));
        }
    }
    out
}

/// For each cut segment's midpoint, how far along the outline's in-plane normal (either way)
/// the image's grey level changes by at least `step`: the distance to the slice's edge.
fn edge_distances(
    image: &case::CaseImage,
    segments: &[([f64; 3], [f64; 3])],
    step: f32,
) -> Vec<f64> {
    segments
        .iter()
        .filter_map(|(a, b)| {
            let mid: [f64; 3] = std::array::from_fn(|k| (a[k] + b[k]) / 2.0);
            let d = [b[0] - a[0], b[1] - a[1]];
            let length = d[0].hypot(d[1]);
            (length > 1e-6).then_some(())?;
            let n = [-d[1] / length, d[0] / length];
            let at = |t: f64| image.sample([mid[0] + n[0] * t, mid[1] + n[1] * t, mid[2]]);
            (1..=40)
                .map(|s| s as f64 * 0.05)
                .find(|&t| match (at(t), at(-t)) {
                    (Some(x), Some(y)) => (x - y).abs() >= step,
                    _ => false,
                })
                .or(Some(f64::INFINITY))
        })
        .collect()
}

#[test]
fn the_slice_edges_lie_on_the_surfaces_cut_outline_within_a_voxel() {
    let mut case = phantom_with_image();
    for s in &mut case.structures {
        smooth_structure(s);
    }
    let image = Arc::clone(case.image.as_ref().expect("added"));
    let voxel = 0.78;
    // Planes through the organs at the phantom's slice centres (2.5 mm apart from -40 mm). Near
    // a level between two slices a smoothed cap crosses the plane far (in the plane) from any
    // edge of the interpolated image, though within a voxel of one in 3D.
    for z in [0.0, 20.0, 37.5] {
        for s in &case.structures {
            let staircase = cut(&s.original.positions, &s.original.triangles, z);
            let smoothed = cut(s.positions(), &s.original.triangles, z);
            if staircase.is_empty() {
                continue;
            }
            // The segmentation's own outline runs along the image's label boundaries: within a
            // voxel of an edge (the trilinear slice blurs it over one), wherever it is.
            let worst = edge_distances(&image, &staircase, 30.0)
                .into_iter()
                .fold(0.0, f64::max);
            assert!(
                worst <= voxel,
                "{} at z = {z}: staircase {worst} mm from an edge",
                s.name
            );
            // The smoothed surface's outline: within one voxel.
            let d = edge_distances(&image, &smoothed, 30.0);
            let within = d.iter().filter(|&&x| x <= voxel).count() as f64 / d.len() as f64;
            let worst = d.iter().copied().fold(0.0, f64::max);
            println!(
                "{} z = {z}: {} cut points, {:.1}% within a voxel, worst {worst:.2} mm",
                s.name,
                d.len(),
                100.0 * within
            );
            assert!(
                within >= 0.99 && worst <= 1.5 * voxel,
                "{} at z = {z}: {:.1}% of the outline within a voxel of an edge, worst {worst} mm",
                s.name,
                100.0 * within
            );
        }
    }
}

/// The phantom's CT with every slice twice, at half the slice spacing, over the same field of
/// view; `slices` of those kept (the origin moved with the first).
fn phantom_ct_half_slices(slices: std::ops::Range<usize>) -> Vec<u8> {
    let map = phantom_map();
    let sform: [[f32; 4]; 3] = std::array::from_fn(|r| {
        let m = &map.affine.0[r];
        // The first thin slice's centre lies a quarter of a slice below the first slice's.
        let origin = m[3] - 0.25 * m[2] + slices.start as f64 * 0.5 * m[2];
        [m[0], m[1], 0.5 * m[2], origin].map(|v| v as f32)
    });
    let [i, j, _] = map.dims;
    let spacing = map.spacing();
    let pixdim = [spacing[0], spacing[1], spacing[2] / 2.0].map(|s| s as f32);
    let mut bytes = nifti::nifti_header([i, j, slices.len()], sform, pixdim);
    bytes[70..72].copy_from_slice(&4i16.to_le_bytes()); // int16
    bytes[72..74].copy_from_slice(&16i16.to_le_bytes());
    let (plane, hu) = (i * j * 2, phantom_hu(&map));
    for thin in slices {
        let k = thin / 2;
        bytes.extend(&hu[k * plane..(k + 1) * plane]);
    }
    bytes
}

#[test]
fn an_image_on_another_grid_is_added_where_it_covers_the_structures() {
    let on_grid = phantom_with_image();
    let on_grid = on_grid.image.as_ref().expect("added");
    let mut case = label_maps::phantom_case();
    let slices = 2 * phantom_map().dims[2];
    let thin = phantom_ct_half_slices(0..slices);
    let preset = WindowPreset::CtSoftTissue;
    (add_one(&mut case, &thin, "thin.nii", preset, 1 << 24)).expect("covers the structures");
    let image = case.image.as_ref().expect("added");
    assert_eq!(image.dims[2], slices);
    // At the segmentation's voxel centres, between two thin slices of the same level, the grey
    // levels are those of the CT on the segmentation's grid.
    let map = phantom_map();
    let mut levels = std::collections::BTreeSet::new();
    for k in 0..map.dims[2] {
        for (i, j) in [(40, 50), (80, 70), (100, 60), (120, 90)] {
            let at = map.affine.apply([i as f64, j as f64, k as f64]);
            let (a, b) = (image.sample(at), on_grid.sample(at));
            assert_eq!(a, b, "voxel ({i}, {j}, {k})");
            levels.insert(a.map(|a| a as u8));
        }
    }
    assert!(
        levels.len() >= 3,
        "{levels:?}: more than the background compared"
    );
    // Half the thin slices leave the structures outside: refused, the case kept.
    let before = case.clone();
    let half = phantom_ct_half_slices(0..slices / 2);
    let error = add_one(&mut case, &half, "half.nii", preset, 1 << 24).expect_err("half");
    assert!(
        error.starts_with("the image, on another voxel grid")
            && error.contains("does not cover the segmentation"),
        "{error}"
    );
    assert_eq!(case, before);
}
