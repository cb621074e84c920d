//! The label maps authors get from FreeSurfer and TotalSegmentator, written with nibabel (by
//! tests/data/make_mgz.py and make_totalseg.py) from the shared NIfTI files: the same voxels,
//! grids and surfaces, their names; broken MGH headers.

use super::build::{gzip, mgh};
use super::{assert_affine_near, error_of, load_named, read, voxel_values};
use meshsmooth::io::Code;
use meshsmooth::segmentation::{self, NamedBytes, OpenOptions, Structure};
use std::io::Read;

const TESTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");

pub(super) fn ours(name: &str) -> Vec<u8> {
    let path = format!("{TESTS}{name}");
    std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn inflate(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(bytes)
        .read_to_end(&mut out)
        .expect("gzip");
    out
}

pub(super) fn open(files: &[(&str, &[u8])], table: Option<&[u8]>) -> Vec<Structure> {
    let files: Vec<NamedBytes> = (files.iter())
        .map(|&(name, bytes)| NamedBytes { name, bytes })
        .collect();
    let table = table.map(|bytes| NamedBytes {
        name: "table.txt",
        bytes,
    });
    segmentation::open(&files, table, &OpenOptions::default()).expect("opens")
}

/// The largest distance between corresponding vertices of two structures' surfaces.
pub(super) fn largest_offset(a: &Structure, b: &Structure) -> f32 {
    assert_eq!(a.mesh.triangles, b.mesh.triangles, "{}", a.name);
    (a.mesh.positions.iter().zip(&b.mesh.positions))
        .map(|(p, q)| (0..3).map(|i| (p[i] - q[i]).abs()).fold(0.0, f32::max))
        .fold(0.0, f32::max)
}

#[test]
fn an_mgz_nibabel_wrote_holds_the_niftis_voxels_grid_and_surfaces() {
    let nifti_bytes = read("JHU-WhiteMatter-labels-1mm.nii.gz");
    let nifti = load_named(&nifti_bytes, "jhu.nii.gz");
    let mgz_bytes = ours("jhu_labels.mgz");
    let mgz = load_named(&mgz_bytes, "jhu_labels.mgz");
    assert_eq!(mgz.dims, nifti.dims);
    assert_eq!(voxel_values(&mgz, 0), voxel_values(&nifti, 0));
    assert_affine_near(&mgz.affine, &nifti.affine.0, 1e-5);
    // Uncompressed, and told by its bytes where the name does not say.
    let raw = inflate(&mgz_bytes);
    assert_eq!(load_named(&raw, "jhu_labels.mgh"), mgz);
    assert_eq!(load_named(&raw, "volume"), mgz);

    let from_nifti = open(&[("jhu.nii.gz", &nifti_bytes)], None);
    let from_mgz = open(&[("jhu.mgz", &mgz_bytes)], None);
    assert_eq!(from_mgz.len(), 48);
    for (m, n) in from_mgz.iter().zip(&from_nifti) {
        assert_eq!(m.label, n.label);
        assert!(largest_offset(m, n) <= 1e-3, "label {}", m.label);
    }
}

#[test]
fn aseg_labels_take_freesurfers_names_below_an_authors_table() {
    let phantom_bytes = read("case_phantom_shared.nii.gz");
    let mgz_bytes = ours("phantom_aseg.mgz");
    let structures = open(&[("phantom_aseg.mgz", &mgz_bytes)], None);
    let named: Vec<(i64, &str)> = (structures.iter())
        .map(|s| (s.label, s.name.as_str()))
        .collect();
    assert_eq!(
        named,
        [
            (10, "Left-Thalamus"),
            (17, "Left-Hippocampus"),
            (53, "Right-Hippocampus"),
            (2035, "ctx-rh-insula")
        ]
    );
    let hippocampus = [220.0, 216.0, 20.0].map(|c: f32| c / 255.0);
    assert_eq!(structures[1].color, hippocampus);
    // The aseg labels carry their SNOMED CT codes; the cortical parcel has none in the table.
    let coded: Vec<Option<(&str, &str)>> = (structures.iter())
        .map(|s| {
            (s.codes.as_ref()).map(|c| {
                (
                    c.kind.value.as_str(),
                    c.modifier.as_ref().map_or("", |m| m.meaning.as_str()),
                )
            })
        })
        .collect();
    assert_eq!(
        coded,
        [
            Some(("119406000", "Left")),
            Some(("5366008", "Left")),
            Some(("5366008", "Right")),
            None
        ]
    );
    // The surfaces are the phantom's, its labels 2, 1, 3, 4 renumbered.
    let phantom = open(&[("phantom.nii.gz", &phantom_bytes)], None);
    for (s, p) in structures.iter().zip([1, 0, 2, 3].map(|i| &phantom[i])) {
        assert!(largest_offset(s, p) <= 1e-3, "{}", s.name);
    }
    // The author's table wins where it names a label.
    let table = b"17 Hippocampus 255 0 0\n";
    let renamed = open(&[("phantom_aseg.mgz", &mgz_bytes)], Some(table));
    assert_eq!(renamed[1].name, "Hippocampus");
    assert_eq!(renamed[1].color, [1.0, 0.0, 0.0]);
    assert_eq!(renamed[1].codes, None, "codes follow the name shown");
    assert_eq!(renamed[0].name, "Left-Thalamus");
}

fn expect(bytes: &[u8], name: &str, words: &str) {
    let e = error_of(bytes, name).to_string();
    assert!(e.contains(words), "{name}: expected {words:?} in: {e}");
    assert!(e.starts_with("MGH: "), "{name}: {e}");
}

#[test]
fn a_header_built_here_places_its_grid_as_nibabel_does() {
    let voxels = [0, 1, 1, 0, 2, 2, 0, 0, 3, 0, 0, 0];
    let map = load_named(&mgh([2, 3, 2, 1], 4, 1, [0.5, 1.0, 2.0], &voxels), "a.mgh");
    assert_eq!(voxel_values(&map, 0), voxels.map(i64::from));
    // Centre (10, 20, 30) at voxel dims / 2 = (1, 1.5, 1).
    let expected = [
        [0.5, 0.0, 0.0, 9.5],
        [0.0, 1.0, 0.0, 18.5],
        [0.0, 0.0, 2.0, 28.0],
    ];
    assert_affine_near(&map.affine, &expected, 1e-12);
    // Without goodRASFlag: 1 mm coronal slices, centred on the origin.
    let default = load_named(&mgh([2, 3, 2, 1], 4, 0, [0.5, 1.0, 2.0], &voxels), "a.mgh");
    let lia = [
        [-1.0, 0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0, 1.0],
        [0.0, 1.0, 0.0, -1.5],
    ];
    assert_affine_near(&default.affine, &lia, 1e-12);
}

#[test]
fn broken_mgh_files_are_errors() {
    let voxels = [0i16; 12];
    let good = mgh([2, 3, 2, 1], 4, 1, [1.0; 3], &voxels);
    expect(&good[..60], "a.mgh", "file ends early at byte 60");
    let mut version = good.clone();
    version[3] = 2;
    expect(&version, "a.mgh", "version 2 at byte 0");
    expect(
        &mgh([2, 0, 2, 1], 4, 1, [1.0; 3], &voxels),
        "a.mgh",
        "byte 8: dims[1] = 0",
    );
    expect(
        &mgh([2, 3, 2, 2], 4, 1, [1.0; 3], &voxels),
        "a.mgh",
        "2 frames",
    );
    expect(
        &mgh([2, 3, 2, 1], 2, 1, [1.0; 3], &voxels),
        "a.mgh",
        "data type 2",
    );
    expect(&good[..300], "a.mgh", "bytes of voxel data");
    let nan = mgh([2, 3, 2, 1], 4, 1, [1.0, f32::NAN, 1.0], &voxels);
    expect(&nan, "a.mgh", "not a finite number");
    expect(
        &mgh([2, 3, 2, 1], 4, 1, [1.0, 0.0, 1.0], &voxels),
        "a.mgh",
        "voxel size",
    );
    // A small gzip claiming a large volume is refused before anything is allocated for it.
    let claim = mgh([1024, 1024, 1024, 1], 4, 1, [1.0; 3], &voxels);
    expect(&gzip(&claim), "a.mgz", "header claims");
    let cut = gzip(&good);
    expect(&cut[..cut.len() / 2], "a.mgz", "truncated");
    expect(&gzip(&good[..200]), "a.mgz", "gzip stream is truncated");
}

#[test]
fn a_totalsegmentator_multilabel_nifti_names_its_classes_from_its_extension() {
    // tests/data/make_totalseg.py wrote it as TotalSegmentator does: an XML label table of its
    // 117 classes in a header extension, the phantom renumbered (liver 5, portal vein 64,
    // right kidney 2).
    let gz = ours("totalseg_multilabel.nii.gz");
    let map = load_named(&gz, "totalseg_multilabel.nii.gz");
    assert_eq!(map.segments.len(), 117);
    let phantom = load_named(&read("case_phantom_shared.nii.gz"), "phantom.nii.gz");
    let renumbered: Vec<i64> = (voxel_values(&phantom, 0).iter())
        .map(|v| [0, 5, 64, 5, 2][*v as usize])
        .collect();
    assert_eq!(voxel_values(&map, 0), renumbered);
    // Uncompressed, the extension is read from the bytes in place.
    assert_eq!(load_named(&inflate(&gz), "totalseg_multilabel.nii"), map);

    let structures = open(&[("totalseg_multilabel.nii.gz", &gz)], None);
    let named: Vec<(i64, &str)> = (structures.iter())
        .map(|s| (s.label, s.name.as_str()))
        .collect();
    assert_eq!(
        named,
        [
            (2, "Right kidney"),
            (5, "Liver"),
            (64, "Portal vein and splenic vein")
        ]
    );
    // Not the colours its table cycles through (2 would be blue) but the ones TotalSegmentator
    // gives its classes in DICOM: the right kidney (34, 102, 136), the liver (40, 140, 40).
    let bytes = |s: &Structure| s.color.map(|c| (c * 255.0).round() as u8);
    assert_eq!(bytes(&structures[0]), [34, 102, 136]);
    assert_eq!(bytes(&structures[1]), [40, 140, 40]);
    // Its SNOMED CT codes as TotalSegmentator publishes them for its classes.
    let kidney = structures[0].codes.as_ref().expect("coded");
    assert_eq!(kidney.kind, Code::new("SCT", "64033007", "Kidney"));
    assert_eq!(kidney.modifier, Some(Code::new("SCT", "24028007", "Right")));
    let portal = structures[2].codes.as_ref().expect("coded");
    assert_eq!(
        (portal.kind.value.as_str(), &portal.modifier),
        ("110765007", &None)
    );
}
