//! A DICOM image series (one CT slice a file, written by pydicom: tests/data/make_dicom_series.py)
//! read as the image under a case: the same voxels and world frame as its NIfTI twin, whatever
//! the files' order, and refused, naming the file or the reason, when its slices cannot be one
//! image.

use meshsmooth::case::{CaseImage, WindowPreset};
use meshsmooth::io::{load_image, load_image_series, ImageVolume, SeriesError};
use meshsmooth::session::Session;
use meshsmooth::worker::NamedFile;
use std::path::{Path, PathBuf};

#[path = "common/cli.rs"]
mod common_cli;

#[path = "common/label_maps.rs"]
mod label_maps;

#[path = "common/dicom.rs"]
mod dicom;

const ALL: usize = usize::MAX;

fn folder(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/dicom_series")
        .join(name)
}

/// The files of a series folder, sorted by name (not slice order: the names are hashes).
fn slices(name: &str) -> Vec<(String, Vec<u8>)> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(folder(name))
        .expect("the series folder")
        .map(|e| e.expect("an entry").path())
        .collect();
    paths.sort();
    (paths.iter())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(p).expect("a slice"))
        })
        .collect()
}

fn read(files: &[(String, Vec<u8>)], max_voxels: usize) -> Result<ImageVolume, SeriesError> {
    let named: Vec<(&str, &[u8])> = (files.iter())
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    load_image_series(&named, max_voxels)
}

fn twin(max_voxels: usize) -> ImageVolume {
    let bytes = std::fs::read(folder("oblique.nii.gz")).expect("the NIfTI twin");
    load_image(&bytes, "oblique.nii.gz", max_voxels).expect("the twin reads")
}

fn assert_same(got: &ImageVolume, want: &ImageVolume) {
    assert_eq!(got.dims, want.dims);
    assert_eq!(got.source_dims, want.source_dims);
    assert_eq!(
        got.values, want.values,
        "the voxels, slice by slice rescaled"
    );
    for (affine, other) in [
        (&got.affine, &want.affine),
        (&got.source_affine, &want.source_affine),
    ] {
        for (r, row) in affine.0.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                // The DICOM writes directions to 9 decimals and positions to 6.
                assert!(
                    (v - other.0[r][c]).abs() < 1e-5,
                    "{:?} vs {:?}",
                    affine,
                    other
                );
            }
        }
    }
}

#[test]
fn an_oblique_series_reads_as_its_nifti_twin_in_any_file_order() {
    let files = slices("oblique");
    assert_eq!(files.len(), 12);
    let image = read(&files, ALL).expect("the series reads");
    assert_eq!(image.dims, [24, 20, 12]);
    assert_same(&image, &twin(ALL));
    let mut reversed = files.clone();
    reversed.reverse();
    assert_same(&read(&reversed, ALL).expect("reversed"), &twin(ALL));
    // Reduced to fit, as any image is, by the same whole factor as the twin.
    let small = read(&files, 1000).expect("reduced");
    assert!(small.dims.iter().product::<usize>() <= 1000);
    assert_same(&small, &twin(1000));
}

#[test]
fn one_slice_reads_as_an_image_of_one_slice() {
    let files = slices("oblique");
    let (name, bytes) = &files[0];
    let image = load_image(bytes, name, ALL).expect("one slice");
    assert_eq!(image.dims, [24, 20, 1]);
    let values: std::collections::HashSet<i32> = image.values.iter().map(|&v| v as i32).collect();
    assert!(values.len() > 2, "the slice's HU: {values:?}");
}

fn refusal(files: &[(String, Vec<u8>)]) -> String {
    read(files, ALL).expect_err("refused").to_string()
}

#[test]
fn slices_that_cannot_be_one_image_are_refused_naming_the_files() {
    let gap = refusal(&slices("gap"));
    assert!(
        gap.contains("not evenly spaced") && gap.contains(".dcm"),
        "{gap}"
    );
    let tilted = refusal(&slices("tilted"));
    assert!(
        tilted.contains("gantry tilt") && tilted.contains(".dcm"),
        "{tilted}"
    );

    let mut mixed = slices("oblique");
    mixed.push(slices("gap").remove(0));
    let mixed = refusal(&mixed);
    assert!(mixed.contains("different series"), "{mixed}");

    let mut twice = slices("oblique");
    let mut copy = twice[3].clone();
    copy.0 = "copy.dcm".into();
    twice.push(copy);
    let twice = refusal(&twice);
    assert!(
        twice.contains("same position") && twice.contains("copy.dcm"),
        "{twice}"
    );

    assert!(refusal(&[]).contains("no slice"));
}

#[test]
fn a_broken_or_foreign_file_in_a_series_is_named() {
    let mut files = slices("oblique");
    let (name, bytes) = files[5].clone();
    files[5].1.truncate(bytes.len() - 100);
    let cut = refusal(&files);
    assert!(cut.starts_with(&format!("{name}: DICOM image:")), "{cut}");

    let mut files = slices("oblique");
    let seg = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/dicom_seg/phantom.dcm"),
    )
    .expect("a SEG");
    files.push(("seg.dcm".into(), seg));
    let seg = refusal(&files);
    assert!(
        seg.starts_with("seg.dcm:") && seg.contains("DICOM SEG"),
        "{seg}"
    );

    let mut files = slices("oblique");
    files.push(("notes.txt".into(), b"not a slice".to_vec()));
    let text = refusal(&files);
    assert!(
        text.starts_with("notes.txt:") && text.contains("DICM"),
        "{text}"
    );

    let mut files = slices("oblique");
    let map = common_cli::data("labelmaps/case_phantom_shared.nii.gz");
    files.insert(
        0,
        (
            "map.nii.gz".into(),
            std::fs::read(map).expect("a label map"),
        ),
    );
    let map = refusal(&files);
    assert!(
        map.starts_with("map.nii.gz:") && map.contains("DICM"),
        "{map}"
    );
}

/// Each slice of `files` with `(0028,0101)` Bits Stored and `(0028,0102)` High Bit set (the
/// files are explicit VR little endian: tag, "US", length 2, value) and the top 4 bits of every
/// 16-bit pixel (the file's last bytes) set to 1010, as an overlay there would.
fn twelve_bits(files: &mut [(String, Vec<u8>)], high_bit: u16) {
    let element = |e: u8| [0x28, 0x00, e, 0x01, b'U', b'S', 0x02, 0x00];
    for (name, bytes) in files.iter_mut() {
        for (e, value) in [(0x01, 12u16), (0x02, high_bit)] {
            let at = (bytes.windows(8).position(|w| w == element(e)))
                .unwrap_or_else(|| panic!("{name}: no (0028,01{e:02x})"));
            bytes[at + 8..at + 10].copy_from_slice(&value.to_le_bytes());
        }
        let plane = 24 * 20 * 2;
        let start = bytes.len() - plane;
        for pixel in bytes[start..].chunks_exact_mut(2) {
            assert!(pixel[1] < 0x08, "{name}: a value beyond 11 bits");
            pixel[1] |= 0xA0;
        }
    }
}

#[test]
fn only_the_bits_stored_are_read() {
    let mut files = slices("oblique");
    twelve_bits(&mut files, 11);
    assert_same(&read(&files, ALL).expect("12 bits of 16"), &twin(ALL));
    let mut files = slices("oblique");
    twelve_bits(&mut files, 15);
    let e = refusal(&files);
    assert!(e.contains("12 bits stored of 16, high bit 15"), "{e}");
}

/// The oblique series as RLE Lossless (tests/data/make_dicom_compressed.py): two segments a 16-bit
/// frame. A broken frame is refused naming its file.
#[test]
fn an_rle_series_reads_as_the_uncompressed_one() {
    let files = slices("oblique_rle");
    assert_eq!(files.len(), 12);
    assert_same(&read(&files, ALL).expect("the RLE series"), &twin(ALL));
    let refused = |index: usize, value: u32, words: &str| {
        let mut files = slices("oblique_rle");
        files[3].1 = dicom::with_rle_word(&files[3].1, index, value);
        let e = refusal(&files);
        assert!(
            e.starts_with(&format!("{}: DICOM image:", files[3].0)),
            "{e}"
        );
        assert!(e.contains(words), "wanted '{words}' in: {e}");
    };
    refused(0, 3, "3 segments for samples of 2 byte(s)");
    refused(2, 60_000, "out of order or off the fragment");
    refused(2, 66, "segment 1 holds fewer than the frame's 480 pixels");
}

/// The oblique series compressed losslessly in `folder` reads as the uncompressed one, a frame
/// over two fragments as over one.
fn assert_reads_as_the_twin(folder: &str) {
    assert_same(&read(&slices(folder), ALL).expect("lossless"), &twin(ALL));
    let mut split = slices(folder);
    for (_, bytes) in &mut split {
        *bytes = dicom::with_first_fragment_split(bytes, 100);
    }
    assert_same(&read(&split, ALL).expect("split"), &twin(ALL));
}

/// How far (mean, most; HU) the phantom CT's slices compressed with loss in `folder` read from
/// the uncompressed ones, on the same grid.
fn lossy_off(folder: &str) -> (f32, f32) {
    let plain = read(&slices("phantom_ct"), ALL).expect("uncompressed");
    let lossy = read(&slices(folder), ALL).expect("lossy");
    assert_eq!(lossy.dims, plain.dims);
    assert_eq!(lossy.affine, plain.affine);
    let off: Vec<f32> = (lossy.values.iter().zip(&plain.values))
        .map(|(a, b)| (a - b).abs())
        .collect();
    let mean = off.iter().sum::<f32>() / off.len() as f32;
    (mean, off.iter().copied().fold(0.0, f32::max))
}

/// The series in `folder` with its fourth slice changed by `change` is refused naming that
/// slice, in `words`.
fn assert_refused(folder: &str, change: &dyn Fn(&mut [u8]), words: &str) {
    let mut files = slices(folder);
    change(&mut files[3].1[..]);
    let e = refusal(&files);
    assert!(
        e.starts_with(&format!("{}: DICOM image:", files[3].0)),
        "{e}"
    );
    assert!(e.contains(words), "wanted '{words}' in: {e}");
}

/// Cuts a slice's first fragment short: its last bytes, the codestream's end marker (and the
/// padding after it), gone
/// (zeros in their place, as a copy that stopped early would leave them).
fn cut_short(b: &mut [u8]) {
    let at = dicom::first_fragment(b);
    let length = u32::from_le_bytes(b[at - 4..at].try_into().unwrap()) as usize;
    let end = at + length;
    let fragment = &b[at..end];
    assert!(
        (fragment.strip_suffix(&[0]).unwrap_or(fragment)).ends_with(&[0xFF, 0xD9]),
        "the fragment ends the codestream (padded to an even length or not)"
    );
    b[end - 64..end].fill(0);
}

/// Its first fragment's first two bytes made those of a GIF.
fn not_a_codestream(b: &mut [u8]) {
    let at = dicom::first_fragment(b);
    b[at..at + 2].copy_from_slice(b"GI");
}

/// The oblique series as JPEG Lossless (GDCM's codestreams) reads as the uncompressed one; the
/// phantom CT's slices as lossy JPEG Baseline (8-bit) within a few stored units of theirs. A
/// frame whose size is not the header's, that is no JPEG or that is cut short is refused naming
/// its file.
#[test]
fn jpeg_series_read_as_the_uncompressed_ones() {
    assert_reads_as_the_twin("oblique_jpeg");
    let (mean, most) = lossy_off("phantom_ct_jpeg");
    eprintln!("JPEG baseline: mean {mean} HU, most {most} HU off");
    // A stored unit is 10 HU.
    assert!(mean < 2.0 && most <= 80.0, "mean {mean} HU, most {most} HU");

    let frame_header = |bytes: &[u8]| {
        let start = dicom::first_fragment(bytes);
        start + (bytes[start..].windows(2).position(|w| w == [0xFF, 0xC3])).expect("SOF3")
    };
    let columns = |b: &mut [u8]| {
        let at = frame_header(b) + 7;
        b[at..at + 2].copy_from_slice(&25u16.to_be_bytes());
    };
    let refused = |change: &dyn Fn(&mut [u8]), words| assert_refused("oblique_jpeg", change, words);
    refused(&columns, "25 x 20 pixels of 1 component(s) and 16 bits");
    refused(
        &not_a_codestream,
        "JPEG frame 1: the codestream does not start",
    );
    refused(
        &cut_short,
        "JPEG frame 1: the codestream ends without a JPEG end of image",
    );
}

/// The oblique series (signed 16-bit) as JPEG 2000 Lossless (GDCM's OpenJPEG codestreams)
/// reads as the uncompressed one; the phantom CT's slices as lossy JPEG 2000 within a few stored
/// units of theirs. A frame whose size is not the header's, that is no JPEG 2000 or that is cut
/// short is refused naming its file.
#[test]
fn jpeg_2000_series_read_as_the_uncompressed_ones() {
    assert_reads_as_the_twin("oblique_j2k");
    let (mean, most) = lossy_off("phantom_ct_j2k");
    eprintln!("JPEG 2000 at 20:1: mean {mean} HU, most {most} HU off");
    assert!(
        mean < 2.0 && most <= 150.0,
        "mean {mean} HU, most {most} HU"
    );

    let columns = |b: &mut [u8]| {
        let at = dicom::first_fragment(b) + 8;
        b[at..at + 4].copy_from_slice(&25u32.to_be_bytes());
    };
    let refused = |change: &dyn Fn(&mut [u8]), words| assert_refused("oblique_j2k", change, words);
    refused(&columns, "25 x 20 pixels of 1 component(s) and 16 bits");
    refused(
        &not_a_codestream,
        "JPEG 2000 frame 1: no JPEG 2000 codestream",
    );
    refused(
        &cut_short,
        "JPEG 2000 frame 1: the codestream ends without its end of codestream marker",
    );
}

/// The oblique series as JPEG-LS Lossless (GDCM's CharLS codestreams) reads as the uncompressed
/// one; the phantom CT's slices as near-lossless JPEG-LS (an error bound of 2 stored units)
/// within that bound of theirs. A frame whose size is not the header's, that is no JPEG-LS or
/// that is cut short is refused naming its file.
#[test]
fn jpeg_ls_series_read_as_the_uncompressed_ones() {
    assert_reads_as_the_twin("oblique_jls");
    let (mean, most) = lossy_off("phantom_ct_jls");
    eprintln!("JPEG-LS near-lossless: mean {mean} HU, most {most} HU off");
    // A stored unit is 10 HU: off by the bound at most, and off somewhere (it is lossy).
    assert!(most <= 20.0 && mean > 0.0, "mean {mean} HU, most {most} HU");

    let columns = |b: &mut [u8]| {
        let start = dicom::first_fragment(b);
        let sof = (b[start..].windows(2).position(|w| w == [0xFF, 0xF7])).expect("SOF55");
        let at = start + sof + 7;
        b[at..at + 2].copy_from_slice(&25u16.to_be_bytes());
    };
    let refused = |change: &dyn Fn(&mut [u8]), words| assert_refused("oblique_jls", change, words);
    refused(&columns, "25 x 20 pixels of 1 component(s) and 16 bits");
    refused(
        &not_a_codestream,
        "JPEG-LS frame 1: the codestream does not start",
    );
    refused(&cut_short, "JPEG-LS frame 1: truncated JPEG-LS stream");
}

/// `case build --image FOLDER`: the series' image in the case, the same as from its twin and
/// from a DICOM export's folder above it; a tilted series, an export of two series and
/// subfolders without files refused naming the slice or folder, with no case written.
#[test]
fn case_build_takes_a_series_folder_as_the_image() {
    let twin_path = folder("oblique.nii.gz").display().to_string();
    let build = |image: &Path, out: &Path| {
        common_cli::meshsmooth(&[
            "case",
            "build",
            &twin_path,
            "--level",
            "0",
            "--image",
            &image.display().to_string(),
            "-o",
            &out.display().to_string(),
            "--json",
        ])
    };
    let from_series = common_cli::json(&build(&folder("oblique"), &common_cli::tmp("s.glb")));
    let from_twin = common_cli::json(&build(&folder("oblique.nii.gz"), &common_cli::tmp("t.glb")));
    let (a, b) = (&from_series["image"], &from_twin["image"]);
    assert_eq!(a["source"], "oblique");
    assert_eq!(a["dims"], serde_json::json!([24, 20, 12]));
    for key in ["dims", "preset", "window", "bytes"] {
        assert_eq!(a[key], b[key], "{key}");
    }

    let out = common_cli::tmp("tilted.glb");
    let refused = build(&folder("tilted"), &out);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("tilted") && stderr.contains("gantry tilt"),
        "{stderr}"
    );
    assert!(!out.exists());

    // A DICOM export's folder above the series' own, with its DICOMDIR and a hidden file: the
    // series read from its subfolder as from its own folder.
    let export = common_cli::tmp("export_above_the_series");
    let _ = std::fs::remove_dir_all(&export);
    copy_series(&folder("oblique"), &export.join("PATIENT/STUDY/SERIES1"));
    std::fs::write(export.join("DICOMDIR"), b"an index, not read").expect("a file");
    std::fs::write(export.join(".DS_Store"), b"Bud1").expect("a file");
    let from_export = common_cli::json(&build(&export, &common_cli::tmp("e.glb")));
    let c = &from_export["image"];
    assert_eq!(c["source"], "export_above_the_series");
    for key in ["dims", "preset", "window", "bytes"] {
        assert_eq!(c[key], a[key], "{key}");
    }

    // Two series in it: refused, naming a slice of each by its path in the export.
    copy_series(&folder("tilted"), &export.join("PATIENT/STUDY/SERIES2"));
    let refused = build(&export, &out);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        stderr.contains("PATIENT/STUDY/SERIES1/") && stderr.contains("PATIENT/STUDY/SERIES2/"),
        "{stderr}"
    );
    assert!(!out.exists());

    // Subfolders that hold no file: said, not "no file" alone.
    let empty = common_cli::tmp("export_without_files");
    std::fs::create_dir_all(empty.join("SERIES1/.hidden")).expect("a temporary folder");
    let refused = build(&empty, &out);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains(
            "export_without_files: neither the folder nor its 1 subfolder(s) hold a file"
        ),
        "{stderr}"
    );
    assert!(!out.exists());
}

/// Copies the files of the series folder `from` into `to`, made with its parents.
fn copy_series(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("a temporary folder");
    for entry in std::fs::read_dir(from).expect("the series") {
        let path = entry.expect("an entry").path();
        std::fs::copy(&path, to.join(path.file_name().expect("a name"))).expect("a copy");
    }
}

/// The page's session reads a series chosen together (its worker on this thread): the
/// phantom's first 24 CT slices under its segmentation, the same grey levels as the NIfTI CT's
/// slices; a tilted series refused naming the slice, the image kept.
#[test]
fn the_page_session_adds_a_series_under_the_phantom() {
    let mut session = Session::default();
    let seg = label_maps::read("labelmaps/case_phantom_shared.seg.nrrd");
    label_maps::open_in_session(&mut session, "case_phantom_shared.seg.nrrd", seg);
    let named = |folder: &str| -> Vec<NamedFile> {
        (slices(folder).into_iter())
            .map(|(name, bytes)| NamedFile { name, bytes })
            .collect()
    };
    (session.begin_image(named("phantom_ct"), WindowPreset::CtSoftTissue)).expect("asked");
    session.poll_opening().expect("done").expect("read");
    let image = session.case().as_case().image.clone().expect("added");
    assert_eq!(image.source, "DICOM series (24 slices)");
    assert_eq!(image.dims, [160, 140, 24]);

    let ct =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/phantom_ct.nii.gz"))
            .expect("the NIfTI CT");
    let mut volume = load_image(&ct, "phantom_ct.nii.gz", ALL).expect("the NIfTI CT reads");
    volume.dims[2] = 24;
    volume.values.truncate(160 * 140 * 24);
    let want = CaseImage::new(&volume, "phantom_ct.nii.gz", WindowPreset::CtSoftTissue);
    assert_eq!(
        image.voxels, want.voxels,
        "the NIfTI's first 24 slices' grey levels"
    );
    let (got, wanted) = (image.affine.0, want.affine.0);
    for (g, w) in got.iter().flatten().zip(wanted.iter().flatten()) {
        assert!((g - w).abs() < 1e-4, "{got:?} {wanted:?}");
    }

    (session.begin_image(named("tilted"), WindowPreset::CtBone)).expect("asked");
    let error = session.poll_opening().expect("done").expect_err("tilted");
    assert!(
        error.starts_with("Cannot open the image DICOM series (12 slices): ")
            && error.contains("gantry tilt"),
        "{error}"
    );
    assert_eq!(
        session.case().as_case().image.as_ref(),
        Some(&image),
        "kept"
    );
}

/// The oblique series in Deflated Explicit VR Little Endian reads as the uncompressed one; a
/// slice whose stream is cut short is refused naming its file.
#[test]
fn a_deflated_series_reads_as_the_uncompressed_one() {
    let files = slices("oblique_deflated");
    assert_eq!(files.len(), 12);
    assert_same(&read(&files, ALL).expect("the deflated series"), &twin(ALL));
    let mut cut = slices("oblique_deflated");
    let len = cut[5].1.len();
    cut[5].1.truncate(len - 100);
    let e = refusal(&cut);
    assert!(e.starts_with(&format!("{}: DICOM image:", cut[5].0)), "{e}");
    assert!(e.contains("does not inflate"), "{e}");
}
