//! Broken label maps: each must be an error whose message names what is wrong, found quickly
//! and without allocating from the header's claims; mutated files must never panic.

use super::build::{gzip, mgh, nrrd, Nifti};
use super::{error_of, PATTERN};
use meshsmooth::io::{load_label_map, LabelMapOptions};

fn expect(bytes: &[u8], name: &str, words: &str) {
    let e = error_of(bytes, name).to_string();
    assert!(e.contains(words), "{name}: expected {words:?} in: {e}");
    let format = if name.contains(".nrrd") {
        "NRRD: "
    } else {
        "NIfTI: "
    };
    assert!(e.starts_with(format), "{name}: {e}");
}

fn base() -> Nifti {
    Nifti::u8([2, 3, 2], &PATTERN)
}

fn with(change: impl FnOnce(&mut Nifti)) -> Vec<u8> {
    let mut file = base();
    change(&mut file);
    file.bytes()
}

#[test]
fn broken_nifti_headers_are_errors() {
    let good = base().bytes();
    expect(
        &good[..200],
        "a.nii",
        "file ends early at byte 200: the NIfTI-1 header needs 348",
    );
    expect(&good[..3], "a.nii", "4-byte size");
    let mut bad = good.clone();
    bad[..4].copy_from_slice(&100i32.to_le_bytes());
    expect(&bad, "a.nii", "sizeof_hdr is 100");
    let mut pair = good.clone();
    pair[344..348].copy_from_slice(b"ni1\0");
    expect(&pair, "a.nii", "header/image pair");
    let mut analyze = good.clone();
    analyze[344..348].copy_from_slice(b"\0\0\0\0");
    expect(&analyze, "a.nii", "no 'n+1' magic at byte 344");
    let bad = with(|f| f.dim[0] = 0);
    expect(&bad, "a.nii", "byte 40: dim[0] = 0");
    expect(&with(|f| f.dim[0] = 8), "a.nii", "dim[0] = 8");
    expect(&with(|f| f.dim[2] = 0), "a.nii", "byte 44: dim[2] = 0");
    expect(&with(|f| f.dim[3] = -4), "a.nii", "dim[3] = -4");
    let vector = with(|f| {
        f.dim[0] = 5;
        f.dim[5] = 3;
    });
    expect(&vector, "a.nii", "dim[5] = 3");
    expect(&with(|f| f.vox_offset = 100.0), "a.nii", "vox_offset 100");
    expect(&with(|f| f.vox_offset = 352.5), "a.nii", "vox_offset 352.5");
    let mut past = good[..352].to_vec();
    past[108..112].copy_from_slice(&10000f32.to_le_bytes());
    expect(
        &past,
        "a.nii",
        "starts at byte 10000 (vox_offset), past the end",
    );
    for (code, name) in [
        (128, "RGB24"),
        (1024, "int64"),
        (32, "complex64"),
        (7, "not a NIfTI datatype"),
    ] {
        let bad = with(|f| f.datatype = code);
        expect(
            &bad,
            "a.nii",
            &format!("datatype {code} ({name}) is not supported"),
        );
    }
    let v2 = base().v2().bytes();
    let mut pair = v2.clone();
    pair[4..7].copy_from_slice(b"ni2");
    expect(&pair, "a.nii", "NIfTI-2 header/image pair");
    expect(&v2[..500], "a.nii", "the NIfTI-2 header needs 540 bytes");
}

#[test]
fn bad_sizes_and_affines_are_errors() {
    let good = base().bytes();
    expect(
        &good[..good.len() - 5],
        "a.nii",
        "claims 12 bytes of voxel data but the data can hold at most 7",
    );
    let huge = with(|f| f.dim[1..4].copy_from_slice(&[1000, 1000, 1000]));
    expect(
        &huge,
        "a.nii",
        "claims 1000000000 bytes of voxel data but the data can hold at most 12",
    );
    let beyond = with(|f| f.dim[1..4].copy_from_slice(&[32767, 32767, 32767]));
    expect(&beyond, "a.nii", "more than the 4 GiB limit");
    let beyond2 = Nifti {
        dim: [3, 1 << 40, 1 << 40, 1, 1, 1, 1, 1],
        ..base().v2()
    };
    expect(&beyond2.bytes(), "a.nii", "more than the 4 GiB limit");
    for (v, shown) in [
        (0.0, "voxel size 0 must be positive"),
        (-1.0, "voxel size -1"),
        (f64::NAN, "voxel size NaN"),
    ] {
        expect(
            &with(|f| f.pixdim[2] = v),
            "a.nii",
            &format!("byte 84: pixdim[2]: {shown}"),
        );
        let q = with(|f| {
            f.qform_code = 1;
            f.pixdim[3] = v;
        });
        expect(&q, "a.nii", "pixdim[3]: voxel size");
    }
    let singular = [
        [1.0, 2.0, 0.0, 0.0],
        [1.0, 2.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    expect(
        &base().with_sform(singular).bytes(),
        "a.nii",
        "byte 280: sform (srow_x/y/z): the affine is singular",
    );
    let flat = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    expect(
        &base().with_sform(flat).bytes(),
        "a.nii",
        "voxel size along axis 1 is 0",
    );
    let nan = [
        [1.0, 0.0, 0.0, f64::NAN],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    expect(
        &base().with_sform(nan).bytes(),
        "a.nii",
        "NaN is not a finite number",
    );
    let qnan = with(|f| {
        f.qform_code = 1;
        f.quatern[1] = f64::NAN;
    });
    expect(&qnan, "a.nii", "qform");
    let empty = Nifti::u8([2, 3, 2], &[0; 12]).bytes();
    expect(&empty, "a.nii", "the label map is empty");
    expect(&gzip(&empty), "a.nii.gz", "the label map is empty");
}

#[test]
fn broken_gzip_is_an_error() {
    let good = base().bytes();
    let gz = gzip(&good);
    expect(
        &gz[..gz.len() - 10],
        "a.nii.gz",
        "the gzip stream is truncated",
    );
    expect(&gz[..gz.len() / 2], "a.nii.gz", "truncated");
    expect(&gz[..12], "a.nii.gz", "truncated");
    let mut method = gz.clone();
    method[2] = 7;
    expect(&method, "a.nii.gz", "corrupt gzip data");
    let mut crc = gz.clone();
    let at = crc.len() - 8;
    crc[at] ^= 0xff;
    expect(&crc, "a.nii.gz", "inflated byte 364: corrupt gzip data");
    let mut longer = good.clone();
    longer.extend_from_slice(&[1; 100]);
    expect(
        &gzip(&longer),
        "a.nii.gz",
        "the gzip stream inflates past the 364 bytes the header declares",
    );
    let huge = with(|f| f.dim[1..4].copy_from_slice(&[1000, 1000, 1000]));
    let gz_huge = gzip(&huge[..352]);
    expect(
        &gz_huge,
        "a.nii.gz",
        "claims 1000000352 inflated bytes but the data can hold at most",
    );
    // Several gzip members are one stream (as bgzip writes them).
    let split = [gzip(&good[..200]), gzip(&good[200..])].concat();
    let map = load_label_map(&split, "a.nii.gz", &LabelMapOptions::default()).unwrap();
    assert_eq!(map.dims, [2, 3, 2]);
}

fn nrrd_with(replace: &str, by: &str, data: &[u8]) -> Vec<u8> {
    let header = "type: uint8\ndimension: 3\nsizes: 2 3 2\nencoding: raw";
    assert!(header.contains(replace), "{replace}");
    nrrd(&header.replacen(replace, by, 1), data)
}

#[test]
fn broken_nrrd_headers_are_errors() {
    let n = |replace: &str, by: &str, words: &str| {
        expect(&nrrd_with(replace, by, &PATTERN), "a.seg.nrrd", words)
    };
    n(
        "encoding: raw",
        "encoding: bzip2",
        "encoding \"bzip2\" is not supported",
    );
    n(
        "encoding: raw",
        "encoding: ascii",
        "encoding \"ascii\" is not supported",
    );
    n(
        "encoding: raw",
        "encoding: raw\ndata file: a.raw.gz",
        "line 6: a detached header",
    );
    n(
        "encoding: raw",
        "encoding: raw\nbyte skip: 4",
        "byte skip 4 is not supported",
    );
    n(
        "type: uint8",
        "type: block",
        "type \"block\" is not supported",
    );
    n(
        "type: uint8",
        "type: int64",
        "type \"int64\" is not supported",
    );
    n(
        "type: uint8",
        "content: x",
        "line 6: the header has no 'type' field",
    );
    n("encoding: raw", "", "no 'encoding' field");
    n("dimension: 3", "dimension: 5", "line 3: dimension \"5\"");
    n(
        "sizes: 2 3 2",
        "sizes: 2 3",
        "line 4: 2 sizes for dimension 3",
    );
    n(
        "sizes: 2 3 2",
        "sizes: 2 0 2",
        "each must be a whole number >= 1",
    );
    n(
        "sizes: 2 3 2",
        "sizes: 1000 1000 1000",
        "claims 1000000000 bytes of voxel data but the data can hold at most 12",
    );
    n(
        "sizes: 2 3 2",
        "sizes: 100000 100000 1000",
        "more than the 4 GiB limit",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace: scanner-xyz",
        "space \"scanner-xyz\" is not supported",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace: RAS\nspace directions: (1,0,0) (0,0,0) (0,0,1)",
        "line 7: space directions: the voxel size along axis 1 is 0",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace directions: (1,0,0) (2,0,0) (0,0,1)",
        "the affine is singular",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace directions: (1,0,0) (0,nan,0) (0,0,1)",
        "not a finite vector",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace directions: (1,0,0) (0,1,0)",
        "space directions: 2 entries for dimension 3",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace directions: (1,0,0) none (0,0,1)",
        "axis 1 is none",
    );
    n(
        "encoding: raw",
        "encoding: raw\nspace origin: (1,2)",
        "is not a vector",
    );
    for bad in ["0", "-1", "nan"] {
        let by = format!("encoding: raw\nspacings: 1 {bad} 1");
        n("encoding: raw", &by, "line 6: spacings: voxel size");
    }
    n(
        "encoding: raw",
        "encoding: raw\nendian: middle",
        "endian \"middle\"",
    );
    n(
        "encoding: raw",
        "encoding: raw\nnonsense",
        "line 6: expected 'field: value'",
    );
    n(
        "encoding: raw",
        "encoding: raw\nSegment0_Color:=1 0",
        "Segment0_Color \"1 0\"",
    );
    n(
        "encoding: raw",
        "encoding: raw\nSegment0_LabelValue:=one",
        "Segment0_LabelValue",
    );
    n(
        "encoding: raw",
        "encoding: raw\nSegment0_Layer:=3",
        "line 6: Segment0_Layer 3: the file has 1 layer(s)",
    );
    let four = "dimension: 4\nsizes: 2 3 2 1";
    n(
        "dimension: 3\nsizes: 2 3 2",
        four,
        "tell the list of layers",
    );
    let kinds = format!("{four}\nkinds: domain domain domain domain");
    n(
        "dimension: 3\nsizes: 2 3 2",
        &kinds,
        "exactly one list axis",
    );
    let many = "dimension: 4\nsizes: 2000 1 1 1\nkinds: list domain domain domain";
    n(
        "dimension: 3\nsizes: 2 3 2",
        many,
        "2000 layers: a label map may hold at most 1024",
    );
    let middle = "dimension: 4\nsizes: 2 1 3 2\nkinds: domain list domain domain";
    n(
        "dimension: 3\nsizes: 2 3 2",
        middle,
        "the list of layers is axis 1",
    );
    expect(
        &nrrd_with("type", "type", &[0; 12]),
        "a.nrrd",
        "the label map is empty",
    );
    let short = nrrd_with("type", "type", &PATTERN[..11]);
    expect(&short, "a.nrrd", "at most 11");
    let mut magic = nrrd_with("type", "type", &PATTERN);
    magic[3] = b'X';
    expect(&magic, "a.nrrd", "not NRRD000N");
    let open = b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 3 2\nencoding: raw\n";
    expect(open, "a.nrrd", "does not end with a blank line");
}

#[test]
fn broken_nrrd_gzip_is_an_error() {
    let gz = |data: &[u8]| nrrd_with("encoding: raw", "encoding: gzip", &gzip(data));
    let good = gz(&PATTERN);
    assert!(load_label_map(&good, "a.nrrd", &LabelMapOptions::default()).is_ok());
    expect(
        &good[..good.len() - 4],
        "a.nrrd",
        "the gzip stream is truncated",
    );
    expect(
        &gz(&[PATTERN, PATTERN].concat()),
        "a.nrrd",
        "inflates past the 12 bytes",
    );
    expect(
        &gz(&PATTERN[..10]),
        "a.nrrd",
        "ends after 10 inflated bytes; the header declares 12",
    );
    let huge = nrrd(
        "type: uint8\ndimension: 3\nsizes: 1000 1000 1000\nencoding: gzip",
        &gzip(&[1; 1000]),
    );
    expect(
        &huge,
        "a.nrrd",
        "claims 1000000000 bytes of inflated voxel data but the data can hold at most",
    );
}

/// xorshift64: deterministic, so a failure names a reproducible case.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

#[test]
fn mutated_label_maps_never_panic() {
    let header = "type: short\ndimension: 4\nsizes: 2 2 3 2\nendian: big\nkinds: list domain domain domain\n\
        space: LPS\nspace directions: none (1,0,0) (0,2,0) (0,0,3)\nSegment0_Layer:=1\nencoding: ";
    let data: Vec<u8> = (0..24u16).flat_map(|v| (v % 5).to_be_bytes()).collect();
    let mgh_seed = mgh(
        [2, 3, 2, 1],
        4,
        1,
        [0.5, 1.0, 2.0],
        &[0, 1, 1, 0, 2, 2, 0, 0, 3, 0, 0, 0],
    );
    let mut seeds: Vec<(Vec<u8>, &str)> = vec![
        (base().bytes(), "m.nii"),
        (gzip(&base().bytes()), "m.nii.gz"),
        (base().v2().bytes(), "m.nii"),
        (nrrd(&format!("{header}raw"), &data), "m.nrrd"),
        (nrrd(&format!("{header}gzip"), &gzip(&data)), "m.nrrd"),
        (mgh_seed.clone(), "m.mgh"),
        (gzip(&mgh_seed), "m.mgz"),
    ];
    let mut rng = XorShift(0x5eed_1abe1);
    for (seed, name) in seeds.iter_mut() {
        for round in 0..400 {
            let mut input = seed.clone();
            for _ in 0..1 + rng.below(3) {
                let len = input.len().max(1);
                let at = if rng.below(2) == 0 {
                    rng.below(len)
                } else {
                    rng.below(len.min(360))
                };
                match rng.below(4) {
                    0 if at < input.len() => input[at] ^= 1 << rng.below(8),
                    1 if at < input.len() => input[at] = rng.next() as u8,
                    2 => input.truncate(at),
                    _ => input.insert(at.min(input.len()), rng.next() as u8),
                }
            }
            let result = std::panic::catch_unwind(|| {
                load_label_map(&input, name, &LabelMapOptions::default())
            });
            let Ok(result) = result else {
                panic!("{name} round {round}: panicked on {input:?}");
            };
            if let Ok(map) = result {
                let voxels = map.voxel_count();
                assert!(map.affine.0.iter().flatten().all(|v| v.is_finite()));
                for layer in &map.layers {
                    assert_eq!(layer.codes.len(), voxels);
                    assert!(layer
                        .codes
                        .iter()
                        .all(|&c| (c as usize) < layer.values.len()));
                    assert_eq!(layer.values[0], 0);
                    assert!(layer.values.windows(2).skip(1).all(|w| w[0] < w[1]));
                }
                assert!(map.segments.iter().all(|s| s.layer < map.layers.len()));
            }
        }
    }
}
