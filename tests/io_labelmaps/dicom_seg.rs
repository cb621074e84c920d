//! DICOM SEG files highdicom wrote (tests/data/make_dicom_seg.py): the shared phantom with the
//! same names, colours, codes and surfaces as its `.seg.nrrd`; skipped slices, an oblique grid
//! and a fractional segmentation against the NIfTI files written beside them; overlapping
//! segments; and broken SEGs, each refused with what is wrong.

use super::sources::{largest_offset, open, ours};
use super::{assert_affine_near, load_named, peak_of, read, voxel_values};
use dicom_core::value::{DataSetSequence, PrimitiveValue};
use dicom_core::{DataElement, Tag, VR};
use dicom_dictionary_std::tags;
use dicom_object::file::{OpenFileOptions, ReadPreamble};
use dicom_object::mem::InMemDicomObject;
use dicom_object::FileDicomObject;
use meshsmooth::io::{load_label_map, Code, LabelMap, LabelMapOptions, StructureCodes};

type Object = FileDicomObject<InMemDicomObject>;

#[path = "../common/dicom.rs"]
mod dicom;

fn seg(name: &str) -> Vec<u8> {
    ours(&format!("dicom_seg/{name}"))
}

fn expected() -> serde_json::Value {
    serde_json::from_slice(&seg("expected.json")).expect("expected.json")
}

fn sct(value: &str, meaning: &str) -> Code {
    Code::new("SCT", value, meaning)
}

#[test]
fn the_phantom_as_dicom_seg_matches_its_seg_nrrd() {
    let dicom_bytes = seg("phantom.dcm");
    let nrrd_bytes = read("case_phantom_shared.seg.nrrd");
    let map = load_named(&dicom_bytes, "phantom.dcm");
    let nifti = load_named(&read("case_phantom_shared.nii.gz"), "phantom.nii.gz");
    assert_same_voxels(&map, &nifti);
    // Told by its bytes when the name does not say.
    assert_eq!(load_named(&dicom_bytes, "export"), map);

    let from_dicom = open(&[("phantom.dcm", &dicom_bytes)], None);
    let from_nrrd = open(&[("phantom.seg.nrrd", &nrrd_bytes)], None);
    assert_eq!(from_dicom.len(), 4);
    for (d, n) in from_dicom.iter().zip(&from_nrrd) {
        assert_eq!(d.name, n.name);
        for (a, b) in d.color.iter().zip(&n.color) {
            assert!(
                (a - b).abs() * 255.0 <= 2.0,
                "{}: {:?} vs {:?}",
                d.name,
                d.color,
                n.color
            );
        }
        assert!(largest_offset(d, n) <= 1e-3, "{}", d.name);
    }
    let anatomy = sct("123037004", "Anatomical Structure");
    let codes: Vec<Option<StructureCodes>> = from_dicom.iter().map(|s| s.codes.clone()).collect();
    let coded = |category: &Code, kind: Code, modifier: Option<Code>| {
        Some(StructureCodes {
            category: category.clone(),
            kind,
            modifier,
        })
    };
    assert_eq!(
        codes,
        [
            coded(&anatomy, sct("10200004", "Liver"), None),
            coded(&anatomy, sct("32764006", "Portal vein"), None),
            coded(
                &sct("49755003", "Morphologically Altered Structure"),
                sct("108369006", "Neoplasm"),
                None
            ),
            coded(
                &anatomy,
                sct("64033007", "Kidney"),
                Some(sct("24028007", "Right"))
            ),
        ]
    );
}

/// A SEG's grid spans only the slices its frames cover: its voxels must be the NIfTI's on
/// those slices, on the same axes, and the NIfTI's other slices empty.
fn assert_same_voxels(map: &LabelMap, nifti: &LabelMap) {
    assert_eq!(map.dims[..2], nifti.dims[..2]);
    let corner = nifti
        .affine
        .inverse_apply(map.affine.apply([0.0; 3]))
        .unwrap();
    let first = corner[2].round() as usize;
    assert!(
        corner
            .iter()
            .zip([0.0, 0.0, first as f64])
            .all(|(a, b)| (a - b).abs() < 1e-4),
        "{corner:?}"
    );
    let mut ours = map.affine.0;
    for (r, row) in ours.iter_mut().enumerate() {
        row[3] = nifti.affine.0[r][3] + nifti.affine.0[r][2] * first as f64;
    }
    assert_affine_near(&map.affine, &ours, 1e-4);
    let plane = map.dims[0] * map.dims[1];
    let theirs = voxel_values(nifti, 0);
    let mine = voxel_values(map, 0);
    let (before, rest) = theirs.split_at(first * plane);
    let (same, after) = rest.split_at(mine.len());
    assert_eq!(mine, same);
    assert!(before.iter().chain(after).all(|&v| v == 0));
}

/// The label map a SEG gives and the NIfTI written beside it: same voxels on the same grid.
fn same_as_nifti(name: &str, options: &LabelMapOptions) {
    let map = load_label_map(&seg(&format!("{name}.dcm")), name, options)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let nifti = load_named(&seg(&format!("{name}.nii.gz")), "twin.nii.gz");
    assert_same_voxels(&map, &nifti);
    let facts = &expected()[format!("{name}.dcm")];
    for (segment, fact) in map
        .segments
        .iter()
        .zip(facts["segments"].as_array().unwrap())
    {
        assert_eq!(segment.name, fact["label"].as_str().unwrap());
        let srgb = fact["srgb"].as_array().unwrap();
        for (c, want) in segment.color.unwrap().iter().zip(srgb) {
            assert!(
                (c * 255.0 - want.as_f64().unwrap() as f32).abs() <= 2.0,
                "{name}"
            );
        }
    }
}

#[test]
fn skipped_slices_oblique_grids_and_fractions_read_as_their_nifti_twins() {
    let options = LabelMapOptions::default();
    for name in ["gap", "oblique", "fractional"] {
        same_as_nifti(name, &options);
    }
    // The gap: every segment is absent from slices 10..19, which the grid still holds.
    let gap = load_named(&seg("gap.dcm"), "gap.dcm");
    assert_eq!(gap.dims[2], 30 - 3 - 3);
    // A higher level keeps fewer voxels of the fractional sphere.
    let strict = LabelMapOptions { level: Some(0.9) };
    let fewer = load_label_map(&seg("fractional.dcm"), "f.dcm", &strict).unwrap();
    let count = |m: &LabelMap| m.layers[0].codes.iter().filter(|&&c| c != 0).count();
    let usual = load_named(&seg("fractional.dcm"), "f.dcm");
    assert_eq!(count(&usual), 1513);
    assert!(count(&fewer) < count(&usual));
}

fn parse(bytes: &[u8]) -> Object {
    OpenFileOptions::new()
        .read_preamble(ReadPreamble::Always)
        .from_reader(bytes)
        .expect("a DICOM file")
}

fn write(object: &Object) -> Vec<u8> {
    let mut out = Vec::new();
    object.write_all(&mut out).expect("writes");
    out
}

fn edit(bytes: &[u8], change: impl FnOnce(&mut Object)) -> Vec<u8> {
    let mut object = parse(bytes);
    change(&mut object);
    write(&object)
}

/// Replaces the items of a sequence with what `change` makes of them.
fn with_items(
    object: &mut InMemDicomObject,
    tag: Tag,
    change: impl FnOnce(&mut Vec<InMemDicomObject>),
) {
    let element = object.take(tag).expect("the sequence is there");
    let mut items = element.items().expect("a sequence").to_vec();
    change(&mut items);
    object.put(DataElement::new(tag, VR::SQ, DataSetSequence::from(items)));
}

/// Changes the first item of a frame's functional group `group`.
fn with_frame(
    object: &mut InMemDicomObject,
    frame: usize,
    group: Tag,
    change: impl FnOnce(&mut InMemDicomObject),
) {
    with_items(
        object,
        tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE,
        |frames| {
            with_items(&mut frames[frame], group, |items| change(&mut items[0]));
        },
    );
}

fn put_text(object: &mut InMemDicomObject, tag: Tag, vr: VR, text: &str) {
    object.put(DataElement::new(tag, vr, PrimitiveValue::from(text)));
}

fn put_u16(object: &mut InMemDicomObject, tag: Tag, value: u16) {
    object.put(DataElement::new(tag, VR::US, PrimitiveValue::from(value)));
}

fn frames_of(object: &InMemDicomObject, segment: u16) -> Vec<usize> {
    let groups = object
        .element(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .unwrap();
    (groups.items().unwrap().iter().enumerate())
        .filter(|(_, g)| {
            let id = g
                .element(tags::SEGMENT_IDENTIFICATION_SEQUENCE)
                .unwrap()
                .items()
                .unwrap();
            let n: u16 = id[0]
                .element(tags::REFERENCED_SEGMENT_NUMBER)
                .unwrap()
                .to_int()
                .unwrap();
            n == segment
        })
        .map(|(f, _)| f)
        .collect()
}

#[test]
fn overlapping_segments_go_to_separate_layers() {
    // A fifth segment holding the liver's frames again: it overlaps the liver everywhere.
    let bytes = edit(&seg("phantom.dcm"), |object| {
        let liver = frames_of(object, 1);
        let frame_bytes = 160 * 140 / 8;
        let mut data = object
            .element(tags::PIXEL_DATA)
            .unwrap()
            .to_bytes()
            .unwrap()
            .to_vec();
        let frames: usize = object
            .element(tags::NUMBER_OF_FRAMES)
            .unwrap()
            .to_int()
            .unwrap();
        data.truncate(frames * frame_bytes);
        for &f in &liver {
            data.extend_from_slice(&data.clone()[f * frame_bytes..(f + 1) * frame_bytes]);
        }
        if data.len() % 2 == 1 {
            data.push(0);
        }
        object.put(DataElement::new(
            tags::PIXEL_DATA,
            VR::OB,
            PrimitiveValue::from(data),
        ));
        put_text(
            object,
            tags::NUMBER_OF_FRAMES,
            VR::IS,
            &(frames + liver.len()).to_string(),
        );
        with_items(
            object,
            tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE,
            |groups| {
                for &f in &liver {
                    let mut copy = groups[f].clone();
                    with_items(&mut copy, tags::SEGMENT_IDENTIFICATION_SEQUENCE, |id| {
                        put_u16(&mut id[0], tags::REFERENCED_SEGMENT_NUMBER, 5);
                    });
                    groups.push(copy);
                }
            },
        );
        with_items(object, tags::SEGMENT_SEQUENCE, |segments| {
            let mut copy = segments[0].clone();
            put_u16(&mut copy, tags::SEGMENT_NUMBER, 5);
            put_text(&mut copy, tags::SEGMENT_LABEL, VR::LO, "liver again");
            segments.push(copy);
        });
    });
    let map = load_named(&bytes, "overlap.dcm");
    assert_eq!(map.layers.len(), 2);
    let again = map
        .segments
        .iter()
        .find(|s| s.name == "liver again")
        .unwrap();
    assert_eq!((again.layer, again.value), (1, 5));
    let structures = open(&[("overlap.dcm", &bytes)], None);
    assert_eq!(structures.len(), 5);
    assert!(largest_offset(&structures[0], &structures[4]) == 0.0);
    assert_eq!(structures[4].codes, structures[0].codes);
}

/// Checks a broken SEG is refused, quickly and within bounded memory, with `words` in the
/// message, and that the message names the file through the segmentation reader. The bound is
/// looser than for the other label maps: dicom-object's parsed object takes several times the
/// file's bytes.
fn refused(bytes: &[u8], words: &str) {
    let start = std::time::Instant::now();
    let (result, peak) =
        peak_of(|| load_label_map(bytes, "broken.dcm", &LabelMapOptions::default()));
    assert!(start.elapsed().as_secs_f64() < 2.0, "{words}: slow");
    eprintln!("{words}: held {peak} bytes for {}", bytes.len());
    assert!(
        peak <= 16 * bytes.len() + (1 << 20),
        "{words}: held {peak} bytes for {}",
        bytes.len()
    );
    let error = match result {
        Ok(map) => panic!("{words}: the broken file loaded ({:?})", map.dims),
        Err(e) => e.to_string(),
    };
    assert!(error.contains(words), "wanted '{words}' in: {error}");
    let files = [meshsmooth::segmentation::NamedBytes {
        name: "broken.dcm",
        bytes,
    }];
    let options = meshsmooth::segmentation::OpenOptions::default();
    let error = meshsmooth::segmentation::open(&files, None, &options).unwrap_err();
    assert!(error.to_string().contains("broken.dcm"), "{error}");
}

#[test]
fn broken_segs_are_refused_by_what_is_wrong() {
    let good = seg("phantom.dcm");
    refused(&good[..good.len() / 2], "bytes");
    refused(&good[..100], "DICM");
    refused(
        &edit(&good, |o| {
            put_text(o, tags::SOP_CLASS_UID, VR::UI, "1.2.840.10008.5.1.4.1.1.2")
        }),
        "not Segmentation Storage",
    );
    refused(
        &edit(&good, |o| put_text(o, tags::NUMBER_OF_FRAMES, VR::IS, "54")),
        "54 frames",
    );
    refused(&edit(&good, |o| put_u16(o, tags::ROWS, 400)), "pixel data");
    refused(
        &edit(&good, |o| put_u16(o, tags::BITS_ALLOCATED, 16)),
        "16 bits",
    );
    refused(
        &edit(&good, |o| {
            put_text(o, tags::SEGMENTATION_TYPE, VR::CS, "LABELMAP")
        }),
        "LABELMAP",
    );
    refused(
        &edit(&good, |o| {
            with_frame(o, 3, tags::SEGMENT_IDENTIFICATION_SEQUENCE, |id| {
                put_u16(id, tags::REFERENCED_SEGMENT_NUMBER, 9)
            })
        }),
        "segment 9 is not declared",
    );
    let moved = |to: &str| {
        edit(&good, |o| {
            with_frame(o, 2, tags::PLANE_POSITION_SEQUENCE, |p| {
                put_text(p, tags::IMAGE_POSITION_PATIENT, VR::DS, to)
            })
        })
    };
    // Frame 3 of the liver sits on a slice at z = -40 + 2.5 k; half a slice off, then NaN.
    let frame_z = |bytes: &[u8]| -> Vec<f64> {
        let o = parse(bytes);
        let g = o
            .element(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
            .unwrap()
            .items()
            .unwrap()[2]
            .clone();
        let p = g
            .element(tags::PLANE_POSITION_SEQUENCE)
            .unwrap()
            .items()
            .unwrap()[0]
            .clone();
        p.element(tags::IMAGE_POSITION_PATIENT)
            .unwrap()
            .to_multi_float64()
            .unwrap()
    };
    let at = frame_z(&good);
    refused(
        &moved(&format!("{}\\{}\\{}", at[0], at[1], at[2] + 1.25)),
        "not evenly spaced",
    );
    refused(
        &moved(&format!("{}\\{}\\{}", at[0] + 3.9, at[1], at[2])),
        "shifted",
    );
    refused(
        &moved(&format!("{}\\{}\\{}", at[0], at[1], at[2] + 1e9)),
        "cannot be right",
    );
    refused(
        &edit(&good, |o| {
            with_items(o, tags::SEGMENT_SEQUENCE, |s| {
                let copy = s[1].clone();
                s[0] = copy;
            })
        }),
        "declared twice",
    );
    refused(
        &edit(&good, |o| {
            with_items(o, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE, |shared| {
                with_items(&mut shared[0], tags::PLANE_ORIENTATION_SEQUENCE, |p| {
                    put_text(
                        &mut p[0],
                        tags::IMAGE_ORIENTATION_PATIENT,
                        VR::DS,
                        "1\\0\\0\\1\\0\\0",
                    )
                })
            })
        }),
        "not perpendicular",
    );
    let mut compressed = edit(&good, |_| {});
    let at = (compressed.windows(19))
        .position(|w| w == b"1.2.840.10008.1.2.1")
        .unwrap();
    compressed[at..at + 19].copy_from_slice(b"1.2.840.10008.1.2.5");
    refused(
        &compressed,
        "compressed pixel data that is not encapsulated",
    );
}

#[test]
fn a_lying_length_costs_no_memory() {
    let good = seg("phantom.dcm");
    // The pixel data's length (after its tag, VR and two reserved bytes) claims 3.75 GiB.
    let tag = [0xE0, 0x7F, 0x10, 0x00, b'O', b'B', 0, 0];
    let at = good.windows(8).rposition(|w| w == tag).expect("pixel data") + 8;
    let mut lying = good.clone();
    lying[at..at + 4].copy_from_slice(&0xF000_0000u32.to_le_bytes());
    let (result, peak) =
        peak_of(|| load_label_map(&lying, "lying.dcm", &LabelMapOptions::default()));
    let error = result.unwrap_err().to_string();
    assert!(error.contains("4026531840"), "{error}");
    assert!(peak < 1 << 20, "held {peak} bytes");
    // A VR the fuzzer turned into one DICOM does not define: dicom-rs reads a 32-bit length
    // after it, which claimed gigabytes before the walk read headers the same way.
    let mutated = seg("fuzz_unknown_vr.dcm");
    let (result, peak) =
        peak_of(|| load_label_map(&mutated, "mutated.dcm", &LabelMapOptions::default()));
    assert!(result.is_err());
    assert!(peak < 16 * mutated.len() + (1 << 20), "held {peak} bytes");
    // A file meta group whose declared length (0002,0000) takes in elements past those of group
    // 2: dicom-rs reads by that length, and so must the walk, or the data set it checks is not
    // the one dicom-rs parses (where a 1.8 GB value hid).
    let mutated = seg("fuzz_meta_length.dcm");
    let (result, peak) =
        peak_of(|| load_label_map(&mutated, "mutated.dcm", &LabelMapOptions::default()));
    let error = result.unwrap_err().to_string();
    assert!(error.contains("1851878985"), "{error}");
    assert!(peak < 16 * mutated.len() + (1 << 20), "held {peak} bytes");
}

#[test]
fn slicer_terminology_tags_carry_the_same_codes_as_the_seg() {
    // The shared .seg.nrrd with the tumour's tags as 3D Slicer writes a terminology entry.
    let nrrd = read("case_phantom_shared.seg.nrrd");
    let empty = b"Segment2_Tags:=|";
    let at = nrrd
        .windows(empty.len())
        .position(|w| w == empty)
        .expect("the tumour's tags");
    let entry = "Segment2_Tags:=Segmentation.Status:inprogress|TerminologyEntry:Segmentation \
        category and type - 3D Slicer General Anatomy list~SCT^49755003^Morphologically Altered \
        Structure~SCT^108369006^Neoplasm~^^~Anatomic codes - DICOM master list~^^~^^|";
    let tagged = [&nrrd[..at], entry.as_bytes(), &nrrd[at + empty.len()..]].concat();
    let from_nrrd = open(&[("tagged.seg.nrrd", &tagged)], None);
    let from_dicom = open(&[("phantom.dcm", &seg("phantom.dcm"))], None);
    assert_eq!(from_nrrd[2].name, "tumor");
    assert!(from_nrrd[2].codes.is_some());
    assert_eq!(from_nrrd[2].codes, from_dicom[2].codes);
}

#[test]
fn a_folder_of_segs_keeps_every_segment_and_masks_beside_them_stay_masks() {
    let phantom = seg("phantom.dcm");
    let gap = seg("gap.dcm");
    let mask = seg("fractional.nii.gz");
    let structures = open(
        &[
            ("a/phantom.dcm", &phantom),
            ("a/gap.dcm", &gap),
            ("a/sphere_mask.nii.gz", &mask),
        ],
        None,
    );
    let named: Vec<(i64, &str)> = (structures.iter())
        .map(|s| (s.label, s.name.as_str()))
        .collect();
    assert_eq!(
        named,
        [
            (1, "liver"),
            (2, "portal_vein"),
            (3, "tumor"),
            (4, "right_kidney"),
            (5, "box"),
            (6, "sphere"),
            (7, "Sphere mask")
        ]
    );
    let alone = open(&[("phantom.dcm", &phantom)], None);
    assert_eq!(structures[3].codes, alone[3].codes);
    assert_eq!(structures[3].mesh, alone[3].mesh);
}

/// The phantom as a LABELMAP SEG (each frame a slice of segment numbers) gives the structures
/// the BINARY one gives; a pixel whose number no segment has is refused.
#[test]
fn a_labelmap_seg_reads_as_the_binary_one() {
    let labels = seg("labelmap.dcm");
    let binary = seg("phantom.dcm");
    let from_labels = open(&[("labelmap.dcm", &labels)], None);
    let from_binary = open(&[("phantom.dcm", &binary)], None);
    assert_eq!(from_labels.len(), 4);
    for (l, b) in from_labels.iter().zip(&from_binary) {
        assert_eq!((&l.name, &l.color, &l.codes), (&b.name, &b.color, &b.codes));
        assert!(largest_offset(l, b) <= 1e-6, "{}", l.name);
    }
    let map = load_named(&labels, "labelmap.dcm");
    assert_eq!(map.layers.len(), 1);
    assert_same_voxels(
        &map,
        &load_named(&read("case_phantom_shared.nii.gz"), "p.nii.gz"),
    );

    let undeclared = edit(&labels, |o| {
        with_items(o, tags::SEGMENT_SEQUENCE, |items| {
            items.pop();
        })
    });
    refused(&undeclared, "pixel value 4 is no segment");
    refused(
        &edit(&labels, |o| put_u16(o, tags::BITS_ALLOCATED, 1)),
        "LABELMAP (8 or 16 bits)",
    );
}

/// RLE Lossless twins of the LABELMAP and FRACTIONAL SEGs and JPEG Lossless, JPEG-LS Lossless
/// and JPEG 2000 Lossless ones of the FRACTIONAL SEG (tests/data/make_dicom_compressed.py) read as the
/// uncompressed files; a broken frame is refused.
#[test]
fn compressed_segs_read_as_the_uncompressed_ones() {
    for (name, twin) in [
        ("labelmap", "labelmap_rle"),
        ("fractional", "fractional_rle"),
        ("fractional", "fractional_jpeg"),
        ("fractional", "fractional_j2k"),
        ("fractional", "fractional_jls"),
    ] {
        let plain = load_named(&seg(&format!("{name}.dcm")), "plain.dcm");
        let compressed = load_named(&seg(&format!("{twin}.dcm")), "twin.dcm");
        assert_eq!(compressed, plain, "{twin}");
    }
    let rle = seg("labelmap_rle.dcm");
    refused(
        &dicom::with_rle_word(&rle, 0, 2),
        "2 segments for samples of 1 byte(s)",
    );
    refused(&rle[..rle.len() - 2000], "bytes");
}

/// The BINARY phantom SEG in Deflated Explicit VR Little Endian (the data set one deflate
/// stream, tests/data/make_dicom_compressed.py) reads as the uncompressed file; a stream cut
/// short or corrupt is refused within the memory and time of any broken file.
#[test]
fn a_deflated_seg_reads_as_the_uncompressed_one() {
    let plain = load_named(&seg("phantom.dcm"), "plain.dcm");
    let deflated = seg("phantom_deflated.dcm");
    assert_eq!(load_named(&deflated, "twin.dcm"), plain);
    refused(&deflated[..deflated.len() - 500], "does not inflate");
    let mut corrupt = deflated.clone();
    let middle = corrupt.len() / 2;
    corrupt[middle..middle + 8].copy_from_slice(&[0xFF; 8]);
    // Still a deflate stream, of other bytes: the length walk refuses what it inflates to.
    refused(&corrupt, "bytes in an element");
}
