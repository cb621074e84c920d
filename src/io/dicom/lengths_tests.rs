use super::*;

fn element(tag: (u16, u16), vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend(tag.0.to_le_bytes());
    out.extend(tag.1.to_le_bytes());
    out.extend(vr);
    if matches!(vr, b"OB" | b"SQ" | b"UN") {
        out.extend([0, 0]);
        out.extend((value.len() as u32).to_le_bytes());
    } else {
        out.extend((value.len() as u16).to_le_bytes());
    }
    out.extend(value);
    out
}

fn file(syntax: &str, data_set: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; 128];
    out.extend(b"DICM");
    let mut uid = syntax.as_bytes().to_vec();
    if uid.len() % 2 == 1 {
        uid.push(0);
    }
    let syntax = element(TRANSFER_SYNTAX, b"UI", &uid);
    let length = (syntax.len() as u32).to_le_bytes();
    out.extend(element(GROUP_LENGTH, b"UL", &length));
    out.extend(syntax);
    out.extend(data_set);
    out
}

#[test]
fn a_length_past_the_end_is_refused_before_parsing() {
    let good = element((0x0010, 0x0010), b"PN", b"Anon");
    assert_eq!(
        check(&file(EXPLICIT_LE, &good), Format::DicomSeg).map(|l| l.start),
        Ok(128)
    );
    let mut lying = element((0x7FE0, 0x0010), b"OB", &[1, 2]);
    lying[8..12].copy_from_slice(&0xF000_0000u32.to_le_bytes());
    let error = check(&file(EXPLICIT_LE, &lying), Format::DicomSeg).unwrap_err();
    assert!(matches!(error, LoadError::CountTooLarge { claimed, .. } if claimed == 0xF000_0000));
}

#[test]
fn a_lying_length_inside_a_sequence_item_is_found() {
    let mut inner = element((0x0008, 0x0100), b"SH", b"T-D0050 ");
    inner[6..8].copy_from_slice(&0xFFF0u16.to_le_bytes());
    let mut item = Vec::new();
    item.extend(0xFFFEu16.to_le_bytes());
    item.extend(0xE000u16.to_le_bytes());
    item.extend((inner.len() as u32).to_le_bytes());
    item.extend(&inner);
    let sequence = element((0x0062, 0x0002), b"SQ", &item);
    assert!(matches!(
        check(&file(EXPLICIT_LE, &sequence), Format::DicomSeg),
        Err(LoadError::CountTooLarge {
            claimed: 0xFFF0,
            ..
        })
    ));
}

/// An element of undefined length in implicit VR is a sequence; one that holds an element
/// where its first item should start (a fuzzed file dicom-rs then read a 4 GB value from)
/// is refused, and an empty sequence is no sequence to look into.
#[test]
fn a_sequence_that_does_not_start_with_an_item_is_refused() {
    let implicit = |tag: (u16, u16), len: u32| {
        let mut out = Vec::new();
        out.extend(tag.0.to_le_bytes());
        out.extend(tag.1.to_le_bytes());
        out.extend(len.to_le_bytes());
        out
    };
    let mut data_set = implicit((0x0009, 0x1001), UNDEFINED);
    data_set.extend(implicit((0x0010, 0x0010), 0));
    let error = check(&file(IMPLICIT_LE, &data_set), Format::DicomImage).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("a sequence holds (0010,0010) where an item"),
        "{error}"
    );
    let mut items = implicit((0x0009, 0x1001), UNDEFINED);
    items.extend(implicit(ITEM, 0));
    items.extend(implicit(SEQUENCE_END, 0));
    items.extend(implicit((0x0010, 0x0010), 0));
    assert!(check(&file(IMPLICIT_LE, &items), Format::DicomImage).is_ok());
    let mut empty = element((0x0062, 0x0002), b"SQ", &[]);
    empty.extend(element((0x0010, 0x0010), b"PN", b"Anon"));
    assert!(check(&file(EXPLICIT_LE, &empty), Format::DicomSeg).is_ok());
}

/// A number whose length is not a whole number of its values (Samples per Pixel of 2 bytes
/// as UL, explicit; Rows of 3 bytes, implicit) is refused; whole ones pass.
#[test]
fn numbers_of_a_broken_length_are_refused() {
    let explicit = element((0x0028, 0x0002), b"UL", &[1, 0]);
    let error = check(&file(EXPLICIT_LE, &explicit), Format::DicomImage).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("(0028,0002) holds 2 bytes, not a whole number of UL's 4"),
        "{error}"
    );
    let whole = element((0x0028, 0x0002), b"US", &[1, 0]);
    assert!(check(&file(EXPLICIT_LE, &whole), Format::DicomImage).is_ok());
    let mut implicit = Vec::new();
    implicit.extend([0x28, 0x00, 0x10, 0x00, 3, 0, 0, 0, 20, 0, 0]);
    let error = check(&file(IMPLICIT_LE, &implicit), Format::DicomImage).unwrap_err();
    assert!(
        error
            .to_string()
            .contains("(0028,0010) holds 3 bytes, not a whole number of US's 2"),
        "{error}"
    );
}

#[test]
fn other_encodings_are_named() {
    let error = check(&file("1.2.840.10008.1.2.4.201", &[]), Format::DicomSeg).unwrap_err();
    assert!(
        error.to_string().contains("1.2.840.10008.1.2.4.201"),
        "{error}"
    );
    let error = check(&file("1.2.840.10008.1.2.2", &[]), Format::DicomSeg).unwrap_err();
    assert!(error.to_string().contains("big endian"), "{error}");
    assert!(matches!(
        check(b"not dicom", Format::DicomSeg),
        Err(LoadError::BadMagic { .. })
    ));
}
