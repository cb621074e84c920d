//! Colour tables that name a label map's labels, in the three forms they come in:
//!
//! - 3D Slicer and FreeSurfer: `index name R G B [A]`, channels 0..255, `#` comments;
//! - FSL and MRIcron: `index<TAB>name` (no colour);
//! - ITK-SNAP label descriptions: `IDX -R- -G- -B- -A-- VIS MSH "LABEL"`.
//!
//! Names may contain spaces in the tab-separated and ITK-SNAP forms. A whitespace-separated name
//! of several words is kept, its words joined by single spaces.

use super::text::{self, Lines};
use super::{Format, LoadError, Location};

const FORMAT: Format = Format::ColorTable;

/// One label of a colour table.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelEntry {
    pub value: i64,
    pub name: String,
    /// Display (sRGB) colour, each channel in [0, 1]; `None` when the table gives none.
    pub color: Option<[f32; 3]>,
}

/// Whether a file name is one a colour table comes in (`.txt`: FreeSurfer, FSL, ITK-SNAP;
/// `.ctbl`: 3D Slicer), ignoring case. Only beside a label map is such a file read as one.
pub fn is_color_table(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.ends_with(".txt") || lower.ends_with(".ctbl")
}

/// Reads a colour table; entries come in file order (a later entry for the same value is a
/// later line, which callers may let win).
pub fn parse_color_table(text: &[u8]) -> Result<Vec<LabelEntry>, LoadError> {
    let mut entries = Vec::new();
    for (line, bytes) in Lines::new(text::strip_bom(text)) {
        let content = String::from_utf8_lossy(bytes);
        let content = content.trim();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let entry = if content.contains('"') {
            itk_snap_entry(content)
        } else {
            plain_entry(content)
        };
        entries.push(entry.map_err(|detail| LoadError::Syntax {
            format: FORMAT,
            location: Location::Line(line),
            detail,
        })?);
    }
    if entries.is_empty() {
        return Err(LoadError::Empty { format: FORMAT });
    }
    Ok(entries)
}

/// `IDX -R- -G- -B- -A-- VIS MSH "LABEL"`.
fn itk_snap_entry(line: &str) -> Result<LabelEntry, String> {
    let (fields, quoted) = line.split_once('"').unwrap_or((line, ""));
    let name = quoted
        .rsplit_once('"')
        .map(|(name, _)| name)
        .ok_or("the label name's closing quote is missing")?;
    let fields: Vec<&str> = fields.split_whitespace().collect();
    if fields.len() < 4 {
        return Err(format!(
            "expected 'IDX R G B A VIS MSH \"LABEL\"', found {} numbers before the name",
            fields.len()
        ));
    }
    Ok(LabelEntry {
        value: index_of(fields[0])?,
        name: name.to_string(),
        color: Some(color_of(&fields[1..4])?),
    })
}

/// `index name R G B [A]` or `index<TAB>name`.
fn plain_entry(line: &str) -> Result<LabelEntry, String> {
    // Tabs separate columns when there are any, so that a name may hold spaces.
    let fields: Vec<&str> = if line.contains('\t') {
        line.split('\t')
            .map(str::trim)
            .filter(|f| !f.is_empty())
            .collect()
    } else {
        line.split_whitespace().collect()
    };
    let Some((first, rest)) = fields.split_first() else {
        return Err("an empty line".into());
    };
    let value = index_of(first)?;
    let is_channel = |f: &&str| f.parse::<u32>().is_ok();
    // Colour columns: the last four (R G B A) or three (R G B) integers after a name.
    let channels = [4, 3]
        .into_iter()
        .find(|&n| rest.len() > n && rest[rest.len() - n..].iter().all(is_channel));
    let (name, color) = match channels {
        Some(n) => {
            let (name, rgba) = rest.split_at(rest.len() - n);
            (name, Some(color_of(&rgba[..3])?))
        }
        None => (rest, None),
    };
    if name.is_empty() {
        return Err(format!("label {value} has no name"));
    }
    Ok(LabelEntry {
        value,
        name: name.join(" "),
        color,
    })
}

fn index_of(field: &str) -> Result<i64, String> {
    field
        .parse()
        .map_err(|_| format!("{field:?} is not a label index (a whole number)"))
}

fn color_of(channels: &[&str]) -> Result<[f32; 3], String> {
    let mut rgb = [0.0f32; 3];
    for (c, field) in rgb.iter_mut().zip(channels) {
        let v: u32 =
            field.parse().ok().filter(|&v| v <= 255).ok_or_else(|| {
                format!("colour channel {field:?} is not a whole number 0 to 255")
            })?;
        *c = v as f32 / 255.0;
    }
    Ok(rgb)
}
