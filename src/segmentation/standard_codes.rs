//! Standard codes for common structure names, so that a case built from these tools' output
//! carries codes without the author typing them:
//! - the classes of TotalSegmentator's 'total' task with the SNOMED CT codes TotalSegmentator
//!   publishes for them (`totalsegmentator/resources/totalsegmentator_snomed_mapping.csv` of
//!   github.com/wasserth/TotalSegmentator, last changed in d90ebaf4d8d5), and the display colour
//!   it gives each class in its DICOM SEGs, for structures whose file gives none;
//! - FreeSurfer's aseg labels with the codes fs2dicom gives them, in SNOMED CT
//!   (`freesurfer_codes.tsv`, whose head and `tests/data/make_freesurfer_codes.py` say how).
//!
//! A structure matches a class by its name as the tool writes it or as it reads
//! ("kidney_right", "Right kidney"; "Left-Hippocampus"), ignoring case.

use std::collections::HashMap;
use std::sync::OnceLock;

use crate::io::{readable_class_name, Code, StructureCodes};

/// The tables, compiled in so that a malformed row is caught by the tests, not met by a user.
const TABLES: [(&str, &str); 2] = [
    ("standard_codes.tsv", include_str!("standard_codes.tsv")),
    ("freesurfer_codes.tsv", include_str!("freesurfer_codes.tsv")),
];

const HEADER: &str = "class\tcategory_scheme\tcategory_value\tcategory_meaning\t\
                      type_scheme\ttype_value\ttype_meaning\t\
                      modifier_scheme\tmodifier_value\tmodifier_meaning\tcolor";

/// The parsed tables: each class with its codes, and an index by both of its names.
struct Table {
    rows: Vec<Row<'static>>,
    /// Normalised name (as written and as read) to its row in `rows`.
    by_name: HashMap<String, usize>,
}

/// The name a lookup compares: structures come from files and from people, so case and
/// surrounding spaces vary.
fn normalise(name: &str) -> String {
    name.trim().to_ascii_lowercase()
}

/// A class, its codes and its display colour (sRGB bytes).
type Row<'a> = (&'a str, StructureCodes, [u8; 3]);

/// One data line of the table, or what is wrong with it.
fn parse_row(line: &str) -> Result<Row<'_>, String> {
    let fields: Vec<&str> = line.split('\t').collect();
    let [class, fields @ .., color] = <[&str; 11]>::try_from(fields.as_slice())
        .map_err(|_| format!("{} fields, expected 11", fields.len()))?;
    let color: Vec<u8> = (color.split(','))
        .map(|c| c.trim().parse::<u8>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("colour '{color}' is not 'r,g,b' of bytes"))?;
    let color = <[u8; 3]>::try_from(color).map_err(|_| "a colour of 3 bytes".to_string())?;
    let code = |f: &[&str]| Code::new(f[0], f[1], f[2]);
    if class.is_empty() || fields[..6].iter().any(|f| f.is_empty()) {
        return Err("an empty class, category or type field".to_string());
    }
    let modifier = match fields[6..] {
        ["", "", ""] => None,
        [s, v, m] if !s.is_empty() && !v.is_empty() && !m.is_empty() => Some(code(&fields[6..])),
        _ => return Err("a modifier with some of its fields empty".to_string()),
    };
    let codes = StructureCodes {
        category: code(&fields[..3]),
        kind: code(&fields[3..6]),
        modifier,
    };
    Ok((class, codes, color))
}

impl Table {
    /// Panics naming the file and line of a malformed row: the texts are compiled in, so that
    /// is a programming error, and the unit tests parse them.
    fn parse(tables: &[(&str, &'static str)]) -> Self {
        let mut rows = Vec::new();
        for (file, text) in tables {
            let mut lines = (text.lines().enumerate()).filter(|(_, line)| !line.starts_with('#'));
            let header = lines.next().map(|(_, line)| line);
            assert_eq!(header, Some(HEADER), "{file}: header");
            rows.extend(lines.map(|(i, line)| {
                parse_row(line).unwrap_or_else(|e| panic!("{file} line {}: {e}", i + 1))
            }));
        }
        let mut by_name = HashMap::with_capacity(2 * rows.len());
        for (row, (class, ..)) in rows.iter().enumerate() {
            // Single-word classes ("liver") read as they are written: one key for both.
            for name in [normalise(class), normalise(&readable_class_name(class))] {
                let before = by_name.insert(name.clone(), row);
                assert!(
                    before.is_none_or(|b| b == row),
                    "two classes are named '{name}'"
                );
            }
        }
        Self { rows, by_name }
    }

    fn get() -> &'static Self {
        static TABLE: OnceLock<Table> = OnceLock::new();
        TABLE.get_or_init(|| Self::parse(&TABLES))
    }
}

/// A class of the tables: its codes and display colour (sRGB, channels in [0, 1]).
#[derive(Clone, Debug, PartialEq)]
pub struct StandardClass {
    pub codes: StructureCodes,
    pub color: [f32; 3],
}

/// The class a structure named `name` is, when it is one of TotalSegmentator's or FreeSurfer's.
pub fn standard_class(name: &str) -> Option<StandardClass> {
    let table = Table::get();
    let (_, codes, color) = &table.rows[*table.by_name.get(&normalise(name))?];
    Some(StandardClass {
        codes: codes.clone(),
        color: color.map(|c| f32::from(c) / 255.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn codes_for_name(name: &str) -> Option<StructureCodes> {
        standard_class(name).map(|c| c.codes)
    }

    fn color_for_name(name: &str) -> Option<[f32; 3]> {
        standard_class(name).map(|c| c.color)
    }

    #[test]
    fn totalsegmentator_classes_have_their_published_codes() {
        assert_eq!(Table::get().rows.len(), 117 + 51);
        let kidney = codes_for_name("Right kidney").unwrap();
        assert_eq!(kidney.kind, Code::new("SCT", "64033007", "Kidney"));
        assert_eq!(kidney.modifier, Some(Code::new("SCT", "24028007", "Right")));
        assert_eq!(codes_for_name("kidney_right"), Some(kidney.clone()));
        assert_eq!(codes_for_name("  KIDNEY_RIGHT "), Some(kidney));
        let liver = codes_for_name("liver").unwrap();
        assert_eq!(
            liver.category,
            Code::new("SCT", "123037004", "Anatomical Structure")
        );
        assert_eq!(
            (liver.kind.value.as_str(), liver.modifier),
            ("10200004", None)
        );
        assert_eq!(
            codes_for_name("Left rib 1").unwrap().kind.meaning,
            "First rib"
        );
        assert_eq!(
            codes_for_name("Vertebrae L1").unwrap().kind.value,
            "66794005"
        );
        assert_eq!(codes_for_name("tumor"), None);
        assert_eq!(codes_for_name(""), None);
        // TotalSegmentator's liver is green (40, 140, 40).
        let green = color_for_name("Liver")
            .unwrap()
            .map(|c| (c * 255.0).round() as u8);
        assert_eq!(green, [40, 140, 40]);
        assert_eq!(color_for_name("tumor"), None);
    }

    #[test]
    fn every_row_is_whole_and_every_name_finds_its_own_row() {
        let table = Table::parse(&TABLES[..1]);
        assert_eq!(table.rows.len(), 117);
        for (row, (class, codes, _)) in table.rows.iter().enumerate() {
            assert!(!class.is_empty() && !codes.kind.meaning.is_empty());
            assert_eq!(table.by_name[&normalise(class)], row, "{class}");
            let readable = readable_class_name(class);
            assert_eq!(table.by_name[&normalise(&readable)], row, "{readable}");
        }
        // Two keys a class, less one for each of the 16 single-word classes ("liver" reads
        // "Liver"): any fewer and two classes' names would collide.
        let single_words = (table.rows.iter()).filter(|(c, ..)| !c.contains('_'));
        assert_eq!(single_words.count(), 16);
        assert_eq!(table.by_name.len(), 2 * 117 - 16);
    }

    #[test]
    fn freesurfers_aseg_labels_have_snomed_ct_codes_and_freesurfers_colours() {
        let table = Table::parse(&TABLES[1..]);
        // fs2dicom's 49 labels, two of them under FreeSurfer 7's names as well.
        assert_eq!(table.rows.len(), 51);
        let hippocampus = codes_for_name("left-hippocampus").unwrap();
        assert_eq!(hippocampus.kind, Code::new("SCT", "5366008", "Hippocampus"));
        assert_eq!(
            hippocampus.modifier,
            Some(Code::new("SCT", "7771000", "Left"))
        );
        assert_eq!(hippocampus.category.value, "123037004");
        let thalamus = codes_for_name("Right-Thalamus").unwrap();
        assert_eq!(
            codes_for_name("Right-Thalamus-Proper"),
            Some(thalamus.clone())
        );
        assert_eq!(
            (thalamus.kind.value.as_str(), thalamus.kind.scheme.as_str()),
            ("119406000", "SCT")
        );
        assert_eq!(
            codes_for_name("CSF").unwrap().category.meaning,
            "Body Substance"
        );
        assert_eq!(
            codes_for_name("CC Posterior"),
            codes_for_name("CC_Posterior")
        );
        // Codes of DICOM's own scheme stay as they are.
        let dc = codes_for_name("Left-VentralDC").unwrap().kind;
        assert_eq!((dc.scheme.as_str(), dc.value.as_str()), ("DCM", "110700"));
        // No SNOMED RT identifier is left (io's colour table checks the colours).
        for (class, codes, _) in &table.rows {
            let all = [
                Some(&codes.category),
                Some(&codes.kind),
                codes.modifier.as_ref(),
            ];
            assert!(all.iter().flatten().all(|c| c.scheme != "SRT"), "{class}");
        }
        assert_eq!(codes_for_name("ctx-lh-insula"), None);
    }

    #[test]
    fn a_malformed_row_is_refused() {
        let row = "liver\tSCT\t123037004\tAnatomical Structure\tSCT\t10200004\tLiver";
        assert!(parse_row(&format!("{row}\t\t\t\t1,2,3")).is_ok());
        assert!(parse_row(&format!("{row}\tSCT\t7771000\tLeft\t1,2,3")).is_ok());
        assert!(parse_row(&format!("{row}\tSCT\t\tLeft\t1,2,3")).is_err());
        assert!(parse_row(row).is_err());
        assert!(parse_row(&format!("{row}\t\t\t\t1,2")).is_err());
        assert!(parse_row(&format!("{row}\t\t\t\t1,2,300")).is_err());
        assert!(parse_row(&format!("{row}\t\t\t\t\t1,2,3")).is_err());
        let row = row.replace("SCT\t10200004", "\t10200004");
        assert!(parse_row(&format!("{row}\t\t\t\t1,2,3")).is_err());
    }
}
