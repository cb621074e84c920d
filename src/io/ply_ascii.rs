//! ASCII PLY bodies, read as a stream of whitespace-separated tokens (records may span or share
//! lines in the wild). Errors name the line of the offending token.
use super::ply::{syntax, Element, Fan, Header, Property, Role, FORMAT};
use super::text;
use super::{LoadError, Location};
use crate::mesh::Mesh;

/// Reads the body; `check_counts` has bounded every element count by the body's tokens.
pub(super) fn read(header: &Header, bytes: &[u8], vertex_count: usize) -> Result<Mesh, LoadError> {
    let mut tokens = Tokens {
        bytes,
        pos: header.body_start,
        line: header.body_line,
    };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for element in &header.elements {
        if element.properties.is_empty() {
            continue;
        }
        let possible_tokens = (bytes.len() - tokens.pos.min(bytes.len())).div_ceil(2);
        let count = element.count as usize;
        match element.role {
            Role::Vertex { xyz } => {
                positions.reserve_exact(count);
                for i in 0..count {
                    positions.push(tokens.vertex(element, xyz, i)?);
                }
            }
            Role::Face { indices } => {
                let per_triangle = element.properties.len() + 3;
                triangles.reserve(count.min(possible_tokens / per_triangle));
                for i in 0..count {
                    tokens.face(element, indices, vertex_count, i, &mut triangles)?;
                }
            }
            Role::Skip => {
                for i in 0..count {
                    for property in &element.properties {
                        tokens.skip_property(*property, element, i)?;
                    }
                }
            }
        }
    }
    Ok(Mesh::new(positions, triangles))
}

struct Tokens<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Line of the byte at `pos`.
    line: usize,
}

impl<'a> Tokens<'a> {
    /// The next token and its line, counting `\n`, `\r\n` and lone `\r` as one break each.
    fn next(&mut self) -> Option<(&'a [u8], usize)> {
        let rest = self.bytes.get(self.pos..)?;
        let mut skipped = 0;
        while let Some(&b) = rest.get(skipped) {
            if !text::is_space(b) {
                break;
            }
            let crlf = b == b'\r' && rest.get(skipped + 1) == Some(&b'\n');
            if (b == b'\n' || b == b'\r') && !crlf {
                self.line += 1;
            }
            skipped += 1;
        }
        let start = skipped;
        let len = rest
            .get(start..)?
            .iter()
            .position(|&b| text::is_space(b))
            .unwrap_or(rest.len() - start);
        self.pos += start + len;
        if len == 0 {
            return None;
        }
        rest.get(start..start + len).map(|t| (t, self.line))
    }

    /// The next token of record `i` of `e`, or a truncation error.
    fn expect(&mut self, e: &Element, i: usize) -> Result<(&'a [u8], usize), LoadError> {
        self.next().ok_or_else(|| LoadError::Truncated {
            format: FORMAT,
            offset: self.bytes.len(),
            detail: format!(
                "{} record {i} of {} is incomplete (line {})",
                e.name, e.count, self.line
            ),
        })
    }

    fn vertex(&mut self, e: &Element, xyz: [usize; 3], i: usize) -> Result<[f32; 3], LoadError> {
        let mut p = [0f32; 3];
        for (k, property) in e.properties.iter().enumerate() {
            match xyz.iter().position(|&a| a == k) {
                Some(axis) => {
                    let (token, line) = self.expect(e, i)?;
                    let value = text::parse_f32(token).ok_or_else(|| not_number(token, line))?;
                    if !value.is_finite() {
                        return Err(LoadError::NonFinite {
                            format: FORMAT,
                            location: Location::Line(line),
                            value: text::show(token),
                        });
                    }
                    p[axis] = value;
                }
                None => self.skip_property(*property, e, i)?,
            }
        }
        Ok(p)
    }

    fn face(
        &mut self,
        e: &Element,
        list_at: usize,
        vertex_count: usize,
        i: usize,
        triangles: &mut Vec<[u32; 3]>,
    ) -> Result<(), LoadError> {
        for (k, property) in e.properties.iter().enumerate() {
            if k != list_at {
                self.skip_property(*property, e, i)?;
                continue;
            }
            let (n, line) = self.list_length(e, i)?;
            if n < 3 {
                return Err(syntax(
                    line,
                    format!("a face needs at least 3 vertices, this one has {n}"),
                ));
            }
            let mut fan = Fan::new();
            for _ in 0..n {
                let (token, line) = self.expect(e, i)?;
                let index = text::parse_int(token).ok_or_else(|| {
                    syntax(
                        line,
                        format!("'{}' is not a vertex index", text::show(token)),
                    )
                })?;
                if index < 0 || index as u64 >= vertex_count as u64 {
                    return Err(LoadError::IndexOutOfRange {
                        format: FORMAT,
                        location: Location::Line(line),
                        index,
                        count: vertex_count,
                    });
                }
                fan.push(index as u32, triangles);
            }
        }
        Ok(())
    }

    /// Reads past one property, checking that its tokens are numbers.
    fn skip_property(
        &mut self,
        property: Property,
        e: &Element,
        i: usize,
    ) -> Result<(), LoadError> {
        let items = match property {
            Property::Scalar(_) => 1,
            Property::List(..) => self.list_length(e, i)?.0,
        };
        for _ in 0..items {
            let (token, line) = self.expect(e, i)?;
            if text::parse_f64(token).is_none() {
                return Err(not_number(token, line));
            }
        }
        Ok(())
    }

    fn list_length(&mut self, e: &Element, i: usize) -> Result<(usize, usize), LoadError> {
        let (token, line) = self.expect(e, i)?;
        let n = text::parse_int(token)
            .and_then(|n| usize::try_from(n).ok())
            .ok_or_else(|| syntax(line, format!("bad list length '{}'", text::show(token))))?;
        Ok((n, line))
    }
}

fn not_number(token: &[u8], line: usize) -> LoadError {
    syntax(line, format!("'{}' is not a number", text::show(token)))
}
