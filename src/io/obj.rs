//! OBJ: `v` and `f` records; everything else (normals, texture coordinates, groups, materials,
//! smoothing groups, comments, curves) is skipped. Polygons are fan-triangulated.
use super::text::{self, Lines};
use super::{Format, LoadError, Location};
use crate::mesh::Mesh;

const FORMAT: Format = Format::Obj;

pub(super) fn parse(bytes: &[u8]) -> Result<Mesh, LoadError> {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // Positive indices may point past the vertices read so far (a forward reference, which
    // common readers accept); they are checked once the whole file is read.
    let mut forward: Vec<(usize, i64)> = Vec::new();
    for (line, content) in Lines::new(text::strip_bom(bytes)) {
        let mut tokens = text::tokens(content);
        let Some(word) = tokens.next() else { continue };
        match word {
            b"v" => positions.push(read_vertex(&mut tokens, line, positions.len())?),
            b"f" => read_face(
                &mut tokens,
                line,
                positions.len(),
                &mut triangles,
                &mut forward,
            )?,
            _ if word.first() == Some(&b'#') => {}
            // Any other statement (vn, vt, vp, o, g, s, usemtl, mtllib, l, p, curves...) is a
            // keyword: skipped. Anything else means this is not OBJ text.
            _ if word.iter().all(|b| b.is_ascii_alphanumeric() || *b == b'_')
                && word.first().is_some_and(u8::is_ascii_alphabetic) => {}
            _ => {
                return Err(LoadError::Syntax {
                    format: FORMAT,
                    location: Location::Line(line),
                    detail: format!("unknown statement '{}'", text::show(word)),
                })
            }
        }
    }
    let count = positions.len();
    if let Some(&(line, index)) = forward.iter().find(|&&(_, i)| i as u64 > count as u64) {
        return Err(out_of_range(line, index, count));
    }
    if triangles.is_empty() {
        return Err(LoadError::NoTriangles { format: FORMAT });
    }
    Ok(Mesh::new(positions, triangles))
}

/// `v x y z [w]` (w and any trailing vertex colours are ignored).
fn read_vertex<'a>(
    tokens: &mut impl Iterator<Item = &'a [u8]>,
    line: usize,
    count: usize,
) -> Result<[f32; 3], LoadError> {
    // Vertex numbers are u32 with u32::MAX reserved for "none".
    if count >= u32::MAX as usize {
        return Err(LoadError::Unsupported {
            format: FORMAT,
            detail: "more than 4294967294 vertices".into(),
        });
    }
    text::read_xyz(tokens, FORMAT, line, "v")
}

/// `f a b c ...` with each corner `v`, `v/t`, `v//n` or `v/t/n`; negative `v` counts back from
/// the last vertex read. Polygons become the fan `(a, b, c), (a, c, d), ...`.
fn read_face<'a>(
    tokens: &mut impl Iterator<Item = &'a [u8]>,
    line: usize,
    count: usize,
    triangles: &mut Vec<[u32; 3]>,
    forward: &mut Vec<(usize, i64)>,
) -> Result<(), LoadError> {
    let mut first = None;
    let mut previous = None;
    let mut corners = 0usize;
    for token in tokens {
        if token.first() == Some(&b'#') {
            break;
        }
        let vertex = token.split(|&b| b == b'/').next().unwrap_or(token);
        let index = text::parse_int(vertex).ok_or_else(|| {
            syntax(
                line,
                format!("'{}' is not a vertex reference", text::show(token)),
            )
        })?;
        let resolved = resolve(index, line, count, forward)?;
        corners += 1;
        match (first, previous) {
            (Some(a), Some(b)) => triangles.push([a, b, resolved]),
            (None, _) => first = Some(resolved),
            _ => {}
        }
        previous = Some(resolved).filter(|_| corners >= 2);
    }
    if corners < 3 {
        return Err(syntax(
            line,
            format!("a face needs at least 3 vertices, this one has {corners}"),
        ));
    }
    Ok(())
}

/// 1-based index (or negative, relative) to a 0-based vertex number.
fn resolve(
    index: i64,
    line: usize,
    count: usize,
    forward: &mut Vec<(usize, i64)>,
) -> Result<u32, LoadError> {
    if index < 0 {
        let back = index.unsigned_abs();
        if back > count as u64 {
            return Err(out_of_range(line, index, count));
        }
        return Ok((count as u64 - back) as u32);
    }
    if index == 0 || index > i64::from(u32::MAX) {
        return Err(out_of_range(line, index, count));
    }
    if index as u64 > count as u64 {
        forward.push((line, index));
    }
    Ok((index - 1) as u32)
}

fn out_of_range(line: usize, index: i64, count: usize) -> LoadError {
    LoadError::IndexOutOfRange {
        format: FORMAT,
        location: Location::Line(line),
        index,
        count,
    }
}

fn syntax(line: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format: FORMAT,
        location: Location::Line(line),
        detail,
    }
}
