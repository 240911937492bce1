//! Wavefront OBJ: reader and writer.
//!
//! Read: `v x y z` (a `w` or an RGB colour after the coordinates is ignored), `vt u v`,
//! `f` with corners `i`, `i/j`, `i//k`, `i/j/k` and negative (relative) indices, polygons of
//! any size (fan-triangulated later by the builder), `\` line continuation. Ignored: `vn`,
//! `vp`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, free-form geometry statements, comments.
//! Texture coordinates are kept as per-vertex UVs only when every referenced vertex carries
//! one consistent `vt` (same index or same value at every corner); otherwise they are dropped
//! with a note (a texture seam needs per-corner UVs, which a [`Surface`] does not have); the
//! per-corner coordinates stay available in [`PolygonSoup::corner_uvs`].

use super::error::{ReadResult, Record};
use super::text::{self, at_line, parse_f64, parse_i64, show, strip_comment, tokens};
use crate::error::{Error, Result};
use crate::mesh::{PolygonSoup, Surface, NONE};
use std::io::Write;

/// Keywords that carry nothing a triangle surface needs.
const IGNORED: &[&[u8]] = &[
    b"vn",
    b"vp",
    b"o",
    b"g",
    b"s",
    b"usemtl",
    b"mtllib",
    b"l",
    b"p",
    b"cstype",
    b"deg",
    b"bmat",
    b"step",
    b"curv",
    b"curv2",
    b"surf",
    b"parm",
    b"trim",
    b"hole",
    b"scrv",
    b"sp",
    b"end",
    b"con",
    b"mg",
    b"bevel",
    b"c_interp",
    b"d_interp",
    b"lod",
    b"shadow_obj",
    b"trace_obj",
    b"ctech",
    b"stech",
    b"maplib",
    b"usemap",
];

/// Parse an OBJ file held in memory.
pub fn parse_obj(data: &[u8]) -> ReadResult<PolygonSoup> {
    let mut records = ObjRecords::default();
    let mut lines = text::Lines::new(data);
    let mut joined: Vec<u8> = Vec::new();
    while let Some((n, raw)) = lines.next() {
        let mut line = strip_comment(raw);
        if line.trim_ascii_end().ends_with(b"\\") {
            join_continued(line, &mut lines, &mut joined);
            line = &joined;
        }
        let mut t = tokens(line);
        let Some(key) = t.next() else { continue };
        records.anything = true;
        match key {
            b"v" => records.vertex(n, t)?,
            b"vt" => records.texture_coordinate(n, t)?,
            b"f" | b"fo" => records.face(n, t)?,
            k if IGNORED.contains(&k) => {}
            k => records.unknown(n, k),
        }
    }
    records.finish()
}

/// A line ending in `\` continues on the next one: `first` and its continuations, joined by
/// spaces, into `joined` (the continuation lines are consumed from `lines`).
fn join_continued(first: &[u8], lines: &mut text::Lines<'_>, joined: &mut Vec<u8>) {
    joined.clear();
    let mut cur = first;
    loop {
        let t = cur.trim_ascii_end();
        if let Some(body) = t.strip_suffix(b"\\") {
            joined.extend_from_slice(body);
            joined.push(b' ');
            match lines.next() {
                Some((_, l)) => cur = strip_comment(l),
                None => break,
            }
        } else {
            joined.extend_from_slice(cur);
            break;
        }
    }
}

/// The records of an OBJ file read so far, one method per statement kind.
#[derive(Default)]
struct ObjRecords {
    positions: Vec<[f64; 3]>,
    vertex_lines: Vec<usize>,
    texcoords: Vec<[f64; 2]>,
    polygons: Vec<Vec<u32>>,
    polygon_lines: Vec<usize>,
    /// vt index of every corner (NONE where the corner has none), flat in polygon order.
    corner_vt: Vec<u32>,
    any_vt_corner: bool,
    /// The first statement this reader does not know (line, keyword), and how many there are.
    unknown: Option<(usize, String)>,
    unknown_count: usize,
    /// Whether any line holds a statement.
    anything: bool,
}

impl ObjRecords {
    /// `v x y z` at line `n` (anything after z is ignored).
    fn vertex<'a>(&mut self, n: usize, mut t: impl Iterator<Item = &'a [u8]>) -> ReadResult<()> {
        let i = self.positions.len();
        let mut p = [0.0f64; 3];
        for (k, x) in p.iter_mut().enumerate() {
            let tok = t.next().ok_or_else(|| {
                at_line(
                    n,
                    format!(
                        "vertex {} has {k} coordinates; three are needed (v x y z)",
                        i + 1
                    ),
                )
                .about(Record::Vertex(i))
            })?;
            *x = parse_f64(tok).ok_or_else(|| {
                at_line(
                    n,
                    format!("vertex {}: '{}' is not a number", i + 1, show(tok)),
                )
                .about(Record::Vertex(i))
            })?;
        }
        self.positions.push(p);
        self.vertex_lines.push(n);
        Ok(())
    }

    /// `vt u [v]` at line `n` (v = 0 when absent, the OBJ default).
    fn texture_coordinate<'a>(
        &mut self,
        n: usize,
        mut t: impl Iterator<Item = &'a [u8]>,
    ) -> ReadResult<()> {
        let i = self.texcoords.len();
        let mut uv = [0.0f64; 2];
        for (k, x) in uv.iter_mut().enumerate() {
            match t.next() {
                Some(tok) => {
                    *x = parse_f64(tok).ok_or_else(|| {
                        at_line(
                            n,
                            format!(
                                "texture coordinate {}: '{}' is not a number",
                                i + 1,
                                show(tok)
                            ),
                        )
                        .about(Record::TextureCoordinate(i))
                    })?
                }
                None if k == 1 => {} // `vt u` alone: v = 0 (OBJ default)
                None => {
                    return Err(at_line(n, format!("texture coordinate {} is empty", i + 1))
                        .about(Record::TextureCoordinate(i)))
                }
            }
        }
        self.texcoords.push(uv);
        Ok(())
    }

    /// `f` (or `fo`) at line `n` with corners `i`, `i/j`, `i//k`, `i/j/k`.
    fn face<'a>(&mut self, n: usize, t: impl Iterator<Item = &'a [u8]>) -> ReadResult<()> {
        let face = self.polygons.len();
        let mut poly = Vec::with_capacity(4);
        for corner in t {
            let mut parts = corner.split(|&b| b == b'/');
            let vi = parts.next().unwrap_or_default();
            let ti = parts.next().unwrap_or_default();
            poly.push(resolve(vi, self.positions.len(), n, "vertex", face)?);
            if ti.is_empty() {
                self.corner_vt.push(NONE);
            } else {
                let vt = resolve(ti, self.texcoords.len(), n, "texture coordinate", face)?;
                self.corner_vt.push(vt);
                self.any_vt_corner = true;
            }
        }
        self.polygons.push(poly);
        self.polygon_lines.push(n);
        Ok(())
    }

    /// A statement this reader does not know, at line `n`: counted, reported in a note.
    fn unknown(&mut self, n: usize, keyword: &[u8]) {
        self.unknown_count += 1;
        if self.unknown.is_none() {
            self.unknown = Some((n, show(keyword)));
        }
    }

    /// The polygon soup, after the checks that need the whole file (forward indices).
    fn finish(self) -> ReadResult<PolygonSoup> {
        if !self.anything {
            return Err(text::empty_file());
        }
        if self.positions.is_empty() && self.polygons.is_empty() {
            return Err(match self.unknown {
                Some((n, k)) => at_line(
                    n,
                    format!("'{k}' is not an OBJ statement, and the file has no 'v' or 'f' lines: is it an OBJ file?"),
                ),
                None => text::whole("the file has no vertices ('v' lines) and no faces ('f' lines)"),
            });
        }
        self.check_indices()?;
        let nv = self.positions.len();
        let mut notes = Vec::new();
        if self.unknown_count > 0 {
            let (n, k) = self.unknown.clone().unwrap_or_default();
            notes.push(format!(
                "{} lines with statements this reader does not know were ignored (first: '{k}' at line {n})",
                self.unknown_count
            ));
        }
        let corner_vt = &self.corner_vt;
        let uvs = if self.any_vt_corner {
            match per_vertex_uvs(
                &self.polygons,
                &self.polygon_lines,
                corner_vt,
                &self.texcoords,
                nv,
            ) {
                Ok(uvs) => Some(uvs),
                Err(why) => {
                    notes.push(format!("texture coordinates were ignored: {why}"));
                    None
                }
            }
        } else {
            None
        };
        let corner_uvs =
            (self.any_vt_corner && corner_vt.iter().all(|&vt| vt != NONE)).then(|| {
                corner_vt
                    .iter()
                    .map(|&vt| self.texcoords[vt as usize])
                    .collect()
            });
        Ok(PolygonSoup {
            positions: self.positions,
            polygons: self.polygons,
            vertex_lines: Some(self.vertex_lines),
            polygon_lines: Some(self.polygon_lines),
            uvs,
            corner_uvs,
            notes,
        })
    }

    /// Positive indices may refer forward; check them once every vertex and `vt` is known.
    fn check_indices(&self) -> ReadResult<()> {
        let nv = self.positions.len();
        for (i, poly) in self.polygons.iter().enumerate() {
            if let Some(&v) = poly.iter().find(|&&v| v as usize >= nv) {
                return Err(at_line(
                    self.polygon_lines[i],
                    format!(
                        "face {i} refers to vertex {} (1-based OBJ index), but the file has only {nv} vertices",
                        v as u64 + 1
                    ),
                )
                .about(Record::Face(i)));
            }
        }
        if let Some((j, &vt)) = self
            .corner_vt
            .iter()
            .enumerate()
            .find(|(_, &vt)| vt != NONE && vt as usize >= self.texcoords.len())
        {
            let face = polygon_of_corner(&self.polygons, j);
            return Err(at_line(
                self.polygon_lines[face],
                format!(
                    "face {face} refers to texture coordinate {} (1-based), but the file has only {} of them",
                    vt as u64 + 1,
                    self.texcoords.len()
                ),
            )
            .about(Record::Face(face)));
        }
        Ok(())
    }
}

/// An OBJ index (1-based, or negative = relative to the `count` elements defined so far) as a
/// 0-based index. Positive indices are checked against the final count later.
fn resolve(tok: &[u8], count: usize, line: usize, what: &str, face: usize) -> ReadResult<u32> {
    let at = |message: String| at_line(line, message).about(Record::Face(face));
    match parse_i64(tok) {
        Some(0) => Err(at(
            format!("face {face} uses {what} index 0; OBJ indices start at 1 (or are negative)"),
        )),
        Some(i) if i > 0 && i < u32::MAX as i64 => Ok((i - 1) as u32),
        Some(i) if i < 0 && -i <= count as i64 => Ok((count as i64 + i) as u32),
        Some(i) if i < 0 => Err(at(
            format!(
                "face {face} uses relative {what} index {i}, but only {count} were defined before this line"
            ),
        )),
        Some(i) => Err(at(
            format!("face {face} refers to {what} {i}, beyond what 32-bit indices allow"),
        )),
        None => Err(at(
            format!("face {face}: '{}' is not a {what} index", show(tok)),
        )),
    }
}

fn polygon_of_corner(polygons: &[Vec<u32>], corner: usize) -> usize {
    let mut acc = 0;
    for (i, p) in polygons.iter().enumerate() {
        acc += p.len();
        if corner < acc {
            return i;
        }
    }
    polygons.len().saturating_sub(1)
}

/// One UV per vertex, or the reason why the file's texture coordinates are not per-vertex.
fn per_vertex_uvs(
    polygons: &[Vec<u32>],
    polygon_lines: &[usize],
    corner_vt: &[u32],
    texcoords: &[[f64; 2]],
    nv: usize,
) -> std::result::Result<Vec<[f64; 2]>, String> {
    let mut vt_of = vec![NONE; nv];
    let mut c = 0;
    for (i, poly) in polygons.iter().enumerate() {
        for &v in poly {
            let vt = corner_vt[c];
            c += 1;
            if vt == NONE {
                return Err(format!(
                    "face {i} (line {}) has a corner without one",
                    polygon_lines[i]
                ));
            }
            let have = &mut vt_of[v as usize];
            if *have == NONE {
                *have = vt;
            } else if *have != vt && texcoords[*have as usize] != texcoords[vt as usize] {
                return Err(format!(
                    "vertex {} has two different ones (a texture seam, first seen at face {i}, line {}); \
                     per-vertex UVs need exactly one",
                    v as u64 + 1,
                    polygon_lines[i]
                ));
            }
        }
    }
    Ok(vt_of
        .iter()
        .map(|&vt| {
            if vt == NONE {
                [0.0, 0.0] // unreferenced vertex: dropped by the builder
            } else {
                texcoords[vt as usize]
            }
        })
        .collect())
}

/// Write a surface as OBJ: `v` lines, `vt` lines and `f a/a b/b c/c` when the surface has
/// UVs, `f a b c` otherwise. Numbers use the shortest representation that reads back exactly.
pub fn write_obj<W: Write>(w: W, s: &Surface) -> Result<()> {
    super::check_finite(s)?;
    let mut w = std::io::BufWriter::new(w);
    let io = |e| Error::io("OBJ output", e);
    writeln!(
        w,
        "# {} vertices, {} faces (written by ricci)",
        s.positions.len(),
        s.mesh.n_faces()
    )
    .map_err(io)?;
    for p in &s.positions {
        writeln!(w, "v {:?} {:?} {:?}", p[0], p[1], p[2]).map_err(io)?;
    }
    let uvs = s.uvs.as_ref().filter(|u| u.len() == s.positions.len());
    if let Some(uvs) = uvs {
        for uv in uvs {
            writeln!(w, "vt {:?} {:?}", uv[0], uv[1]).map_err(io)?;
        }
        for t in s.mesh.faces() {
            let [a, b, c] = t.map(|v| v as u64 + 1);
            writeln!(w, "f {a}/{a} {b}/{b} {c}/{c}").map_err(io)?;
        }
    } else {
        for t in s.mesh.faces() {
            let [a, b, c] = t.map(|v| v as u64 + 1);
            writeln!(w, "f {a} {b} {c}").map_err(io)?;
        }
    }
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corner_forms_relative_indices_and_uvs() {
        let d = b"v 0 0 0\nv 1 0 0 1\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvt 1 0\nvt 0 1\n\
                  f 1/1 2/2 3/3\nf -3/-3 -1/-1 -2/-2\n";
        let s = parse_obj(d).unwrap();
        assert_eq!(s.polygons, vec![vec![0, 1, 2], vec![0, 2, 1]]);
        assert_eq!(s.uvs, Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]));
        let d = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";
        let s = parse_obj(d).unwrap();
        assert_eq!(s.polygons, vec![vec![0, 1, 2]]);
        assert_eq!(s.uvs, None);
    }

    #[test]
    fn seams_drop_uvs_with_a_note() {
        let d = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 9 9\n\
                  f 1/1 2/2 3/3\nf 2/4 4/2 3/3\n";
        let s = parse_obj(d).unwrap();
        assert_eq!(s.uvs, None);
        assert!(s.notes[0].contains("vertex 2"), "{:?}", s.notes);
        // The seam is kept per corner: vertex 2 has (1, 0) in the first face, (9, 9) in the second.
        let c = s.corner_uvs.expect("every corner has a vt");
        assert_eq!(c.len(), 6);
        assert_eq!((c[1], c[3]), ([1.0, 0.0], [9.0, 9.0]));
        // A corner without vt: no per-corner UVs either.
        let d = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2 3\n";
        assert_eq!(parse_obj(d).unwrap().corner_uvs, None);
    }

    #[test]
    fn continuation_lines() {
        let d = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n 3\n";
        let s = parse_obj(d).unwrap();
        assert_eq!(s.polygons, vec![vec![0, 1, 2]]);
        assert_eq!(s.polygon_lines, Some(vec![4]));
    }
}
