//! STL (stereolithography): reader (ascii and binary) and writer (ascii and binary).
//!
//! STL stores every triangle with its own three corner positions; the reader welds corners
//! with exactly the same position (−0 and +0 are the same) into one vertex. A binary file
//! may begin with the word "solid" too, so the flavour is decided by the size formula
//! `84 + 50·n` (n = the triangle count in the header) first, then by the leading "solid".
//! Binary STL stores `f32`, so a binary round trip is exact only for `f32` coordinates; the
//! ascii writer uses the shortest round-trip `f64` formatting.

use super::error::{ReadResult, Record};
use super::text::{self, at_byte, at_line, parse_f64, show, strip_comment, tokens};
use crate::error::{Error, Result};
use crate::mesh::{PolygonSoup, Surface};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::io::Write;

/// A fast hasher for bit patterns of coordinates: multiply–rotate while writing, then the
/// MurmurHash3 finaliser so that entropy in the high bits (exponents, leading mantissa
/// bits of "round" numbers) reaches the low bits the table indexes with.
#[derive(Default)]
struct BitsHasher(u64);

impl Hasher for BitsHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

/// Welds corners by exact position.
struct Welder {
    index: HashMap<[u64; 3], u32, BuildHasherDefault<BitsHasher>>,
    positions: Vec<[f64; 3]>,
    lines: Vec<usize>,
}

impl Welder {
    fn new(capacity: usize) -> Self {
        Welder {
            index: HashMap::with_capacity_and_hasher(capacity, Default::default()),
            positions: Vec::with_capacity(capacity),
            lines: Vec::new(),
        }
    }
    fn vertex(&mut self, p: [f64; 3], line: Option<usize>) -> u32 {
        // Adding +0.0 turns −0.0 into +0.0 and leaves every other value unchanged.
        let key = p.map(|x| (x + 0.0).to_bits());
        let next = self.positions.len() as u32;
        let id = *self.index.entry(key).or_insert(next);
        if id == next {
            self.positions.push(p);
            if let Some(l) = line {
                self.lines.push(l);
            }
        }
        id
    }
}

/// Parse an STL file (ascii or binary) held in memory.
pub fn parse_stl(data: &[u8]) -> ReadResult<PolygonSoup> {
    if data.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(text::empty_file());
    }
    let declared = (data.len() >= 84)
        .then(|| u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64);
    if let Some(n) = declared {
        if 84 + 50 * n == data.len() as u64 {
            return parse_binary(data, n as usize);
        }
    }
    let starts_solid = data
        .trim_ascii_start()
        .get(..5)
        .is_some_and(|s| s.eq_ignore_ascii_case(b"solid"));
    // An ascii STL never holds a NUL byte; a binary one (normals, attribute words) always
    // does in practice, even when its header starts with "solid".
    if starts_solid && !data.contains(&0) {
        return parse_ascii(data);
    }
    match declared {
        Some(n) => {
            let expected = 84 + 50 * n;
            let have = data.len() as u64;
            if have < expected {
                let k = (have - 84) / 50;
                Err(at_byte(
                    (84 + 50 * k) as usize,
                    format!(
                        "truncated binary STL: the header declares {n} triangles (84 + 50·{n} = {expected} bytes) but the file has {have} bytes; triangle {k} is the first incomplete one"
                    ),
                )
                .about(Record::Face(k as usize)))
            } else {
                Err(at_byte(
                    expected as usize,
                    format!(
                        "binary STL: the header declares {n} triangles (84 + 50·{n} = {expected} bytes) but the file has {have} bytes; {} unexpected bytes follow the last triangle",
                        have - expected
                    ),
                ))
            }
        }
        None => Err(text::whole(
            "not an STL file: it does not start with 'solid' (ascii) and is shorter than the 84-byte header of a binary STL",
        )),
    }
}

fn parse_binary(data: &[u8], n: usize) -> ReadResult<PolygonSoup> {
    let mut w = Welder::new(n / 2 + 3);
    let mut polygons = Vec::with_capacity(n);
    let f = |b: &[u8], o: usize| f32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]) as f64;
    for (k, rec) in data[84..].chunks_exact(50).enumerate() {
        let mut tri = Vec::with_capacity(3);
        for c in 0..3 {
            let o = 12 + 12 * c;
            let p = [f(rec, o), f(rec, o + 4), f(rec, o + 8)];
            if p.iter().any(|x| !x.is_finite()) {
                return Err(at_byte(
                    84 + 50 * k + o,
                    format!(
                        "triangle {k} has a non-finite corner coordinate ({}, {}, {})",
                        p[0], p[1], p[2]
                    ),
                )
                .about(Record::Face(k)));
            }
            tri.push(w.vertex(p, None));
        }
        polygons.push(tri);
    }
    Ok(PolygonSoup {
        positions: w.positions,
        polygons,
        ..Default::default()
    })
}

fn parse_ascii(data: &[u8]) -> ReadResult<PolygonSoup> {
    let mut w = Welder::new(1024);
    let mut polygons: Vec<Vec<u32>> = Vec::new();
    let mut polygon_lines = Vec::new();
    // The facet being read: its first line and its corners.
    let mut facet: Option<(usize, Vec<u32>)> = None;
    let mut in_solid = false;
    let mut last_line = 0;
    for (n, raw) in text::Lines::new(data) {
        last_line = n;
        let line = strip_comment(raw);
        let mut t = tokens(line);
        let Some(key) = t.next() else { continue };
        let key = key.to_ascii_lowercase();
        match key.as_slice() {
            b"solid" => {
                if in_solid {
                    return Err(at_line(n, "'solid' inside a solid: the previous 'endsolid' is missing"));
                }
                in_solid = true;
            }
            b"endsolid" => {
                if let Some((l, _)) = facet {
                    return Err(at_line(n, format!("the facet that starts at line {l} has no 'endfacet'")));
                }
                in_solid = false;
            }
            b"facet" => {
                if let Some((l, _)) = facet {
                    return Err(at_line(n, format!("the facet that starts at line {l} has no 'endfacet'")));
                }
                if !in_solid {
                    return Err(at_line(n, "'facet' outside of a 'solid … endsolid' block"));
                }
                facet = Some((n, Vec::with_capacity(3)));
            }
            b"outer" | b"endloop" => {}
            b"vertex" => {
                let Some((_, corners)) = facet.as_mut() else {
                    return Err(at_line(n, "'vertex' outside of a facet"));
                };
                let mut p = [0.0f64; 3];
                for (k, x) in p.iter_mut().enumerate() {
                    let tok = t
                        .next()
                        .ok_or_else(|| at_line(n, format!("a vertex has {k} coordinates; three are needed")))?;
                    *x = parse_f64(tok)
                        .ok_or_else(|| at_line(n, format!("'{}' is not a number", show(tok))))?;
                }
                corners.push(w.vertex(p, Some(n)));
            }
            b"endfacet" => {
                let Some((l, corners)) = facet.take() else {
                    return Err(at_line(n, "'endfacet' without a 'facet'"));
                };
                polygons.push(corners);
                polygon_lines.push(l);
            }
            _ => {
                return Err(at_line(
                    n,
                    format!(
                        "unexpected '{}' in an ascii STL file (expected solid, facet, outer loop, vertex, endloop, endfacet or endsolid)",
                        show(&key)
                    ),
                ))
            }
        }
    }
    if let Some((l, _)) = facet {
        return Err(at_line(
            last_line,
            format!("the file ends inside the facet that starts at line {l}"),
        ));
    }
    Ok(PolygonSoup {
        positions: w.positions,
        polygons,
        vertex_lines: Some(w.lines),
        polygon_lines: Some(polygon_lines),
        ..Default::default()
    })
}

fn unit_normal(s: &Surface, t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|v| s.positions[v as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        n.map(|x| x / l)
    } else {
        [0.0; 3]
    }
}

/// Write a surface as STL, binary (`f32`, the usual choice) or ascii (exact `f64`).
pub fn write_stl<W: Write>(w: W, s: &Surface, binary: bool) -> Result<()> {
    super::check_finite(s)?;
    let mut w = std::io::BufWriter::new(w);
    let io = |e| Error::io("STL output", e);
    if binary {
        let nf = u32::try_from(s.mesh.n_faces())
            .map_err(|_| Error::input("too many faces for a binary STL file"))?;
        // Binary STL stores f32: a larger coordinate would become infinite (found by fuzzing).
        if let Some((v, x)) = s.positions.iter().enumerate().find_map(|(v, p)| {
            p.iter()
                .find(|x| !(**x as f32).is_finite())
                .map(|&x| (v, x))
        }) {
            return Err(Error::input(format!(
                "vertex {v} has the coordinate {x:e}, beyond the 32-bit floats of binary STL; write ascii STL or another format"
            )));
        }
        let mut header = [b' '; 80];
        let title = b"binary STL written by ricci";
        header[..title.len()].copy_from_slice(title);
        w.write_all(&header).map_err(io)?;
        w.write_all(&nf.to_le_bytes()).map_err(io)?;
        for &t in s.mesh.faces() {
            let mut rec = [0u8; 50];
            let n = unit_normal(s, t);
            let corners = t.map(|v| s.positions[v as usize]);
            let vals = std::iter::once(n).chain(corners).flatten();
            for (k, x) in vals.enumerate() {
                rec[4 * k..4 * k + 4].copy_from_slice(&(x as f32).to_le_bytes());
            }
            w.write_all(&rec).map_err(io)?;
        }
    } else {
        writeln!(w, "solid ricci").map_err(io)?;
        for &t in s.mesh.faces() {
            let n = unit_normal(s, t);
            writeln!(w, "  facet normal {:?} {:?} {:?}", n[0], n[1], n[2]).map_err(io)?;
            writeln!(w, "    outer loop").map_err(io)?;
            for v in t {
                let p = s.positions[v as usize];
                writeln!(w, "      vertex {:?} {:?} {:?}", p[0], p[1], p[2]).map_err(io)?;
            }
            writeln!(w, "    endloop").map_err(io)?;
            writeln!(w, "  endfacet").map_err(io)?;
        }
        writeln!(w, "endsolid ricci").map_err(io)?;
    }
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\n facet normal 0 0 1\n  outer loop\n   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 -0\n  endloop\n endfacet\nendsolid t\n";

    #[test]
    fn ascii_welds_exact_positions() {
        let s = parse_stl(ASCII.as_bytes()).unwrap();
        assert_eq!(s.positions.len(), 4);
        assert_eq!(s.polygons, vec![vec![0, 1, 2], vec![1, 3, 2]]);
        assert_eq!(s.polygon_lines, Some(vec![2, 9]));
    }

    #[test]
    fn binary_starting_with_solid_is_read_as_binary() {
        let mut d = b"solid but actually binary".to_vec();
        d.resize(80, 0);
        d.extend(2u32.to_le_bytes());
        for tri in [
            [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]],
            [[1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        ] {
            d.extend([0u8; 12]);
            for p in tri {
                for x in p {
                    d.extend(x.to_le_bytes());
                }
            }
            d.extend([0u8; 2]);
        }
        let s = parse_stl(&d).unwrap();
        assert_eq!(s.positions.len(), 4);
        assert_eq!(s.polygons, vec![vec![0, 1, 2], vec![1, 3, 2]]);
        let e = parse_stl(&d[..d.len() - 7]).unwrap_err().to_string();
        assert!(e.contains("triangle 1") && e.contains("byte 134"), "{e}");
    }
}
