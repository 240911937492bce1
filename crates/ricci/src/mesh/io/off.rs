//! Object File Format (Geomview OFF): reader and writer.
//!
//! Accepted: the headers `OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF` (and the other `ST`/`C`/`N`
//! combinations; the extra per-vertex numbers are ignored), counts `V F E` (or just `V F`) on
//! the header line or the next line, `#` comments anywhere, blank lines, CRLF, one vertex and
//! one face per line, faces with any number of corners and trailing per-face colours. Refused
//! with a message naming the line: binary OFF, 4D/nD OFF, a malformed counts line, missing
//! coordinates or indices, negative indices, a file that ends before the declared counts.

use super::error::{ReadResult, Record};
use super::text::{self, at_line, is_blank, parse_f64, parse_i64, show, strip_comment, tokens};
use crate::error::{Error, Result};
use crate::mesh::{PolygonSoup, Surface};
use std::io::Write;

/// Parse an OFF file held in memory.
pub fn parse_off(data: &[u8]) -> ReadResult<PolygonSoup> {
    let mut lines = text::Lines::new(data)
        .map(|(n, l)| (n, strip_comment(l)))
        .filter(|(_, l)| !is_blank(l));
    let Some((hline, header)) = lines.next() else {
        return Err(text::empty_file());
    };
    let mut htoks = tokens(header);
    let keyword = htoks.next().unwrap_or_default();
    check_keyword(hline, keyword)?;
    let rest: Vec<&[u8]> = htoks.collect();
    if rest
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
    {
        return Err(at_line(
            hline,
            "binary OFF is not supported; convert the file to ascii OFF, PLY or OBJ",
        )
        .about(Record::Header));
    }
    // The counts line: on the header line, or the next meaningful line.
    let (cline, counts): (usize, Vec<&[u8]>) = if rest.is_empty() {
        match lines.next() {
            Some((n, l)) => (n, tokens(l).collect()),
            None => return Err(at_line(
                hline,
                "the file ends after the OFF header, before the counts line 'vertices faces edges'",
            )
            .about(Record::Header)),
        }
    } else {
        (hline, rest)
    };
    let parsed: Vec<Option<i64>> = counts.iter().map(|t| parse_i64(t)).collect();
    if !(2..=3).contains(&counts.len()) || parsed.iter().any(|c| !matches!(c, Some(x) if *x >= 0)) {
        let found: Vec<String> = counts.iter().map(|t| show(t)).collect();
        return Err(at_line(
            cline,
            format!(
                "wrong counts line: expected 'vertices faces edges' (two or three non-negative integers), found '{}'",
                found.join(" ")
            ),
        )
        .about(Record::Header));
    }
    let nv = parsed[0].unwrap_or(0) as usize;
    let nf = parsed[1].unwrap_or(0) as usize;
    if nv > u32::MAX as usize / 2 || nf > u32::MAX as usize / 2 {
        return Err(at_line(
            cline,
            format!("the counts line declares {nv} vertices and {nf} faces, more than 32-bit indices allow"),
        ).about(Record::Header));
    }

    let mut soup = PolygonSoup {
        positions: Vec::with_capacity(text::capacity(nv, data.len(), 6)),
        polygons: Vec::with_capacity(text::capacity(nf, data.len(), 8)),
        vertex_lines: Some(Vec::with_capacity(text::capacity(nv, data.len(), 6))),
        polygon_lines: Some(Vec::with_capacity(text::capacity(nf, data.len(), 8))),
        ..Default::default()
    };
    let vlines = soup.vertex_lines.as_mut().expect("set above");
    for i in 0..nv {
        let Some((n, l)) = lines.next() else {
            return Err(at_line(
                cline,
                format!(
                    "the counts line declares {nv} vertices but the file ends after {i} of them"
                ),
            )
            .about(Record::Vertex(i)));
        };
        let mut p = [0.0f64; 3];
        let mut t = tokens(l);
        for (k, x) in p.iter_mut().enumerate() {
            let Some(tok) = t.next() else {
                return Err(at_line(
                    n,
                    format!("vertex {i} has {k} coordinates; three are needed (x y z)"),
                )
                .about(Record::Vertex(i)));
            };
            *x = parse_f64(tok).ok_or_else(|| {
                at_line(n, format!("vertex {i}: '{}' is not a number", show(tok)))
                    .about(Record::Vertex(i))
            })?;
        }
        soup.positions.push(p);
        vlines.push(n);
    }
    let plines = soup.polygon_lines.as_mut().expect("set above");
    for i in 0..nf {
        let Some((n, l)) = lines.next() else {
            return Err(at_line(
                cline,
                format!("the counts line declares {nf} faces but the file ends after {i} of them"),
            )
            .about(Record::Face(i)));
        };
        let poly = off_face(n, l, i, nv)?;
        // Anything after the indices is a per-face colour: ignored.
        soup.polygons.push(poly);
        plines.push(n);
    }
    Ok(soup)
}

/// Face `i` at line `n` of a file with `nv` vertices: `k v₀ … v_{k−1}`, anything after the
/// indices (a per-face colour) ignored.
fn off_face(n: usize, l: &[u8], i: usize, nv: usize) -> ReadResult<Vec<u32>> {
    let mut t = tokens(l);
    let first = t.next().unwrap_or_default();
    let at = |message: String| at_line(n, message).about(Record::Face(i));
    let k = match parse_i64(first) {
        Some(k) if k >= 0 => k as usize,
        _ => {
            return Err(at(format!(
                "face {i} must start with its number of corners, found '{}'",
                show(first)
            )))
        }
    };
    let mut poly = Vec::with_capacity(k.min(16));
    for j in 0..k {
        let Some(tok) = t.next() else {
            return Err(at(format!(
                "face {i} declares {k} corners but lists only {j} vertex indices"
            )));
        };
        match parse_i64(tok) {
            Some(v) if (0..=u32::MAX as i64 - 1).contains(&v) => poly.push(v as u32),
            Some(v) if v < 0 => {
                return Err(at(format!(
                    "face {i} refers to vertex {v}; vertex indices cannot be negative"
                )))
            }
            Some(v) => {
                return Err(at(format!(
                    "face {i} refers to vertex {v}, but the file has only {nv} vertices"
                )))
            }
            None => {
                return Err(at(format!(
                    "face {i}: '{}' is not a vertex index",
                    show(tok)
                )))
            }
        }
    }
    Ok(poly)
}

/// The header keyword: `[ST][C][N]OFF` in any order of the prefixes.
fn check_keyword(line: usize, keyword: &[u8]) -> ReadResult<()> {
    let upper = keyword.to_ascii_uppercase();
    if let Some(prefix) = upper.strip_suffix(b"OFF") {
        // Geomview's `4OFF` / `nOFF` (lower-case n) describe points in other dimensions.
        if prefix.contains(&b'4') || keyword.ends_with(b"nOFF") {
            return Err(at_line(
                line,
                format!(
                    "'{}' (4D or n-dimensional OFF) is not supported; only surfaces in 3D are",
                    show(keyword)
                ),
            )
            .about(Record::Header));
        }
        let mut p = prefix;
        if let Some(r) = p.strip_prefix(b"ST") {
            p = r;
        }
        if p.iter().all(|c| matches!(c, b'C' | b'N')) && p.len() <= 2 {
            return Ok(());
        }
    }
    Err(at_line(
        line,
        format!(
            "expected the OFF header ('OFF', 'COFF', 'NOFF', …), found '{}'",
            show(keyword)
        ),
    )
    .about(Record::Header))
}

/// Write a surface as ascii OFF. Coordinates use the shortest representation that reads back
/// to the same `f64`.
pub fn write_off<W: Write>(w: W, s: &Surface) -> Result<()> {
    super::check_finite(s)?;
    let mut w = std::io::BufWriter::new(w);
    let io = |e| Error::io("OFF output", e);
    writeln!(w, "OFF").map_err(io)?;
    writeln!(
        w,
        "{} {} {}",
        s.positions.len(),
        s.mesh.n_faces(),
        s.mesh.n_edges()
    )
    .map_err(io)?;
    for p in &s.positions {
        writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2]).map_err(io)?;
    }
    for t in s.mesh.faces() {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2]).map_err(io)?;
    }
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_variants_and_counts_on_the_header_line() {
        let s = parse_off(b"# c\r\nCOFF 3 1 0\r\n\r\n0 0 0 1 1 1 1\r\n1 0 0 1 1 1 1\r\n0 1 0 1 1 1 1\r\n3 0 1 2 255 0 0\r\n").unwrap();
        assert_eq!(s.positions.len(), 3);
        assert_eq!(s.polygons, vec![vec![0, 1, 2]]);
        assert_eq!(s.vertex_lines, Some(vec![4, 5, 6]));
        assert_eq!(s.polygon_lines, Some(vec![7]));
        for k in ["OFF", "NOFF", "CNOFF", "STOFF", "STCNOFF"] {
            let d = format!("{k}\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
            assert!(parse_off(d.as_bytes()).is_ok(), "{k}");
        }
        for k in ["4OFF", "nOFF", "OF", "PLY"] {
            let d = format!("{k}\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
            assert!(parse_off(d.as_bytes()).is_err(), "{k}");
        }
    }
}
