//! Label names a NIfTI file carries in its header extensions: the XML label table
//! TotalSegmentator writes into its multilabel output (extension code 0, Caret's layout:
//! `CaretExtension > VolumeInformation > LabelTable > Label Key= Red= Green= Blue=` with the name
//! as text), which Connectome Workbench writes too (code 30). The XML is read with `roxmltree`.
//!
//! An extension that is not such a table, or not well-formed, names nothing: the label map reads
//! as without it, as nibabel reads it. Colours are taken from Workbench's tables only.

use super::label_map::Segment;

/// The most extension bytes read for names; a file with more is read without them.
pub(super) const MAX_EXTENSION_BYTES: usize = 16 << 20;

/// The labels named by the extensions in `area`, the bytes between the fixed header and the
/// voxels (the 4-byte extender first), in the file's byte order.
pub(super) fn label_names(area: &[u8], big_endian: bool) -> Vec<Segment> {
    if area.first().is_none_or(|&flag| flag == 0) {
        return Vec::new();
    }
    let int = |at: usize| -> Option<i32> {
        let b: [u8; 4] = area.get(at..at + 4)?.try_into().ok()?;
        Some(match big_endian {
            true => i32::from_be_bytes(b),
            false => i32::from_le_bytes(b),
        })
    };
    let mut at = 4;
    while let (Some(size), Some(code)) = (int(at), int(at + 4)) {
        let Some(end) = usize::try_from(size)
            .ok()
            .filter(|&s| s >= 8)
            .map(|s| at + s)
        else {
            break;
        };
        let Some(content) = area.get(at + 8..end) else {
            break;
        };
        if matches!(code, 0 | 30) {
            let mut names = label_table(content);
            if code == 0 {
                // TotalSegmentator colours its table by cycling twelve colours that say nothing
                // of the class: left unset, its classes take the colours it gives them in DICOM.
                names.iter_mut().for_each(|s| s.color = None);
            }
            if !names.is_empty() {
                return names;
            }
        }
        at = end;
    }
    Vec::new()
}

/// The labels of a Caret-style XML label table (trailing NULs, nibabel's padding, dropped).
fn label_table(content: &[u8]) -> Vec<Segment> {
    let end = content.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
    let Ok(text) = std::str::from_utf8(&content[..end]) else {
        return Vec::new();
    };
    if !text.contains("LabelTable") {
        return Vec::new();
    }
    let Ok(document) = roxmltree::Document::parse(text.trim()) else {
        return Vec::new();
    };
    let table = (document.descendants()).find(|n| n.has_tag_name("LabelTable"));
    let labels = table.into_iter().flat_map(|t| t.children());
    let mut names: Vec<Segment> = labels
        .filter(|n| n.has_tag_name("Label"))
        .filter_map(|label| {
            let value: i64 = label.attribute("Key")?.trim().parse().ok()?;
            let name: String = (label.descendants())
                .filter(|n| n.is_text())
                .filter_map(|n| n.text())
                .collect();
            let channel = |key: &str| -> Option<f32> {
                let c: f32 = label.attribute(key)?.trim().parse().ok()?;
                (0.0..=1.0).contains(&c).then_some(c)
            };
            let color = match (channel("Red"), channel("Green"), channel("Blue")) {
                (Some(r), Some(g), Some(b)) => Some([r, g, b]),
                _ => None,
            };
            (value != 0).then(|| Segment {
                layer: 0,
                value,
                name: readable(name.trim()),
                color,
                codes: None,
            })
        })
        .collect();
    names.dedup_by_key(|s| s.value);
    names
}

/// A class name as TotalSegmentator writes it, for reading: underscores become spaces, a side
/// comes first, the first letter is capitalised ("kidney_left" is "Left kidney", "rib_left_3"
/// "Left rib 3", "vertebrae_L1" "Vertebrae L1"). Names with spaces are kept as they are.
pub fn readable(name: &str) -> String {
    if name.contains(' ') {
        return name.to_string();
    }
    let words: Vec<&str> = name.split('_').filter(|w| !w.is_empty()).collect();
    let side = (words.iter()).find(|w| matches!(**w, "left" | "right"));
    let rest = words.iter().filter(|w| Some(*w) != side).copied();
    let joined: Vec<&str> = side.copied().into_iter().chain(rest).collect();
    let mut out = joined.join(" ");
    if let Some(first) = out.get(..1) {
        out = first.to_ascii_uppercase() + &out[1..];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totalsegmentator_names_read_as_words() {
        assert_eq!(readable("kidney_left"), "Left kidney");
        assert_eq!(readable("rib_right_12"), "Right rib 12");
        assert_eq!(readable("vertebrae_L1"), "Vertebrae L1");
        assert_eq!(readable("lung_upper_lobe_left"), "Left lung upper lobe");
        assert_eq!(
            readable("portal_vein_and_splenic_vein"),
            "Portal vein and splenic vein"
        );
        assert_eq!(readable("spleen"), "Spleen");
        assert_eq!(readable("Left kidney"), "Left kidney");
    }

    #[test]
    fn a_broken_or_foreign_extension_names_nothing() {
        let table = |xml: &str| label_table(xml.as_bytes());
        assert!(table("<LabelTable><Label Key=\"1\">liver</Label>").is_empty());
        assert!(table("<afni>LabelTable</afni>").is_empty());
        let two = table(
            "<CaretExtension><VolumeInformation><LabelTable>\
             <Label Key=\"2\" Red=\"1.0\" Green=\"0.0\" Blue=\"2\"><![CDATA[kidney_left]]></Label>\
             <Label Key=\"x\">bad</Label><Label Key=\"0\">background</Label>\
             </LabelTable></VolumeInformation></CaretExtension>",
        );
        assert_eq!(two.len(), 1);
        assert_eq!((two[0].value, two[0].name.as_str()), (2, "Left kidney"));
        assert_eq!(two[0].color, None, "a channel past 1 is no colour");
    }
}
