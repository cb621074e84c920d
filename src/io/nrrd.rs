//! NRRD label maps with attached data (`.nrrd`, 3D Slicer's `.seg.nrrd`): raw or gzip encoding,
//! 3D, or 4D with one axis a list of layers (first: interleaved, as Slicer writes overlapping
//! segments; or last: one layer after another), with Slicer's `SegmentN_*` names and colours.
//!
//! Grids go to RAS: `space directions` (or `spacings`, or 1) and `space origin`, with LPS and LAS
//! turned to RAS by negating rows. Detached headers (`data file`) are refused: parsers take
//! bytes, never paths.

use std::collections::BTreeMap;

use super::codes::{self, StructureCodes};
use super::gzip::Inflater;
use super::label_map::LabelMapOptions;
use super::label_map::{Affine, LabelMap, Segment};
use super::label_map_checks::{check_affine, check_raw, check_spacing, Sample, VoxelLayout};
use super::text::Lines;
use super::voxels::{self, Feed, Streamed, VoxelSink};
use super::{Format, LoadError, Location};

const FORMAT: Format = Format::Nrrd;

pub(super) fn parse(bytes: &[u8], options: &LabelMapOptions) -> Result<LabelMap, LoadError> {
    let volume = read(bytes, |layout| VoxelSink::new(layout, options, FORMAT))?;
    let segments = volume.meta.segments(volume.layout.layers)?;
    Ok(LabelMap {
        dims: volume.layout.dims,
        affine: volume.affine,
        layers: volume.sink.finish()?,
        segments,
        conventional: Vec::new(),
    })
}

type Volume<S> = Streamed<S, Header>;

/// Reads a NRRD file's header, then streams its voxels into the sink `make` builds for their
/// layout (label codes, or an image's intensities).
pub(super) fn read<S: Feed>(
    bytes: &[u8],
    make: impl FnOnce(&VoxelLayout) -> Result<S, LoadError>,
) -> Result<Volume<S>, LoadError> {
    let header = Header::parse(bytes)?;
    let (layout, spatial) = header.layout()?;
    let affine = header.affine(spatial)?;
    let data_bytes = layout.data_bytes(FORMAT)?;
    let data = bytes.get(header.data_start..).unwrap_or_default();
    let mut sink;
    match header.encoding {
        Some(Encoding::Raw) => {
            check_raw(data_bytes, data.len(), FORMAT)?;
            sink = make(&layout)?;
            sink.feed(&data[..data_bytes as usize])?;
        }
        Some(Encoding::Gzip) => {
            let mut inflater = Inflater::new(data, FORMAT);
            inflater.check_ratio(data_bytes, "bytes of inflated voxel data")?;
            inflater.expect_total(data_bytes);
            sink = make(&layout)?;
            voxels::decode_gzip(inflater, &mut sink, data_bytes)?;
        }
        None => return Err(missing("encoding", header.end_line)),
    }
    Ok(Streamed {
        layout,
        affine,
        sink,
        meta: header,
    })
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Raw,
    Gzip,
}

/// The world frame the directions are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum Space {
    /// RAS, or no `space` field: directions are taken as they are.
    #[default]
    Ras,
    Las,
    Lps,
}

/// A field's value and the line it was on.
#[derive(Debug, Clone)]
struct Field<T> {
    value: T,
    line: usize,
}

/// One of Slicer's segments as its `SegmentN_*` keys describe it.
#[derive(Debug, Clone, Default)]
struct SegmentFields {
    name: Option<String>,
    color: Option<[f32; 3]>,
    value: Option<i64>,
    layer: Option<Field<usize>>,
    codes: Option<StructureCodes>,
}

#[derive(Debug, Default)]
pub(super) struct Header {
    data_start: usize,
    /// The blank line that ends the header (where missing fields are reported).
    end_line: usize,
    sample: Option<Sample>,
    dimension: Option<usize>,
    sizes: Option<Field<Vec<usize>>>,
    big_endian: bool,
    encoding: Option<Encoding>,
    space: Space,
    directions: Option<Field<Vec<Option<[f64; 3]>>>>,
    origin: Option<[f64; 3]>,
    kinds: Option<Field<Vec<String>>>,
    spacings: Option<Field<Vec<f64>>>,
    segments: BTreeMap<usize, SegmentFields>,
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, LoadError> {
        let mut lines = Lines::new(bytes);
        let magic = lines.next().map(|(_, m)| m).unwrap_or_default();
        let is_magic =
            magic.len() == 8 && magic.starts_with(b"NRRD000") && magic[7].is_ascii_digit();
        if !is_magic {
            return Err(LoadError::BadMagic {
                format: FORMAT,
                detail: format!(
                    "the first line is {:?}, not NRRD000N",
                    super::text::show(magic)
                ),
            });
        }
        let mut header = Header::default();
        let mut last_line = 1;
        while let Some((line, text)) = lines.next() {
            last_line = line;
            if text.is_empty() {
                header.end_line = line;
                header.data_start = lines.offset();
                return Ok(header);
            }
            if !text.starts_with(b"#") {
                header.read_line(line, &String::from_utf8_lossy(text))?;
            }
        }
        Err(LoadError::Truncated {
            format: FORMAT,
            offset: bytes.len(),
            detail: format!(
                "the header (to line {last_line}) does not end with a blank line, so the file \
                 holds no data"
            ),
        })
    }

    fn read_line(&mut self, line: usize, text: &str) -> Result<(), LoadError> {
        let key_value = text.find(":=");
        let field = text.find(": ").or(text.strip_suffix(':').map(str::len));
        match (key_value, field) {
            (Some(k), f) if f.is_none_or(|f| k < f) => {
                self.key_value(line, &text[..k], &text[k + 2..])
            }
            (_, Some(f)) => {
                let name = text[..f].trim().to_ascii_lowercase();
                let value = text.get(f + 1..).unwrap_or_default().trim();
                self.field(line, &name, value)
            }
            _ => Err(syntax(
                line,
                format!("expected 'field: value' or 'key:=value', found {text:?}"),
            )),
        }
    }

    fn field(&mut self, line: usize, name: &str, value: &str) -> Result<(), LoadError> {
        match name {
            "type" => self.sample = Some(sample_of(line, value)?),
            "dimension" => {
                let d = value.parse::<usize>().ok().filter(|d| matches!(d, 3 | 4));
                let detail = || {
                    format!("dimension {value:?}: a label map has 3 (or 4, with a list of layers)")
                };
                self.dimension = Some(d.ok_or_else(|| syntax(line, detail()))?);
            }
            "sizes" => {
                let sizes = value
                    .split_whitespace()
                    .map(|t| t.parse::<usize>().ok().filter(|&n| n >= 1))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        syntax(
                            line,
                            format!("sizes {value:?}: each must be a whole number >= 1"),
                        )
                    })?;
                self.sizes = Some(Field { value: sizes, line });
            }
            "endian" => {
                self.big_endian = match value.to_ascii_lowercase().as_str() {
                    "little" => false,
                    "big" => true,
                    _ => return Err(syntax(line, format!("endian {value:?}: little or big"))),
                }
            }
            "encoding" => self.encoding = Some(encoding_of(line, value)?),
            "space" => self.space = space_of(line, value)?,
            "space dimension" if value != "3" => {
                let detail = format!("space dimension {value}: a label map needs 3");
                return Err(syntax(line, detail));
            }
            "space directions" => {
                let value = parse_directions(line, value)?;
                self.directions = Some(Field { value, line });
            }
            "space origin" => self.origin = Some(parse_vector(line, value)?),
            "kinds" => {
                let value = value
                    .split_whitespace()
                    .map(str::to_ascii_lowercase)
                    .collect();
                self.kinds = Some(Field { value, line });
            }
            "spacings" => {
                let value = value
                    .split_whitespace()
                    .map(|t| t.parse::<f64>().ok())
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| syntax(line, format!("spacings {value:?}: not numbers")))?;
                self.spacings = Some(Field { value, line });
            }
            "data file" | "datafile" => {
                return Err(unsupported(format!(
                    "line {line}: a detached header (data file: {value}): the voxels must be in \
                     the same file; save it as a single .nrrd"
                )))
            }
            "line skip" | "lineskip" | "byte skip" | "byteskip" if value != "0" => {
                return Err(unsupported(format!(
                    "line {line}: {name} {value} is not supported"
                )))
            }
            _ => {}
        }
        Ok(())
    }

    /// 3D Slicer's `SegmentN_Name`, `_Color`, `_LabelValue`, `_Layer`, `_Tags` (its terminology
    /// entry); other keys are ignored.
    fn key_value(&mut self, line: usize, key: &str, value: &str) -> Result<(), LoadError> {
        let Some((n, what)) = key.strip_prefix("Segment").and_then(|k| k.split_once('_')) else {
            return Ok(());
        };
        let Ok(n) = n.parse::<usize>() else {
            return Ok(());
        };
        let segment = self.segments.entry(n).or_default();
        let bad = |what: &str| syntax(line, format!("{key} {value:?}: {what}"));
        match what {
            "Name" => segment.name = Some(value.to_string()),
            "Color" => segment.color = Some(parse_color(value).ok_or_else(|| bad("not 'r g b'"))?),
            "LabelValue" => {
                let v = value
                    .trim()
                    .parse()
                    .map_err(|_| bad("not a whole number"))?;
                segment.value = Some(v);
            }
            "Layer" => {
                let v = value
                    .trim()
                    .parse()
                    .map_err(|_| bad("not a layer number"))?;
                segment.layer = Some(Field { value: v, line });
            }
            "Tags" => segment.codes = codes::from_slicer_tags(value),
            _ => {}
        }
        Ok(())
    }

    /// The voxel layout, and which axes (in order) are i, j, k.
    fn layout(&self) -> Result<(VoxelLayout, [usize; 3]), LoadError> {
        let sample = self.sample.ok_or_else(|| missing("type", self.end_line))?;
        let dimension = self
            .dimension
            .ok_or_else(|| missing("dimension", self.end_line))?;
        let sizes = self
            .sizes
            .as_ref()
            .ok_or_else(|| missing("sizes", self.end_line))?;
        if sizes.value.len() != dimension {
            let detail = format!("{} sizes for dimension {dimension}", sizes.value.len());
            return Err(syntax(sizes.line, detail));
        }
        self.check_counts(dimension)?;
        let list = if dimension == 4 {
            Some(self.list_axis()?)
        } else {
            None
        };
        let mut spatial = [0usize; 3];
        for (slot, axis) in spatial
            .iter_mut()
            .zip((0..dimension).filter(|&a| Some(a) != list))
        {
            *slot = axis;
        }
        if let Some(axis) = list.filter(|&a| a != 0 && a != 3) {
            return Err(unsupported(format!(
                "the list of layers is axis {axis}: only the first or the last axis can be"
            )));
        }
        let layout = VoxelLayout {
            dims: spatial.map(|a| sizes.value[a]),
            layers: list.map_or(1, |a| sizes.value[a]),
            interleaved: list == Some(0),
            sample,
            big_endian: self.big_endian,
            slope: 1.0,
            inter: 0.0,
        };
        Ok((layout, spatial))
    }

    /// Per-axis fields must have one entry per axis.
    fn check_counts(&self, dimension: usize) -> Result<(), LoadError> {
        let counts = [
            (
                "space directions",
                self.directions.as_ref().map(|f| (f.value.len(), f.line)),
            ),
            (
                "kinds",
                self.kinds.as_ref().map(|f| (f.value.len(), f.line)),
            ),
            (
                "spacings",
                self.spacings.as_ref().map(|f| (f.value.len(), f.line)),
            ),
        ];
        for (name, count) in counts {
            if let Some((n, line)) = count.filter(|&(n, _)| n != dimension) {
                let detail = format!("{name}: {n} entries for dimension {dimension}");
                return Err(syntax(line, detail));
            }
        }
        Ok(())
    }

    /// The one non-spatial axis of a 4D file: its direction is `none`, or its kind is neither
    /// `domain` nor `space`.
    fn list_axis(&self) -> Result<usize, LoadError> {
        let (candidates, line): (Vec<usize>, usize) = if let Some(d) = &self.directions {
            let none = (0..4).filter(|&a| d.value[a].is_none()).collect();
            (none, d.line)
        } else if let Some(k) = &self.kinds {
            let spatial = |kind: &str| matches!(kind, "domain" | "space");
            let other = (0..4).filter(|&a| !spatial(&k.value[a])).collect();
            (other, k.line)
        } else {
            return Err(syntax(
                self.end_line,
                "dimension 4 needs 'space directions' or 'kinds' to tell the list of layers".into(),
            ));
        };
        match candidates.as_slice() {
            [axis] => Ok(*axis),
            _ => Err(syntax(
                line,
                format!(
                    "dimension 4 needs exactly one list axis ('none' direction or a non-spatial \
                     kind), found {}",
                    candidates.len()
                ),
            )),
        }
    }

    fn affine(&self, spatial: [usize; 3]) -> Result<Affine, LoadError> {
        let mut m = [[0.0; 4]; 3];
        let (line, source) = if let Some(d) = &self.directions {
            for (c, &axis) in spatial.iter().enumerate() {
                let Some(column) = d.value[axis] else {
                    return Err(syntax(
                        d.line,
                        format!("space directions: axis {axis} is none"),
                    ));
                };
                for r in 0..3 {
                    m[r][c] = column[r];
                }
            }
            (d.line, "space directions")
        } else if let Some(s) = &self.spacings {
            for (c, &axis) in spatial.iter().enumerate() {
                m[c][c] = check_spacing(s.value[axis], FORMAT, Location::Line(s.line), "spacings")?;
            }
            (s.line, "spacings")
        } else {
            for (c, row) in m.iter_mut().enumerate() {
                row[c] = 1.0;
            }
            (self.end_line, "spacing (none given: 1)")
        };
        let origin = self.origin.unwrap_or_default();
        for r in 0..3 {
            m[r][3] = origin[r];
        }
        let flipped_rows = match self.space {
            Space::Ras => 0,
            Space::Las => 1,
            Space::Lps => 2,
        };
        for row in m.iter_mut().take(flipped_rows) {
            row.iter_mut().for_each(|v| *v = -*v);
        }
        let affine = Affine(m);
        check_affine(&affine, FORMAT, Location::Line(line), source)?;
        Ok(affine)
    }

    /// The segments Slicer's keys declare, in key order; label value N+1 and layer 0 unless
    /// given.
    fn segments(&self, layers: usize) -> Result<Vec<Segment>, LoadError> {
        let mut out = Vec::with_capacity(self.segments.len());
        for (&n, fields) in &self.segments {
            let layer = fields.layer.as_ref().map_or(0, |f| f.value);
            if let Some(f) = fields.layer.as_ref().filter(|f| f.value >= layers) {
                return Err(syntax(
                    f.line,
                    format!(
                        "Segment{n}_Layer {}: the file has {layers} layer(s)",
                        f.value
                    ),
                ));
            }
            out.push(Segment {
                layer,
                value: fields.value.unwrap_or((n as i64).saturating_add(1)),
                name: fields
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("Segment_{n}")),
                color: fields.color,
                codes: fields.codes.clone(),
            });
        }
        Ok(out)
    }
}

fn sample_of(line: usize, value: &str) -> Result<Sample, LoadError> {
    Ok(match value.to_ascii_lowercase().as_str() {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => Sample::U8,
        "signed char" | "int8" | "int8_t" => Sample::I8,
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => Sample::U16,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            Sample::I16
        }
        "uint" | "unsigned int" | "uint32" | "uint32_t" => Sample::U32,
        "int" | "signed int" | "int32" | "int32_t" => Sample::I32,
        "float" => Sample::F32,
        "double" => Sample::F64,
        _ => {
            return Err(unsupported(format!(
                "line {line}: type {value:?} is not supported: a label map needs (u)int8, \
                 (u)int16, (u)int32, float or double"
            )))
        }
    })
}

fn encoding_of(line: usize, value: &str) -> Result<Encoding, LoadError> {
    match value.to_ascii_lowercase().as_str() {
        "raw" => Ok(Encoding::Raw),
        "gzip" | "gz" => Ok(Encoding::Gzip),
        other => Err(unsupported(format!(
            "line {line}: encoding {other:?} is not supported: save the file with raw or gzip \
             encoding"
        ))),
    }
}

fn space_of(line: usize, value: &str) -> Result<Space, LoadError> {
    match value.to_ascii_lowercase().as_str() {
        "ras" | "right-anterior-superior" => Ok(Space::Ras),
        "las" | "left-anterior-superior" => Ok(Space::Las),
        "lps" | "left-posterior-superior" => Ok(Space::Lps),
        _ => Err(unsupported(format!(
            "line {line}: space {value:?} is not supported: a label map needs RAS, LAS or LPS"
        ))),
    }
}

/// `(x,y,z)` vectors or `none`, one per axis. An all-NaN vector (older ITK) counts as `none`.
fn parse_directions(line: usize, value: &str) -> Result<Vec<Option<[f64; 3]>>, LoadError> {
    let mut out = Vec::new();
    let mut rest = value.trim_start();
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("none") {
            out.push(None);
            rest = after.trim_start();
            continue;
        }
        let end = rest.find(')').map_or(rest.len(), |e| e + 1);
        let (vector, after) = rest.split_at(end);
        let v = parse_vector_allowing_nan(line, vector)?;
        out.push(if v.iter().all(|c| c.is_nan()) {
            None
        } else {
            Some(v)
        });
        rest = after.trim_start();
    }
    Ok(out)
}

fn parse_vector(line: usize, text: &str) -> Result<[f64; 3], LoadError> {
    let v = parse_vector_allowing_nan(line, text)?;
    if v.iter().any(|c| !c.is_finite()) {
        return Err(syntax(line, format!("{text:?}: not a finite vector")));
    }
    Ok(v)
}

fn parse_vector_allowing_nan(line: usize, text: &str) -> Result<[f64; 3], LoadError> {
    let bad = || syntax(line, format!("{text:?} is not a vector '(x,y,z)'"));
    let inner = text
        .trim()
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .ok_or_else(bad)?;
    let parts: Vec<&str> = inner.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(bad());
    };
    let c = |t: &str| t.parse::<f64>().map_err(|_| bad());
    let v = [c(x)?, c(y)?, c(z)?];
    if v.iter().any(|c| c.is_infinite())
        || (v.iter().any(|c| c.is_nan()) && !v.iter().all(|c| c.is_nan()))
    {
        return Err(syntax(line, format!("{text:?}: not a finite vector")));
    }
    Ok(v)
}

/// Slicer's `SegmentN_Color`: three floats 0..1, clamped.
fn parse_color(value: &str) -> Option<[f32; 3]> {
    let parts: Vec<f32> = value
        .split_whitespace()
        .map(|t| t.parse::<f32>().ok().filter(|c| c.is_finite()))
        .collect::<Option<_>>()?;
    let [r, g, b] = parts.as_slice() else {
        return None;
    };
    Some([*r, *g, *b].map(|c| c.clamp(0.0, 1.0)))
}

fn missing(field: &str, line: usize) -> LoadError {
    syntax(line, format!("the header has no '{field}' field"))
}

fn syntax(line: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format: FORMAT,
        location: Location::Line(line),
        detail,
    }
}

fn unsupported(detail: String) -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail,
    }
}
