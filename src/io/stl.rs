//! STL, binary and ASCII. Both are triangle soup, welded by exact position equality.
//!
//! Binary files often start their free-form 80-byte header with "solid" too, so the header alone
//! cannot tell the encodings apart: a file whose length is exactly `84 + 50 * count` is binary.
use super::text::{self, Lines};
use super::weld::Welder;
use super::{Format, LoadError, Location};
use crate::mesh::Mesh;

const HEADER: usize = 84;
const RECORD: usize = 50;
const FORMAT: Format = Format::Stl;

pub(super) fn parse(bytes: &[u8]) -> Result<Mesh, LoadError> {
    if exact_binary_length(bytes) || !looks_like_ascii(bytes) {
        parse_binary(bytes)
    } else {
        parse_ascii(bytes)
    }
}

/// The triangle count in a binary header, if the file is long enough to have one.
fn binary_count(bytes: &[u8]) -> Option<u32> {
    let field = bytes.get(80..HEADER)?;
    Some(u32::from_le_bytes([field[0], field[1], field[2], field[3]]))
}

fn exact_binary_length(bytes: &[u8]) -> bool {
    binary_count(bytes).is_some_and(|n| {
        (n as u64)
            .checked_mul(RECORD as u64)
            .and_then(|d| d.checked_add(HEADER as u64))
            == Some(bytes.len() as u64)
    })
}

/// ASCII STL starts with "solid" and is text; binary data after the header nearly always holds
/// a NUL or control byte (any float with a zero or small byte), which ASCII never does.
fn looks_like_ascii(bytes: &[u8]) -> bool {
    let bytes = text::strip_bom(bytes);
    let start = bytes.iter().position(|&b| !text::is_space(b)).unwrap_or(0);
    let starts_solid = bytes
        .get(start..start + 5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"));
    starts_solid && !bytes.iter().take(4096).any(|&b| is_binary_byte(b))
}

#[inline]
fn is_binary_byte(b: u8) -> bool {
    b < 0x20 && !text::is_space(b)
}

fn parse_binary(bytes: &[u8]) -> Result<Mesh, LoadError> {
    let Some(count) = binary_count(bytes) else {
        if bytes.iter().all(|&b| !is_binary_byte(b)) {
            return Err(bad_magic());
        }
        return Err(LoadError::Truncated {
            format: FORMAT,
            offset: bytes.len(),
            detail: format!(
                "a binary STL header needs {HEADER} bytes, the file has {}",
                bytes.len()
            ),
        });
    };
    // Checked against the length before any allocation: the count is untrusted.
    let possible = ((bytes.len() - HEADER) / RECORD) as u64;
    if u64::from(count) > possible {
        if !bytes.iter().take(4096).any(|&b| is_binary_byte(b)) {
            // Text without "solid" (or with no triangle data at all): not STL.
            return Err(bad_magic());
        }
        return Err(LoadError::CountTooLarge {
            format: FORMAT,
            what: "triangles",
            claimed: u64::from(count),
            possible,
        });
    }
    if count == 0 {
        return Err(LoadError::NoTriangles { format: FORMAT });
    }
    if u64::from(count) * 3 >= u64::from(u32::MAX) {
        return Err(too_many_vertices());
    }
    let count = count as usize;
    let data = &bytes[HEADER..HEADER + count * RECORD];
    let mut welder = Welder::with_expected_triangles(count);
    let mut triangles = Vec::with_capacity(count);
    for (t, record) in data.chunks_exact(RECORD).enumerate() {
        let mut tri = [0u32; 3];
        for (k, corner) in tri.iter_mut().enumerate() {
            let at = 12 + 12 * k;
            let p = [
                f32_le(record, at),
                f32_le(record, at + 4),
                f32_le(record, at + 8),
            ];
            if let Some(c) = p.iter().position(|c| !c.is_finite()) {
                return Err(LoadError::NonFinite {
                    format: FORMAT,
                    location: Location::Byte(HEADER + t * RECORD + at + 4 * c),
                    value: format!("{:?}", p[c]),
                });
            }
            *corner = welder.insert(p);
        }
        triangles.push(tri);
    }
    Ok(Mesh::new(welder.into_positions(), triangles))
}

/// Little-endian f32 at `at` in a 50-byte record (`at + 4 <= 48` by construction).
#[inline]
fn f32_le(record: &[u8], at: usize) -> f32 {
    let mut b = [0u8; 4];
    b.copy_from_slice(&record[at..at + 4]);
    f32::from_le_bytes(b)
}

fn bad_magic() -> LoadError {
    LoadError::BadMagic {
        format: FORMAT,
        detail: "text that does not start with 'solid', and not a binary STL".into(),
    }
}

/// Where the ASCII reader is in the `solid / facet / vertex` nesting.
enum State {
    Outside,
    InSolid,
    /// In a facet begun on `line`, with `corners` vertices read so far.
    InFacet {
        line: usize,
        corners: usize,
    },
}

fn parse_ascii(bytes: &[u8]) -> Result<Mesh, LoadError> {
    // Each facet takes at least ~7 lines of ~15 bytes; a modest guess avoids regrowth.
    let mut solid = AsciiSolid {
        welder: Welder::with_expected_triangles(bytes.len() / 256),
        triangles: Vec::new(),
        corners: [0; 3],
    };
    let mut state = State::Outside;
    for (line, content) in Lines::new(text::strip_bom(bytes)) {
        let mut tokens = text::tokens(content);
        let Some(word) = tokens.next() else { continue };
        state = solid.next(state, word, &mut tokens, line)?;
    }
    let truncated = |detail: String| LoadError::Truncated {
        format: FORMAT,
        offset: bytes.len(),
        detail,
    };
    match state {
        State::Outside => {}
        State::InSolid => return Err(truncated("missing 'endsolid'".into())),
        State::InFacet { line, .. } => {
            return Err(truncated(format!("inside the facet begun on line {line}")))
        }
    }
    if solid.triangles.is_empty() {
        return Err(LoadError::NoTriangles { format: FORMAT });
    }
    Ok(Mesh::new(solid.welder.into_positions(), solid.triangles))
}

fn syntax(line: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format: FORMAT,
        location: Location::Line(line),
        detail,
    }
}

/// An ASCII solid as read so far: its welded vertices, its triangles and the corners of the
/// facet under way.
struct AsciiSolid {
    welder: Welder,
    triangles: Vec<[u32; 3]>,
    corners: [u32; 3],
}

impl AsciiSolid {
    /// The state after a line that begins with `word` (the rest in `tokens`) in `state`.
    fn next<'a>(
        &mut self,
        state: State,
        word: &[u8],
        tokens: &mut impl Iterator<Item = &'a [u8]>,
        line: usize,
    ) -> Result<State, LoadError> {
        Ok(match state {
            State::Outside if text::is_keyword(word, "solid") => State::InSolid,
            State::Outside => {
                return Err(syntax(
                    line,
                    format!("expected 'solid', found '{}'", text::show(word)),
                ))
            }
            State::InSolid if text::is_keyword(word, "endsolid") => State::Outside,
            State::InSolid if text::is_keyword(word, "facet") => {
                State::InFacet { line, corners: 0 }
            }
            State::InSolid => {
                return Err(syntax(
                    line,
                    format!(
                        "expected 'facet' or 'endsolid', found '{}'",
                        text::show(word)
                    ),
                ))
            }
            State::InFacet {
                line: start,
                corners,
            } => self.in_facet(word, tokens, line, start, corners)?,
        })
    }

    /// The state after a line of a facet begun on `start` with `n` corners read.
    fn in_facet<'a>(
        &mut self,
        word: &[u8],
        tokens: &mut impl Iterator<Item = &'a [u8]>,
        line: usize,
        start: usize,
        n: usize,
    ) -> Result<State, LoadError> {
        if text::is_keyword(word, "vertex") {
            let Some(slot) = self.corners.get_mut(n) else {
                return Err(syntax(line, "a facet has more than 3 vertices".into()));
            };
            let p = read_xyz(tokens, line)?;
            if self.welder.len() >= u32::MAX as usize {
                return Err(too_many_vertices());
            }
            *slot = self.welder.insert(p);
            Ok(State::InFacet {
                line: start,
                corners: n + 1,
            })
        } else if text::is_keyword(word, "endfacet") {
            if n != 3 {
                return Err(syntax(
                    line,
                    format!("the facet begun on line {start} has {n} vertices, expected 3"),
                ));
            }
            self.triangles.push(self.corners);
            Ok(State::InSolid)
        } else if text::is_keyword(word, "outer") || text::is_keyword(word, "endloop") {
            // The loop markers carry nothing the vertex count does not already check.
            Ok(State::InFacet {
                line: start,
                corners: n,
            })
        } else {
            Err(syntax(
                line,
                format!("unexpected '{}' inside a facet", text::show(word)),
            ))
        }
    }
}

fn read_xyz<'a>(
    tokens: &mut impl Iterator<Item = &'a [u8]>,
    line: usize,
) -> Result<[f32; 3], LoadError> {
    text::read_xyz(tokens, FORMAT, line, "vertex")
}

fn too_many_vertices() -> LoadError {
    LoadError::Unsupported {
        format: FORMAT,
        detail: "more than 4294967294 distinct vertices".into(),
    }
}
