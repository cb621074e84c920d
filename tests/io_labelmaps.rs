//! Label maps in: the shared NIfTI and NRRD files against their JSON truth, headers built here
//! (oblique and flipped sforms, qforms, NIfTI-2, big-endian, scaling, float masks, 4D), Slicer's
//! layers and segments, colour tables, and broken inputs, each an error naming what is wrong,
//! found without allocating from the header's claims.

use meshsmooth::io::{
    is_label_map, load, load_label_map, parse_color_table, LabelMapOptions, LoadError,
};
use meshsmooth::io::{Affine, LabelMap};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};

#[path = "io_labelmaps/broken.rs"]
mod broken;
#[path = "io_labelmaps/build.rs"]
mod build;
#[path = "io_labelmaps/dicom_seg.rs"]
mod dicom_seg;
#[path = "io_labelmaps/nrrd_and_tables.rs"]
mod nrrd_and_tables;
#[path = "io_labelmaps/sources.rs"]
mod sources;

use build::{f32s, gzip, i16s, i32s, nrrd, u16s, Nifti, FLOAT32, INT16, INT32, UINT16};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/labelmaps/");

/// Counts this thread's live heap bytes and their peak, so tests can bound what a load holds.
struct Counting;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

fn account(delta: isize) {
    let _ = LIVE.try_with(|l| {
        l.set(l.get() + delta);
        let _ = PEAK.try_with(|p| p.set(p.get().max(l.get())));
    });
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        account(layout.size() as isize);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        account(-(layout.size() as isize));
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        account(new_size as isize - layout.size() as isize);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns its result with the most heap it held at once beyond what was live.
pub fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let start = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(start));
    let out = f();
    (out, (PEAK.with(Cell::get) - start).max(0) as usize)
}

fn read(name: &str) -> Vec<u8> {
    let path = format!("{DATA}{name}");
    std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn load_named(bytes: &[u8], name: &str) -> LabelMap {
    load_label_map(bytes, name, &LabelMapOptions::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Each voxel's label value.
fn voxel_values(map: &LabelMap, layer: usize) -> Vec<i64> {
    let l = &map.layers[layer];
    l.codes.iter().map(|&c| l.values[c as usize]).collect()
}

fn assert_affine_near(a: &Affine, b: &[[f64; 4]; 3], tolerance: f64) {
    for r in 0..3 {
        for c in 0..4 {
            let d = (a.0[r][c] - b[r][c]).abs();
            assert!(d <= tolerance, "affine[{r}][{c}]: {:?} vs {b:?}", a.0);
        }
    }
}

fn json_affine(json: &serde_json::Value) -> [[f64; 4]; 3] {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| json["affine_ras"][r][c].as_f64().expect("a number"))
    })
}

#[test]
fn phantom_nifti_and_seg_nrrd_agree_with_the_json() {
    let json: serde_json::Value =
        serde_json::from_slice(&read("case_phantom_shared.json")).expect("JSON");
    let start = Instant::now();
    let nifti = load_named(
        &read("case_phantom_shared.nii.gz"),
        "case_phantom_shared.nii.gz",
    );
    let nifti_time = start.elapsed();
    let start = Instant::now();
    let seg = load_named(
        &read("case_phantom_shared.seg.nrrd"),
        "case_phantom_shared.seg.nrrd",
    );
    eprintln!("phantom: NIfTI {nifti_time:?}, NRRD {:?}", start.elapsed());
    let dims: Vec<usize> = json["dims"]
        .as_array()
        .expect("dims")
        .iter()
        .map(|d| d.as_u64().unwrap() as usize)
        .collect();
    for map in [&nifti, &seg] {
        assert_eq!(map.dims.to_vec(), dims);
        assert_eq!(map.layers.len(), 1);
        assert_eq!(map.layers[0].values, vec![0, 1, 2, 3, 4]);
        assert_affine_near(&map.affine, &json_affine(&json), 1e-6);
    }
    // The NIfTI's f32 spacings read as the decimals they were written as: the same affine.
    assert_eq!(nifti.affine, seg.affine);
    let values = voxel_values(&nifti, 0);
    assert_eq!(
        values,
        voxel_values(&seg, 0),
        "the same label in every voxel"
    );
    for s in json["structures"].as_array().expect("structures") {
        let label = s["label"].as_i64().unwrap();
        let count = values.iter().filter(|&&v| v == label).count();
        assert_eq!(count as u64, s["voxels"].as_u64().unwrap(), "label {label}");
    }
    assert!(nifti.segments.is_empty());
    assert!(
        nifti.affine.determinant() > 0.0,
        "x and y both flipped: a rotation"
    );
}

#[test]
fn phantom_segments_match_the_colour_table() {
    let seg = load_named(
        &read("case_phantom_shared.seg.nrrd"),
        "case_phantom_shared.seg.nrrd",
    );
    let table = parse_color_table(&read("case_phantom_shared_labels.txt")).expect("table");
    assert_eq!(table.len(), 5);
    assert_eq!(seg.segments.len(), 4);
    for s in &seg.segments {
        let entry = table
            .iter()
            .find(|e| e.value == s.value)
            .expect("in the table");
        assert_eq!(s.name, entry.name);
        assert_eq!(s.layer, 0);
        let (a, b) = (s.color.expect("colour"), entry.color.expect("colour"));
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 1.0 / 255.0,
                "{}: {a:?} vs {b:?}",
                s.name
            );
        }
    }
    let names: Vec<&str> = seg.segments.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["liver", "portal_vein", "tumor", "right_kidney"]);
}

#[test]
fn jhu_atlas_has_48_labels_named_by_its_table() {
    let bytes = read("JHU-WhiteMatter-labels-1mm.nii.gz");
    let start = Instant::now();
    let map = load_named(&bytes, "JHU-WhiteMatter-labels-1mm.nii.gz");
    eprintln!("JHU atlas: {:?}", start.elapsed());
    assert_eq!(map.dims, [182, 218, 182]);
    assert_eq!(map.layers[0].values, (0..=48).collect::<Vec<i64>>());
    // sform (code 2) wins over the qform, whose qfac of -1 would flip k.
    let expect = [
        [1.0, 0.0, 0.0, -91.0],
        [0.0, 1.0, 0.0, -126.0],
        [0.0, 0.0, 1.0, -72.0],
    ];
    assert_eq!(map.affine.0, expect);
    let table = parse_color_table(&read("JHU-WhiteMatter-labels-1mm.nii.txt")).expect("table");
    assert_eq!(table.len(), 49);
    for &v in &map.layers[0].values {
        let entry = table.iter().find(|e| e.value == v).expect("named");
        assert!(entry.color.is_none());
    }
    assert_eq!(table[0].name, "Unclassified");
    assert_eq!(table[2].name, "Pontine_crossing_tract_(a_part_of_MCP)");
    assert_eq!(table[48].name, "Tapetum_L");
}

/// 2 x 3 x 2 voxels, labels 0..=4 in a known pattern.
const PATTERN: [u8; 12] = [0, 1, 2, 0, 3, 4, 4, 0, 0, 1, 1, 2];

fn pattern_values() -> Vec<i64> {
    PATTERN.iter().map(|&v| i64::from(v)).collect()
}

#[test]
fn oblique_flipped_sform_is_read_exactly() {
    // A rotation about z by atan(4/3), i and j flipped, spacing 0.6 x 1.25 x 2.5.
    let srow = [
        [-0.36, 1.0, 0.0, 12.5],
        [-0.48, -0.75, 0.0, -7.25],
        [0.0, 0.0, 2.5, 30.0],
    ];
    let mut file = Nifti::u8([2, 3, 2], &PATTERN).with_sform(srow);
    file.qform_code = 1; // sform wins
    file.quatern = [0.0, 0.0, 1.0, 99.0, 99.0, 99.0];
    let map = load_named(&file.bytes(), "oblique.nii");
    assert_eq!(map.affine.0, srow);
    assert_eq!(voxel_values(&map, 0), pattern_values());
    let gz = load_named(&gzip(&file.bytes()), "oblique.nii.gz");
    assert_eq!(gz, map);
}

#[test]
fn qform_is_used_without_sform() {
    let mut file = Nifti::u8([2, 3, 2], &PATTERN);
    file.qform_code = 1;
    // 90 degrees about z; qfac -1 flips k.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    file.quatern = [0.0, 0.0, h, 10.0, 20.0, 30.0];
    file.pixdim = [-1.0, 2.0, 3.0, 4.0, 1.0, 1.0, 1.0, 1.0];
    let map = load_named(&file.bytes(), "q.nii");
    let expect = [
        [0.0, -3.0, 0.0, 10.0],
        [2.0, 0.0, 0.0, 20.0],
        [0.0, 0.0, -4.0, 30.0],
    ];
    assert_affine_near(&map.affine, &expect, 1e-6);
    // b = c = 0, d = 1: the 180-degree turn a DICOM-derived file has (a = 0).
    file.quatern = [0.0, 0.0, 1.0, 120.0, 95.0, -40.0];
    file.pixdim = [1.0, 0.78, 0.78, 2.5, 1.0, 1.0, 1.0, 1.0];
    let map = load_named(&file.bytes(), "q.nii");
    let expect = [
        [-0.78, 0.0, 0.0, 120.0],
        [0.0, -0.78, 0.0, 95.0],
        [0.0, 0.0, 2.5, -40.0],
    ];
    assert_affine_near(&map.affine, &expect, 1e-12);
}

#[test]
fn without_transform_codes_pixdim_scales_the_grid() {
    let mut file = Nifti::u8([2, 3, 2], &PATTERN);
    file.pixdim[1..4].copy_from_slice(&[0.5, 0.75, 3.0]);
    let map = load_named(&file.bytes(), "plain.nii");
    assert_eq!(map.affine, Affine::scaled([0.5, 0.75, 3.0], [0.0; 3]));
}

#[test]
fn nifti2_and_big_endian_files_read_the_same() {
    let labels: Vec<i16> = vec![0, -3, 7, 0, 7, 7, 1000, 0, -3, 0, 0, 5];
    let srow = [
        [0.0, 0.0, 2.0, 1.5],
        [0.0, -1.5, 0.0, 2.5],
        [1.25, 0.0, 0.0, -3.5],
    ];
    let mut expected = None;
    for version in [1, 2] {
        for big in [false, true] {
            let mut file = Nifti::new([2, 3, 2], INT16, i16s(&labels, big)).with_sform(srow);
            file.big = big;
            if version == 2 {
                file = file.v2();
            }
            let bytes = file.bytes();
            let name = format!("v{version}_{big}.nii");
            let map = load_named(&bytes, &name);
            assert_eq!(map.affine.0, srow, "{name}");
            assert_eq!(map.layers[0].values, vec![0, -3, 5, 7, 1000], "sorted");
            assert_eq!(
                voxel_values(&map, 0),
                labels.iter().map(|&v| i64::from(v)).collect::<Vec<_>>()
            );
            assert_eq!(load_named(&gzip(&bytes), &name), map, "{name} gzipped");
            assert_eq!(*expected.get_or_insert_with(|| map.clone()), map, "{name}");
        }
    }
}

#[test]
fn labels_get_dense_sorted_codes() {
    let labels: [u16; 6] = [0, 700, 3, 700, 65535, 3];
    let map = load_named(
        &Nifti::new([6, 1, 1], UINT16, u16s(&labels, false)).bytes(),
        "a.nii",
    );
    assert_eq!(map.layers[0].values, vec![0, 3, 700, 65535]);
    assert_eq!(map.layers[0].codes, vec![0, 2, 1, 2, 3, 1]);
    // A grid large enough for the direct table, with values beyond it on both sides.
    let pattern = [0, -100_000, 5, 70_000, 5, 0, 65_535, -32_768];
    let labels: Vec<i32> = (0..1 << 16).map(|i| pattern[i % 8]).collect();
    let big = Nifti::new([256, 256, 1], INT32, i32s(&labels, false)).bytes();
    let map = load_named(&big, "b.nii");
    assert_eq!(
        map.layers[0].values,
        [0, -100_000, -32_768, 5, 65_535, 70_000]
    );
    let expect: Vec<i64> = labels.iter().map(|&v| i64::from(v)).collect();
    assert_eq!(voxel_values(&map, 0), expect);
}

#[test]
fn scl_slope_and_inter_scale_integer_labels() {
    let mut file = Nifti::new([4, 1, 1], INT16, i16s(&[-5, 0, 1, 2], false));
    file.slope = 2.0;
    file.inter = 10.0;
    assert_eq!(
        voxel_values(&load_named(&file.bytes(), "s.nii"), 0),
        [0, 10, 12, 14]
    );
    // A slope of 1/3 (as f32) on 0, 3, 6, 9: whole numbers to within rounding.
    let mut file = Nifti::new([4, 1, 1], INT16, i16s(&[0, 3, 6, 9], false));
    file.slope = 1.0 / 3.0;
    assert_eq!(
        voxel_values(&load_named(&file.bytes(), "s.nii"), 0),
        [0, 1, 2, 3]
    );
    // Slope 0 (or NaN) means no scaling, and the intercept is ignored with it.
    for slope in [0.0, f64::NAN] {
        file.slope = slope;
        file.inter = 100.0;
        assert_eq!(
            voxel_values(&load_named(&file.bytes(), "s.nii"), 0),
            [0, 3, 6, 9]
        );
    }
    // A fractional slope that makes fractions: a mask at the level.
    file.slope = 0.1;
    file.inter = 0.0;
    assert_eq!(
        voxel_values(&load_named(&file.bytes(), "s.nii"), 0),
        [0, 0, 1, 1]
    );
}

#[test]
fn float_images_are_masks_at_the_level() {
    let probability = [0.0, 0.2, 0.5, 0.9, f32::NAN, 0.49];
    let file = Nifti::new([6, 1, 1], FLOAT32, f32s(&probability, false));
    let map = load_named(&file.bytes(), "p.nii");
    assert_eq!(voxel_values(&map, 0), [0, 0, 1, 1, 0, 0]);
    assert_eq!(map.layers[0].values, [0, 1]);
    let at = |level| {
        let options = LabelMapOptions { level: Some(level) };
        voxel_values(
            &load_label_map(&file.bytes(), "p.nii", &options).unwrap(),
            0,
        )
    };
    assert_eq!(at(0.3), [0, 0, 1, 1, 0, 1]);
    // Whole-number floats are labels unless a level is asked for.
    let file = Nifti::new([4, 1, 1], FLOAT32, f32s(&[0.0, 2.0, 2.0, 7.0], false));
    assert_eq!(
        voxel_values(&load_named(&file.bytes(), "f.nii"), 0),
        [0, 2, 2, 7]
    );
    assert_eq!(at(0.3).len(), 6);
    let options = LabelMapOptions { level: Some(1.0) };
    let map = load_label_map(&file.bytes(), "f.nii", &options).unwrap();
    assert_eq!(voxel_values(&map, 0), [0, 1, 1, 1]);
    // The first fraction turns the labels read so far into the mask too.
    let file = Nifti::new([4, 1, 1], FLOAT32, f32s(&[3.0, 0.0, 0.25, 0.7], false));
    let map = load_named(&file.bytes(), "f.nii");
    assert_eq!(voxel_values(&map, 0), [1, 0, 0, 1]);
    assert_eq!(map.layers[0].values, [0, 1]);
}

#[test]
fn four_d_with_one_volume_loads_and_two_are_refused() {
    let mut file = Nifti::u8([2, 3, 2], &PATTERN);
    file.dim[0] = 4;
    file.dim[4] = 1;
    assert_eq!(
        voxel_values(&load_named(&file.bytes(), "t.nii"), 0),
        pattern_values()
    );
    file.dim[0] = 5;
    file.dim[4] = 2;
    file.data.extend_from_slice(&PATTERN);
    let e = load_label_map(&file.bytes(), "t.nii", &LabelMapOptions::default()).unwrap_err();
    assert!(e.to_string().contains("2 volumes"), "{e}");
}

#[test]
fn more_than_65535_labels_are_refused() {
    let ok: Vec<i32> = (1..=65535).collect();
    let map = load_named(
        &Nifti::new([255, 257, 1], INT32, i32s(&ok, false)).bytes(),
        "l.nii",
    );
    assert_eq!(map.layers[0].values.len(), 65536);
    assert_eq!(map.layers[0].codes[65534], 65535);
    let too_many: Vec<i32> = (1..=65536).collect();
    let bytes = Nifti::new([256, 256, 1], INT32, i32s(&too_many, false)).bytes();
    let e = load_label_map(&bytes, "l.nii", &LabelMapOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("more than 65535 distinct labels"),
        "{e}"
    );
}

#[test]
fn label_map_names_and_mesh_loading() {
    for name in [
        "a.nii",
        "A.NII.GZ",
        "b.nrrd",
        "c.seg.nrrd",
        "D.Seg.Nrrd",
        "e.nhdr",
    ] {
        assert!(is_label_map(name), "{name}");
    }
    for name in ["a.stl", "nii", "a.nii.zip", "a.gz", "a.txt"] {
        assert!(!is_label_map(name), "{name}");
    }
    let e = load(b"whatever", "scan.nii.gz").unwrap_err().to_string();
    assert!(
        e.contains("is a label map") && e.contains("meshsmooth extract"),
        "{e}"
    );
    let e = load(b"solid x", "mesh.vtk").unwrap_err().to_string();
    assert!(e.contains(".stl .obj .ply") && e.contains(".nii"), "{e}");
    let options = LabelMapOptions::default();
    let e = load_label_map(b"solid x", "part.stl", &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("is a mesh"), "{e}");
    // Other names: told by the bytes. A gzipped file named .nii is read as .nii.gz.
    let file = Nifti::u8([2, 3, 2], &PATTERN).bytes();
    assert_eq!(load_named(&file, "upload.bin").dims, [2, 3, 2]);
    assert_eq!(load_named(&gzip(&file), "scan.nii").dims, [2, 3, 2]);
    let header = "type: uint8\ndimension: 3\nsizes: 2 1 1\nencoding: raw";
    assert_eq!(load_named(&nrrd(header, &[0, 1]), "blob").dims, [2, 1, 1]);
    let e = load_label_map(&[], "x.nrrd", &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("NRRD: the file is empty"), "{e}");
    let nan = LabelMapOptions {
        level: Some(f64::NAN),
    };
    assert!(load_label_map(&file, "x.nii", &nan).is_err());
}

/// A CT-sized grid (512 x 512 x 400 int16, 200 MB of voxels) from gzip: decoded chunk by chunk
/// into codes, so the load holds the codes (2 bytes a voxel) and buffers, never the raw volume.
#[test]
fn ct_sized_gzip_streams_into_codes() {
    let (n, slice) = ([512usize, 512, 400], 512 * 512);
    let mut header = Nifti::new([512, 512, 400], INT16, Vec::new());
    header.pixdim[1..4].copy_from_slice(&[0.7, 0.7, 1.0]);
    let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    use std::io::Write;
    encoder.write_all(&header.bytes()).unwrap();
    let mut plane = vec![0i16; slice];
    for k in 0..n[2] {
        for (at, v) in plane.iter_mut().enumerate() {
            let (i, j) = (at % 512, at / 512);
            let inside = (i as i64 - 256).pow(2) + (j as i64 - 256).pow(2) < 150 * 150;
            *v = if !inside {
                0
            } else if k < 200 {
                1200
            } else {
                -7
            };
        }
        encoder.write_all(&i16s(&plane, false)).unwrap();
    }
    let gz = encoder.finish().unwrap();
    let start = Instant::now();
    let (map, peak) = peak_of(|| load_named(&gz, "ct.nii.gz"));
    let codes = n.iter().product::<usize>() * 2;
    eprintln!(
        "CT-sized: {} MB of gzip in {:?}, peak {} MB (codes {} MB)",
        gz.len() >> 20,
        start.elapsed(),
        peak >> 20,
        codes >> 20
    );
    assert!(
        peak <= codes + (8 << 20),
        "held {peak} bytes for {codes} bytes of codes"
    );
    assert_eq!(map.layers[0].values, [0, -7, 1200]);
    let count = |code| map.layers[0].codes.iter().filter(|&&c| c == code).count();
    assert_eq!(count(1), count(2), "as many -7 slices as 1200 ones");
    assert!(count(1) > 0);
}

/// Parses quickly, and a header's claims never turn into an allocation larger than the input
/// (or, for gzip, a small multiple of it).
pub fn error_of(bytes: &[u8], name: &str) -> LoadError {
    let start = Instant::now();
    let (result, peak) = peak_of(|| load_label_map(bytes, name, &LabelMapOptions::default()));
    let elapsed = start.elapsed();
    assert!(elapsed < Duration::from_secs(2), "{name}: took {elapsed:?}");
    assert!(
        peak <= 4 * bytes.len() + (1 << 20),
        "{name}: held {peak} bytes for a {}-byte input",
        bytes.len()
    );
    match result {
        Ok(m) => panic!("{name}: broken input loaded ({:?})", m.dims),
        Err(e) => e,
    }
}
