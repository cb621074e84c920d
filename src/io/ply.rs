//! PLY: the header (elements, properties, encoding) and what the body readers need from it.
//!
//! The body readers live in `ply_binary` and `ply_ascii`. Only `vertex` (x, y, z) and `face`
//! (`vertex_indices` or `vertex_index`) are read; every other property and element is skipped.
use super::text::{self, Lines};
use super::{ply_ascii, ply_binary, Format, LoadError, Location};
use crate::mesh::Mesh;

pub(super) const FORMAT: Format = Format::Ply;

pub(super) fn parse(bytes: &[u8]) -> Result<Mesh, LoadError> {
    let header = Header::parse(bytes)?;
    let body = bytes.get(header.body_start..).unwrap_or_default();
    // Every count is checked against the bytes before anything is allocated from it.
    check_counts(&header, body)?;
    // Vertex numbers are u32 with u32::MAX reserved for "none".
    let vertex_count = usize::try_from(header.vertex_count)
        .ok()
        .filter(|&n| n < u32::MAX as usize)
        .ok_or_else(|| unsupported("more than 4294967294 vertices"))?;
    let mesh = match header.encoding {
        Encoding::Ascii => ply_ascii::read(&header, bytes, vertex_count)?,
        Encoding::BinaryLittleEndian => ply_binary::read::<false>(&header, body, vertex_count)?,
        Encoding::BinaryBigEndian => ply_binary::read::<true>(&header, body, vertex_count)?,
    };
    if mesh.triangles.is_empty() {
        return Err(LoadError::NoTriangles { format: FORMAT });
    }
    Ok(mesh)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// PLY scalar types, under both their classic and their sized names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Property {
    Scalar(Scalar),
    /// A list: its length's type and its items' type.
    List(Scalar, Scalar),
}

impl Property {
    /// Smallest encoding in a binary body: a scalar, or an empty list's length.
    pub(super) fn min_size(self) -> usize {
        match self {
            Property::Scalar(t) | Property::List(t, _) => t.size(),
        }
    }
}

/// What an element is to the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Role {
    /// Read x, y, z from these property positions.
    Vertex {
        xyz: [usize; 3],
    },
    /// Fan-triangulate the list at this property position.
    Face {
        indices: usize,
    },
    Skip,
}

#[derive(Debug, Clone, PartialEq)]
pub(super) struct Element {
    pub name: String,
    pub count: u64,
    pub properties: Vec<Property>,
    pub role: Role,
}

impl Element {
    /// The fewest bytes (binary) or tokens (ASCII) one record can take.
    pub(super) fn min_size(&self) -> usize {
        self.properties.iter().map(|p| p.min_size()).sum()
    }

    /// Used in count errors (the error names a static noun).
    pub(super) fn noun(&self) -> &'static str {
        match self.role {
            Role::Vertex { .. } => "vertices",
            Role::Face { .. } => "faces",
            Role::Skip => "records of another element",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub(super) struct Header {
    pub encoding: Encoding,
    pub elements: Vec<Element>,
    /// Byte offset of the first body byte.
    pub body_start: usize,
    /// Line number of the first body line (for ASCII error messages).
    pub body_line: usize,
    /// Vertex count from the `vertex` element (0 when absent); unchecked.
    pub vertex_count: u64,
}

/// Names of the properties seen so far in the current element (for the role).
struct Pending {
    element: Element,
    names: Vec<Vec<u8>>,
    line: usize,
}

/// The encoding a `format` line names.
fn parse_encoding(name: &[u8], line: usize) -> Result<Encoding, LoadError> {
    Ok(match name {
        b"ascii" => Encoding::Ascii,
        b"binary_little_endian" => Encoding::BinaryLittleEndian,
        b"binary_big_endian" => Encoding::BinaryBigEndian,
        other => {
            return Err(syntax(
                line,
                format!("unknown format '{}'", text::show(other)),
            ))
        }
    })
}

impl Pending {
    /// An element declared on `line` as `element NAME COUNT`, its properties to follow.
    fn begin(name: &[u8], count: &[u8], line: usize) -> Result<Self, LoadError> {
        let count = text::parse_int(count)
            .and_then(|c| u64::try_from(c).ok())
            .ok_or_else(|| syntax(line, format!("bad element count '{}'", text::show(count))))?;
        Ok(Pending {
            element: Element {
                name: String::from_utf8_lossy(name).into_owned(),
                count,
                properties: Vec::new(),
                role: Role::Skip,
            },
            names: Vec::new(),
            line,
        })
    }
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, LoadError> {
        let mut lines = Lines::new(bytes);
        match lines.next() {
            Some((_, magic)) if magic.trim_ascii_end() == b"ply" => {}
            _ => {
                return Err(LoadError::BadMagic {
                    format: FORMAT,
                    detail: "the first line is not 'ply'".into(),
                })
            }
        }
        let mut encoding = None;
        let mut elements: Vec<Element> = Vec::new();
        let mut pending: Option<Pending> = None;
        while let Some((line, content)) = lines.next() {
            let words: Vec<&[u8]> = text::tokens(content).collect();
            // A last line with no terminator cannot be followed by 'end_header': the file was
            // cut inside the header, whatever the partial line looks like.
            let unterminated =
                lines.offset() == bytes.len() && !matches!(bytes.last(), Some(b'\n' | b'\r'));
            if unterminated && words.as_slice() != [b"end_header"] {
                return Err(LoadError::Truncated {
                    format: FORMAT,
                    offset: bytes.len(),
                    detail: format!("the header ends inside line {line}"),
                });
            }
            match words.as_slice() {
                [] => {}
                [b"comment" | b"obj_info", ..] => {}
                [b"format", name, ..] => encoding = Some(parse_encoding(name, line)?),
                [b"element", name, count] => {
                    if let Some(done) = pending.take() {
                        elements.push(finish(done)?);
                    }
                    pending = Some(Pending::begin(name, count, line)?);
                }
                [b"property", rest @ ..] => {
                    let Some(current) = pending.as_mut() else {
                        return Err(syntax(line, "'property' before any 'element'".into()));
                    };
                    let (property, name) = parse_property(rest, line)?;
                    current.element.properties.push(property);
                    current.names.push(name.to_vec());
                }
                [b"end_header"] => {
                    if let Some(done) = pending.take() {
                        elements.push(finish(done)?);
                    }
                    let encoding = encoding.ok_or_else(|| {
                        syntax(line, "no 'format' line before 'end_header'".into())
                    })?;
                    return Header::complete(encoding, elements, lines.offset(), line + 1);
                }
                [word, ..] => {
                    return Err(syntax(
                        line,
                        format!("unexpected header line starting '{}'", text::show(word)),
                    ))
                }
            }
        }
        Err(LoadError::Truncated {
            format: FORMAT,
            offset: bytes.len(),
            detail: "the header has no 'end_header'".into(),
        })
    }

    fn complete(
        encoding: Encoding,
        elements: Vec<Element>,
        body_start: usize,
        body_line: usize,
    ) -> Result<Header, LoadError> {
        let mut vertex_count = None;
        let mut faces = false;
        for e in &elements {
            match e.role {
                Role::Vertex { .. } if vertex_count.is_some() => {
                    return Err(unsupported("more than one 'vertex' element"))
                }
                Role::Vertex { .. } => vertex_count = Some(e.count),
                Role::Face { .. } if faces => {
                    return Err(unsupported("more than one 'face' element"))
                }
                Role::Face { .. } => faces = true,
                Role::Skip => {}
            }
        }
        Ok(Header {
            encoding,
            elements,
            body_start,
            body_line,
            vertex_count: vertex_count.unwrap_or(0),
        })
    }
}

/// `property <type> <name>` or `property list <count type> <item type> <name>`.
fn parse_property<'a>(rest: &[&'a [u8]], line: usize) -> Result<(Property, &'a [u8]), LoadError> {
    let scalar = |name: &[u8]| {
        Scalar::from_name(name)
            .ok_or_else(|| syntax(line, format!("unknown type '{}'", text::show(name))))
    };
    match rest {
        [b"list", count, item, name] => {
            let count = scalar(count)?;
            if !count.is_integer() {
                return Err(syntax(
                    line,
                    "a list length must have an integer type".into(),
                ));
            }
            Ok((Property::List(count, scalar(item)?), name))
        }
        [ty, name] => Ok((Property::Scalar(scalar(ty)?), name)),
        _ => Err(syntax(line, "malformed 'property' line".into())),
    }
}

/// Gives a finished element its role from its name and property names.
fn finish(pending: Pending) -> Result<Element, LoadError> {
    let Pending {
        mut element,
        names,
        line,
    } = pending;
    let position = |wanted: &[u8]| names.iter().position(|n| n == wanted);
    element.role = match element.name.as_str() {
        "vertex" => {
            let mut xyz = [0usize; 3];
            for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
                let at = position(axis.as_bytes()).ok_or_else(|| {
                    syntax(line, format!("the vertex element has no '{axis}' property"))
                })?;
                if matches!(element.properties.get(at), Some(Property::List(..))) {
                    return Err(syntax(line, format!("vertex property '{axis}' is a list")));
                }
                *slot = at;
            }
            Role::Vertex { xyz }
        }
        "face" => {
            let at = position(b"vertex_indices")
                .or_else(|| position(b"vertex_index"))
                .ok_or_else(|| {
                    syntax(line, "the face element has no 'vertex_indices' list".into())
                })?;
            match element.properties.get(at) {
                Some(Property::List(_, item)) if item.is_integer() => {}
                _ => {
                    return Err(syntax(
                        line,
                        "face 'vertex_indices' must be a list of integers".into(),
                    ))
                }
            }
            Role::Face { indices: at }
        }
        _ => Role::Skip,
    };
    Ok(element)
}

pub(super) fn syntax(line: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format: FORMAT,
        location: Location::Line(line),
        detail,
    }
}

fn unsupported(detail: &str) -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail: detail.into(),
    }
}

/// Fails when the elements' records, each at their smallest, cannot fit in the body: bytes for
/// binary, tokens for ASCII (each token takes a byte and a separator, bar the last).
fn check_counts(header: &Header, body: &[u8]) -> Result<(), LoadError> {
    let ascii = header.encoding == Encoding::Ascii;
    let available = if ascii {
        body.len().div_ceil(2)
    } else {
        body.len()
    } as u128;
    let mut used: u128 = 0;
    for e in &header.elements {
        let min = if ascii {
            e.properties.len()
        } else {
            e.min_size()
        } as u128;
        let need = u128::from(e.count) * min;
        if used + need > available {
            return Err(LoadError::CountTooLarge {
                format: FORMAT,
                what: e.noun(),
                claimed: e.count,
                possible: ((available - used) / min.max(1)) as u64,
            });
        }
        used += need;
    }
    Ok(())
}

/// Builds one fan triangle per corner after the second; shared by both body readers.
pub(super) struct Fan {
    first: u32,
    previous: u32,
    corners: usize,
}

impl Fan {
    pub(super) fn new() -> Self {
        Self {
            first: 0,
            previous: 0,
            corners: 0,
        }
    }

    #[inline]
    pub(super) fn push(&mut self, v: u32, triangles: &mut Vec<[u32; 3]>) {
        match self.corners {
            0 => self.first = v,
            1 => {}
            _ => triangles.push([self.first, self.previous, v]),
        }
        self.previous = v;
        self.corners += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_roles_offsets_and_aliases() {
        let bytes = b"ply\r\nformat binary_big_endian 1.0\r\ncomment hi there\r\n\
element vertex 2\r\nproperty float64 z\r\nproperty uint8 red\r\nproperty double x\r\nproperty float y\r\n\
element edge 1\r\nproperty list uint16 int32 vertex_index\r\n\
element face 3\r\nproperty list char uint vertex_index\r\nend_header\r\nBODY";
        let h = Header::parse(bytes).expect("valid header");
        assert_eq!(h.encoding, Encoding::BinaryBigEndian);
        assert_eq!(&bytes[h.body_start..], b"BODY");
        assert_eq!(h.body_line, 14);
        assert_eq!(h.vertex_count, 2u64);
        assert_eq!(h.elements[0].role, Role::Vertex { xyz: [2, 3, 0] });
        assert_eq!(h.elements[0].min_size(), 8 + 1 + 8 + 4);
        assert_eq!(h.elements[1].role, Role::Skip);
        assert_eq!(h.elements[2].role, Role::Face { indices: 0 });
        assert_eq!(
            h.elements[2].properties,
            vec![Property::List(Scalar::I8, Scalar::U32)]
        );
    }

    #[test]
    fn header_errors_name_the_line() {
        let e = Header::parse(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n",
        );
        assert!(
            matches!(
                e,
                Err(LoadError::Syntax {
                    location: Location::Line(3),
                    ..
                })
            ),
            "{e:?}"
        );
        let e = Header::parse(b"ply\nformat ascii 1.0\nproperty float x\n");
        assert!(
            matches!(
                e,
                Err(LoadError::Syntax {
                    location: Location::Line(3),
                    ..
                })
            ),
            "{e:?}"
        );
        let e = Header::parse(
            b"ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n",
        );
        assert!(
            matches!(
                e,
                Err(LoadError::Syntax {
                    location: Location::Line(4),
                    ..
                })
            ),
            "{e:?}"
        );
        let e = Header::parse(b"ply\nformat ascii 1.0\n");
        assert!(matches!(e, Err(LoadError::Truncated { .. })), "{e:?}");
        let e = Header::parse(b"plyx\n");
        assert!(matches!(e, Err(LoadError::BadMagic { .. })), "{e:?}");
    }
}
