//! Line and number scanning shared by the text formats (OBJ, ASCII STL, ASCII PLY).
//!
//! Files come from every platform, so `\n`, `\r\n` and a lone `\r` all end a line, and a line
//! number counts each of them once. Bytes need not be UTF-8: only tokens we parse are checked.

/// Lines of a byte buffer with their 1-based numbers, without terminators.
pub(super) struct Lines<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            pos: 0,
            line: 0,
        }
    }

    /// Byte offset just past the last line returned (past its terminator).
    pub(super) fn offset(&self) -> usize {
        self.pos
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a [u8]);

    fn next(&mut self) -> Option<Self::Item> {
        let rest = self.bytes.get(self.pos..)?;
        if rest.is_empty() {
            return None;
        }
        self.line += 1;
        let (content, used) = match rest.iter().position(|&b| b == b'\n' || b == b'\r') {
            Some(end) => {
                let crlf = rest.get(end) == Some(&b'\r') && rest.get(end + 1) == Some(&b'\n');
                (&rest[..end], end + if crlf { 2 } else { 1 })
            }
            None => (rest, rest.len()),
        };
        self.pos += used;
        Some((self.line, content))
    }
}

/// The bytes after a UTF-8 byte-order mark, which some Windows editors put before text.
pub(super) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// Whitespace-separated tokens of one line.
pub(super) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| is_space(*b)).filter(|t| !t.is_empty())
}

/// Token separators: ASCII whitespace including vertical tab.
#[inline]
pub(super) fn is_space(b: u8) -> bool {
    b.is_ascii_whitespace() || b == 0x0b
}

/// A token as text for error messages (lossy, shortened so a garbage line cannot flood a message).
pub(super) fn show(token: &[u8]) -> String {
    const MAX: usize = 40;
    let cut = &token[..token.len().min(MAX)];
    let mut s = String::from_utf8_lossy(cut).into_owned();
    if token.len() > MAX {
        s.push('…');
    }
    s
}

/// Parses a decimal float (as Rust reads it: `1`, `-2.5e3`, `.5`, `nan`, `inf`), correctly rounded
/// to `f32`. Values beyond `f32` range become infinite, which the callers reject as non-finite.
pub(super) fn parse_f32(token: &[u8]) -> Option<f32> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses a decimal float to `f64` (used to validate properties that are skipped).
pub(super) fn parse_f64(token: &[u8]) -> Option<f64> {
    std::str::from_utf8(token).ok()?.parse().ok()
}

/// Parses an optionally signed decimal integer; `None` on any other text or on overflow.
pub(super) fn parse_int(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token.split_first()? {
        (b'-', rest) => (true, rest),
        (b'+', rest) => (false, rest),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        value = value.checked_mul(10)?.checked_add(i64::from(d - b'0'))?;
    }
    Some(if negative { -value } else { value })
}

/// Case-insensitive keyword comparison (some writers shout `SOLID`, `FACET NORMAL`).
#[inline]
pub(super) fn is_keyword(token: &[u8], keyword: &str) -> bool {
    token.eq_ignore_ascii_case(keyword.as_bytes())
}

/// Three finite coordinates from a text line's remaining tokens (OBJ `v`, ASCII STL `vertex`).
/// `record` names the statement in the error when a coordinate is missing.
pub(super) fn read_xyz<'a>(
    tokens: &mut impl Iterator<Item = &'a [u8]>,
    format: super::Format,
    line: usize,
    record: &str,
) -> Result<[f32; 3], super::LoadError> {
    use super::{LoadError, Location};
    let syntax = |detail: String| LoadError::Syntax {
        format,
        location: Location::Line(line),
        detail,
    };
    let mut p = [0f32; 3];
    for c in &mut p {
        let token = tokens
            .next()
            .ok_or_else(|| syntax(format!("'{record}' needs 3 coordinates")))?;
        let value =
            parse_f32(token).ok_or_else(|| syntax(format!("'{}' is not a number", show(token))))?;
        if !value.is_finite() {
            return Err(LoadError::NonFinite {
                format,
                location: Location::Line(line),
                value: show(token),
            });
        }
        *c = value;
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_line_ending_counts_once() {
        let text = b"a\nb\r\nc\rd\r\r\ne";
        let lines: Vec<(usize, &[u8])> = Lines::new(text).collect();
        let expect: Vec<(usize, &[u8])> = vec![
            (1, b"a"),
            (2, b"b"),
            (3, b"c"),
            (4, b"d"),
            (5, b""),
            (6, b"e"),
        ];
        assert_eq!(lines, expect);
    }

    #[test]
    fn offset_is_past_the_terminator() {
        let mut lines = Lines::new(b"ab\r\ncd");
        assert_eq!(lines.next(), Some((1, &b"ab"[..])));
        assert_eq!(lines.offset(), 4);
        assert_eq!(lines.next(), Some((2, &b"cd"[..])));
        assert_eq!(lines.offset(), 6);
        assert_eq!(lines.next(), None);
    }

    #[test]
    fn integers_reject_garbage_and_overflow() {
        assert_eq!(parse_int(b"-12"), Some(-12));
        assert_eq!(parse_int(b"+7"), Some(7));
        assert_eq!(parse_int(b"-"), None);
        assert_eq!(parse_int(b"1.0"), None);
        assert_eq!(parse_int(b"99999999999999999999"), None);
    }

    #[test]
    fn floats_and_tokens() {
        assert_eq!(parse_f32(b"-2.5e1"), Some(-25.0));
        assert!(parse_f32(b"nan").is_some_and(f32::is_nan));
        assert_eq!(parse_f32(b"1e39"), Some(f32::INFINITY));
        assert_eq!(parse_f32(b"x"), None);
        let t: Vec<&[u8]> = tokens(b" v\t1  2\x0b3 ").collect();
        assert_eq!(t, vec![&b"v"[..], b"1", b"2", b"3"]);
        assert_eq!(show(&[b'a'; 50]).chars().count(), 41);
        assert_eq!(strip_bom(b"\xEF\xBB\xBFv 1"), b"v 1");
    }
}
