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
pub fn parse_obj(data: &[u8]) -> Result<PolygonSoup> {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut vertex_lines = Vec::new();
    let mut texcoords: Vec<[f64; 2]> = Vec::new();
    let mut polygons: Vec<Vec<u32>> = Vec::new();
    let mut polygon_lines = Vec::new();
    // vt index of every corner (NONE where the corner has none), flat in polygon order.
    let mut corner_vt: Vec<u32> = Vec::new();
    let mut any_vt_corner = false;
    let mut unknown: Option<(usize, String)> = None;
    let mut unknown_count = 0usize;
    let mut anything = false;

    let mut lines = text::Lines::new(data);
    let mut joined: Vec<u8> = Vec::new();
    while let Some((n, raw)) = lines.next() {
        let mut line = strip_comment(raw);
        // `\` at the end of a line continues it on the next one.
        if line.trim_ascii_end().ends_with(b"\\") {
            joined.clear();
            let mut cur = line;
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
            line = &joined;
        }
        let mut t = tokens(line);
        let Some(key) = t.next() else { continue };
        anything = true;
        match key {
            b"v" => {
                let mut p = [0.0f64; 3];
                for (k, x) in p.iter_mut().enumerate() {
                    let tok = t.next().ok_or_else(|| {
                        at_line(
                            n,
                            format!(
                                "vertex {} has {k} coordinates; three are needed (v x y z)",
                                positions.len() + 1
                            ),
                        )
                    })?;
                    *x = parse_f64(tok).ok_or_else(|| {
                        at_line(
                            n,
                            format!(
                                "vertex {}: '{}' is not a number",
                                positions.len() + 1,
                                show(tok)
                            ),
                        )
                    })?;
                }
                positions.push(p);
                vertex_lines.push(n);
            }
            b"vt" => {
                let mut uv = [0.0f64; 2];
                for (k, x) in uv.iter_mut().enumerate() {
                    match t.next() {
                        Some(tok) => {
                            *x = parse_f64(tok).ok_or_else(|| {
                                at_line(
                                    n,
                                    format!(
                                        "texture coordinate {}: '{}' is not a number",
                                        texcoords.len() + 1,
                                        show(tok)
                                    ),
                                )
                            })?
                        }
                        None if k == 1 => {} // `vt u` alone: v = 0 (OBJ default)
                        None => {
                            return Err(at_line(
                                n,
                                format!("texture coordinate {} is empty", texcoords.len() + 1),
                            ))
                        }
                    }
                }
                texcoords.push(uv);
            }
            b"f" | b"fo" => {
                let mut poly = Vec::with_capacity(4);
                for corner in t {
                    let mut parts = corner.split(|&b| b == b'/');
                    let vi = parts.next().unwrap_or_default();
                    let ti = parts.next().unwrap_or_default();
                    let v = resolve(vi, positions.len(), n, "vertex", polygons.len())?;
                    poly.push(v);
                    if ti.is_empty() {
                        corner_vt.push(NONE);
                    } else {
                        let vt =
                            resolve(ti, texcoords.len(), n, "texture coordinate", polygons.len())?;
                        corner_vt.push(vt);
                        any_vt_corner = true;
                    }
                }
                polygons.push(poly);
                polygon_lines.push(n);
            }
            k if IGNORED.contains(&k) => {}
            k => {
                unknown_count += 1;
                if unknown.is_none() {
                    unknown = Some((n, show(k)));
                }
            }
        }
    }
    if !anything {
        return Err(text::empty_file());
    }
    if positions.is_empty() && polygons.is_empty() {
        return Err(match unknown {
            Some((n, k)) => at_line(
                n,
                format!("'{k}' is not an OBJ statement, and the file has no 'v' or 'f' lines: is it an OBJ file?"),
            ),
            None => text::whole("the file has no vertices ('v' lines) and no faces ('f' lines)"),
        });
    }
    // Positive indices may refer forward; check them now that every vertex is known.
    let nv = positions.len();
    for (i, poly) in polygons.iter().enumerate() {
        if let Some(&v) = poly.iter().find(|&&v| v as usize >= nv) {
            return Err(at_line(
                polygon_lines[i],
                format!(
                    "face {i} refers to vertex {} (1-based OBJ index), but the file has only {nv} vertices",
                    v as u64 + 1
                ),
            ));
        }
    }
    if let Some((j, &vt)) = corner_vt
        .iter()
        .enumerate()
        .find(|(_, &vt)| vt != NONE && vt as usize >= texcoords.len())
    {
        let face = polygon_of_corner(&polygons, j);
        return Err(at_line(
            polygon_lines[face],
            format!(
                "face {face} refers to texture coordinate {} (1-based), but the file has only {} of them",
                vt as u64 + 1,
                texcoords.len()
            ),
        ));
    }
    let mut notes = Vec::new();
    if unknown_count > 0 {
        let (n, k) = unknown.unwrap_or_default();
        notes.push(format!(
            "{unknown_count} lines with statements this reader does not know were ignored (first: '{k}' at line {n})"
        ));
    }
    let uvs = if any_vt_corner {
        match per_vertex_uvs(&polygons, &polygon_lines, &corner_vt, &texcoords, nv) {
            Ok(uvs) => Some(uvs),
            Err(why) => {
                notes.push(format!("texture coordinates were ignored: {why}"));
                None
            }
        }
    } else {
        None
    };
    let corner_uvs = (any_vt_corner && corner_vt.iter().all(|&vt| vt != NONE))
        .then(|| corner_vt.iter().map(|&vt| texcoords[vt as usize]).collect());
    Ok(PolygonSoup {
        positions,
        polygons,
        vertex_lines: Some(vertex_lines),
        polygon_lines: Some(polygon_lines),
        uvs,
        corner_uvs,
        notes,
    })
}

/// An OBJ index (1-based, or negative = relative to the `count` elements defined so far) as a
/// 0-based index. Positive indices are checked against the final count later.
fn resolve(tok: &[u8], count: usize, line: usize, what: &str, face: usize) -> Result<u32> {
    match parse_i64(tok) {
        Some(0) => Err(at_line(
            line,
            format!("face {face} uses {what} index 0; OBJ indices start at 1 (or are negative)"),
        )),
        Some(i) if i > 0 && i < u32::MAX as i64 => Ok((i - 1) as u32),
        Some(i) if i < 0 && -i <= count as i64 => Ok((count as i64 + i) as u32),
        Some(i) if i < 0 => Err(at_line(
            line,
            format!(
                "face {face} uses relative {what} index {i}, but only {count} were defined before this line"
            ),
        )),
        Some(i) => Err(at_line(
            line,
            format!("face {face} refers to {what} {i}, beyond what 32-bit indices allow"),
        )),
        None => Err(at_line(
            line,
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
