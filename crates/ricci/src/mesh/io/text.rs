//! Small helpers shared by the text readers: lines with their 1-based numbers, whitespace
//! tokens, numbers parsed from bytes, and constructors of [`ReadError`] that carry the line or
//! byte offset.

use super::error::ReadError;
use crate::error::Location;

/// Lines of a byte buffer with their 1-based numbers; `\n`, `\r\n` and lone `\r` all end a
/// line (old Mac files), the terminator is not part of the line.
pub(crate) struct Lines<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        // A UTF-8 byte-order mark is not part of the first line.
        let data = data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(data);
        Lines {
            data,
            pos: 0,
            line: 0,
        }
    }
    /// The bytes not consumed yet.
    pub(crate) fn rest(&self) -> &'a [u8] {
        &self.data[self.pos..]
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a [u8]);
    #[inline]
    fn next(&mut self) -> Option<(usize, &'a [u8])> {
        if self.pos >= self.data.len() {
            return None;
        }
        let rest = &self.data[self.pos..];
        let end = rest
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .unwrap_or(rest.len());
        let mut next = end;
        if next < rest.len() {
            next += if rest[next] == b'\r' && rest.get(next + 1) == Some(&b'\n') {
                2
            } else {
                1
            };
        }
        self.pos += next;
        self.line += 1;
        Some((self.line, &rest[..end]))
    }
}

/// The part of a line before a `#` comment.
#[inline]
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(p) => &line[..p],
        None => line,
    }
}

/// Whitespace-separated tokens of a line.
#[inline]
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

/// True when the line holds nothing but whitespace.
#[inline]
pub(crate) fn is_blank(line: &[u8]) -> bool {
    line.iter().all(|b| b.is_ascii_whitespace())
}

/// A floating-point number (Rust's grammar: `1`, `-2.5e-3`, `inf`, `nan`, …).
#[inline]
pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// A signed decimal integer with an optional sign; `None` on anything else or overflow.
#[inline]
pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    let (neg, digits) = match tok.first()? {
        b'-' => (true, &tok[1..]),
        b'+' => (false, &tok[1..]),
        _ => (false, tok),
    };
    if digits.is_empty() {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add((d - b'0') as i64)?;
    }
    Some(if neg { -v } else { v })
}

/// A token shown in a message: lossy UTF-8, shortened to 40 characters.
pub(crate) fn show(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    let s = s.trim();
    if s.chars().count() > 40 {
        let mut t: String = s.chars().take(40).collect();
        t.push('…');
        t
    } else {
        s.to_string()
    }
}

/// A read error at a 1-based line, about the file as a whole until [`ReadError::about`]
/// names the record.
pub(crate) fn at_line(line: usize, message: impl Into<String>) -> ReadError {
    ReadError {
        location: Location::default().with_line(line),
        ..ReadError::whole(message)
    }
}

/// A read error at a byte offset (binary formats).
pub(crate) fn at_byte(byte: usize, message: impl Into<String>) -> ReadError {
    ReadError {
        location: Location::default().with_byte(byte as u64),
        ..ReadError::whole(message)
    }
}

/// A read error about the file as a whole.
pub(crate) fn whole(message: impl Into<String>) -> ReadError {
    ReadError::whole(message)
}

/// The error for a file with no content.
pub(crate) fn empty_file() -> ReadError {
    whole("the file is empty")
}

/// A capacity for a vector whose length a header claims, bounded by what the data could hold
/// (so a huge count in a tiny file does not allocate gigabytes before failing).
#[inline]
pub(crate) fn capacity(claimed: usize, data_len: usize, min_bytes_per_item: usize) -> usize {
    claimed.min(data_len / min_bytes_per_item.max(1) + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_handle_every_terminator_and_bom() {
        let data = b"\xEF\xBB\xBFa\r\nb\nc\rd";
        let v: Vec<(usize, &[u8])> = Lines::new(data).collect();
        assert_eq!(
            v,
            vec![
                (1, &b"a"[..]),
                (2, &b"b"[..]),
                (3, &b"c"[..]),
                (4, &b"d"[..])
            ]
        );
    }

    #[test]
    fn integers_reject_junk_and_overflow() {
        assert_eq!(parse_i64(b"-12"), Some(-12));
        assert_eq!(parse_i64(b"+7"), Some(7));
        assert_eq!(parse_i64(b"1.0"), None);
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b"99999999999999999999"), None);
    }
}
