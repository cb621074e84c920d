//! Standard codes for common structure names: the classes of TotalSegmentator's 'total' task
//! with the SNOMED CT codes TotalSegmentator publishes for them
//! (`totalsegmentator/resources/totalsegmentator_snomed_mapping.csv` of
//! github.com/wasserth/TotalSegmentator, last changed in d90ebaf4d8d5), so that a case built
//! from its output carries codes without the author typing them, and the display colour
//! TotalSegmentator gives each class in its DICOM SEGs, for structures whose file gives none. A
//! structure matches a class by its name as TotalSegmentator writes it or as it reads
//! ("kidney_right", "Right kidney"), ignoring case.

use std::collections::HashMap;
use std::sync::OnceLock;

use crate::io::{readable_class_name, Code, StructureCodes};

/// The table, compiled in so that a malformed row is caught by the tests, not met by a user.
const TSV: &str = include_str!("standard_codes.tsv");

const HEADER: &str = "class\tcategory_scheme\tcategory_value\tcategory_meaning\t\
                      type_scheme\ttype_value\ttype_meaning\t\
                      modifier_scheme\tmodifier_value\tmodifier_meaning\tcolor";

/// The parsed table: each class with its codes, and an index by both of its names.
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
    /// Panics naming the line of a malformed row: the text is compiled in, so that is a
    /// programming error, and the unit tests parse it.
    fn parse(text: &'static str) -> Self {
        let mut lines = (text.lines().enumerate()).filter(|(_, line)| !line.starts_with('#'));
        let header = lines.next().map(|(_, line)| line);
        assert_eq!(header, Some(HEADER), "standard_codes.tsv: header");
        let rows: Vec<_> = lines
            .map(|(i, line)| {
                parse_row(line).unwrap_or_else(|e| panic!("standard_codes.tsv line {}: {e}", i + 1))
            })
            .collect();
        let mut by_name = HashMap::with_capacity(2 * rows.len());
        for (row, (class, ..)) in rows.iter().enumerate() {
            // Single-word classes ("liver") read as they are written: one key for both.
            for name in [normalise(class), normalise(&readable_class_name(class))] {
                let before = by_name.insert(name.clone(), row);
                assert!(
                    before.is_none_or(|b| b == row),
                    "standard_codes.tsv: two classes are named '{name}'"
                );
            }
        }
        Self { rows, by_name }
    }

    fn get() -> &'static Self {
        static TABLE: OnceLock<Table> = OnceLock::new();
        TABLE.get_or_init(|| Self::parse(TSV))
    }
}

/// One of TotalSegmentator's classes: its codes and display colour (sRGB, channels in [0, 1]).
#[derive(Clone, Debug, PartialEq)]
pub struct StandardClass {
    pub codes: StructureCodes,
    pub color: [f32; 3],
}

/// The class a structure named `name` is, when it is one of TotalSegmentator's.
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
        assert_eq!(Table::get().rows.len(), 117);
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
        let table = Table::parse(TSV);
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
