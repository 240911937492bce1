//! From a polygon soup (what a file holds) to a validated [`Surface`].
//!
//! Checks, in order, each failing with one sentence naming the culprit in the file's own
//! numbering (0-based vertex and face ids, plus the line when the reader recorded it):
//! non-finite coordinates, indices out of range, polygons with fewer than three distinct
//! corners, duplicate faces, non-manifold edges, non-orientable components, non-manifold
//! vertices. Accepted with a note: polygons (fan-triangulated), unreferenced vertices
//! (dropped), inconsistently oriented faces in an orientable component (flipped), zero-area
//! faces (listed).

use super::{Mesh, Surface};
use crate::error::{Error, Result};
use std::collections::HashMap;

/// A face counts as zero-area when its area is at most this times the squared diagonal of
/// the bounding box (sides around 10⁻⁶ of the model's size: below the precision of typical
/// ascii files).
pub const ZERO_AREA_RELATIVE: f64 = 1e-12;

/// What a mesh file holds before validation.
#[derive(Debug, Clone, Default)]
pub struct PolygonSoup {
    pub positions: Vec<[f64; 3]>,
    /// Polygons as 0-based vertex indices (any number of corners).
    pub polygons: Vec<Vec<u32>>,
    /// 1-based source line of each vertex (text formats), if known.
    pub vertex_lines: Option<Vec<usize>>,
    /// 1-based source line of each polygon (text formats), if known.
    pub polygon_lines: Option<Vec<usize>>,
    /// Texture coordinates per vertex, if the file carried them in a per-vertex way.
    pub uvs: Option<Vec<[f64; 2]>>,
    /// What the reader ignored or changed, one sentence each (copied into the report).
    pub notes: Vec<String>,
}

/// What the builder changed or noticed while accepting the input.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct BuildReport {
    /// Number of polygons with more than three corners that were fan-triangulated.
    pub triangulated_polygons: usize,
    /// Input ids of vertices no face refers to; they were dropped.
    pub dropped_vertices: Vec<u32>,
    /// Number of faces whose orientation was flipped to agree with their component.
    pub reoriented_faces: usize,
    /// Ids (in the output mesh) of faces with zero (or numerically zero) area.
    pub zero_area_faces: Vec<u32>,
    /// For every output vertex, its index in the input.
    pub vertex_origin: Vec<u32>,
    /// For every output face, the input polygon it came from.
    pub face_origin: Vec<u32>,
    /// Human-readable notes, one sentence each.
    pub notes: Vec<String>,
}

fn at_line(lines: &Option<Vec<usize>>, i: usize) -> String {
    match lines.as_ref().and_then(|l| l.get(i)) {
        Some(l) => format!(" (line {l})"),
        None => String::new(),
    }
}

/// Validate a polygon soup and build the surface. See the module docs for what is checked.
pub fn build_surface(soup: PolygonSoup) -> Result<(Surface, BuildReport)> {
    let mut report = BuildReport {
        notes: soup.notes.clone(),
        ..Default::default()
    };
    let nv_in = soup.positions.len();
    if soup.polygons.is_empty() {
        return Err(Error::invalid_mesh("the file contains no faces"));
    }
    for (i, p) in soup.positions.iter().enumerate() {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid_mesh(format!(
                "vertex {i}{} has a non-finite coordinate ({}, {}, {})",
                at_line(&soup.vertex_lines, i),
                p[0],
                p[1],
                p[2]
            )));
        }
    }
    // Triangulate, check indices and degenerate polygons.
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(soup.polygons.len());
    let mut tri_src: Vec<u32> = Vec::with_capacity(soup.polygons.len());
    for (pi, poly) in soup.polygons.iter().enumerate() {
        for &v in poly {
            if v as usize >= nv_in {
                return Err(Error::invalid_mesh(format!(
                    "face {pi}{} refers to vertex {v}, but the file has only {nv_in} vertices",
                    at_line(&soup.polygon_lines, pi)
                )));
            }
        }
        let mut distinct = poly.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if poly.len() < 3 || distinct.len() < poly.len() {
            return Err(Error::invalid_mesh(format!(
                "face {pi}{} has {} corners of which {} are distinct; a face needs at least three distinct vertices",
                at_line(&soup.polygon_lines, pi),
                poly.len(),
                distinct.len()
            )));
        }
        if poly.len() > 3 {
            report.triangulated_polygons += 1;
        }
        for k in 1..poly.len() - 1 {
            tris.push([poly[0], poly[k], poly[k + 1]]);
            tri_src.push(pi as u32);
        }
    }
    if report.triangulated_polygons > 0 {
        report.notes.push(format!(
            "{} polygons with more than three corners were fan-triangulated",
            report.triangulated_polygons
        ));
    }
    // Duplicate faces (same vertex set).
    {
        let mut keys: Vec<([u32; 3], u32)> = tris
            .iter()
            .enumerate()
            .map(|(f, t)| {
                let mut k = *t;
                k.sort_unstable();
                (k, f as u32)
            })
            .collect();
        keys.sort_unstable();
        for w in keys.windows(2) {
            if w[0].0 == w[1].0 {
                let (a, b) = (
                    tri_src[w[0].1 as usize] as usize,
                    tri_src[w[1].1 as usize] as usize,
                );
                return Err(Error::invalid_mesh(format!(
                    "faces {a}{} and {b}{} are duplicates (both use vertices {}, {}, {})",
                    at_line(&soup.polygon_lines, a),
                    at_line(&soup.polygon_lines, b),
                    w[0].0[0],
                    w[0].0[1],
                    w[0].0[2]
                )));
            }
        }
    }
    // Undirected edges -> incident triangles.
    let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(tris.len() * 2);
    for (f, t) in tris.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            edge_faces
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(f as u32);
        }
    }
    // Report the non-manifold edge with the smallest vertex ids (deterministic).
    if let Some(((a, b), fs)) = edge_faces
        .iter()
        .filter(|(_, fs)| fs.len() > 2)
        .min_by_key(|(k, _)| **k)
    {
        let list: Vec<String> = fs
            .iter()
            .map(|&f| tri_src[f as usize].to_string())
            .collect();
        return Err(Error::invalid_mesh(format!(
            "non-manifold edge between vertices {a} and {b}: it is shared by {} faces ({})",
            fs.len(),
            list.join(", ")
        )));
    }
    // Orientation: propagate over faces, flipping where needed.
    let nf = tris.len();
    let mut state = vec![0i8; nf]; // 0 unvisited, 1 keep, -1 flip
    let mut stack = Vec::new();
    let dir = |t: &[u32; 3], a: u32, b: u32| -> bool {
        // true if t traverses a->b
        (0..3).any(|i| t[i] == a && t[(i + 1) % 3] == b)
    };
    for seed in 0..nf {
        if state[seed] != 0 {
            continue;
        }
        state[seed] = 1;
        stack.push(seed as u32);
        while let Some(f) = stack.pop() {
            let t = tris[f as usize];
            let sf = state[f as usize];
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                let fs = &edge_faces[&(a.min(b), a.max(b))];
                for &g in fs {
                    if g == f {
                        continue;
                    }
                    // Effective direction of f on this edge: a->b if sf == 1.
                    let g_ab = dir(&tris[g as usize], a, b);
                    // Consistent iff g traverses the edge opposite to f.
                    let need = if g_ab { -sf } else { sf };
                    if state[g as usize] == 0 {
                        state[g as usize] = need;
                        stack.push(g);
                    } else if state[g as usize] != need {
                        return Err(Error::invalid_mesh(format!(
                            "the surface is not orientable: going around it through faces {} and {} \
                             (along the edge between vertices {a} and {b}) reverses the orientation",
                            tri_src[f as usize], tri_src[g as usize]
                        )));
                    }
                }
            }
        }
    }
    for (f, t) in tris.iter_mut().enumerate() {
        if state[f] == -1 {
            t.swap(1, 2);
            report.reoriented_faces += 1;
        }
    }
    if report.reoriented_faces > 0 {
        report.notes.push(format!(
            "{} faces were flipped to agree with the orientation of their neighbours",
            report.reoriented_faces
        ));
    }
    // Drop unreferenced vertices.
    let mut used = vec![false; nv_in];
    for t in &tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut new_id = vec![u32::MAX; nv_in];
    let mut vertex_origin = Vec::with_capacity(nv_in);
    for v in 0..nv_in {
        if used[v] {
            new_id[v] = vertex_origin.len() as u32;
            vertex_origin.push(v as u32);
        } else {
            report.dropped_vertices.push(v as u32);
        }
    }
    if !report.dropped_vertices.is_empty() {
        let first: Vec<String> = report
            .dropped_vertices
            .iter()
            .take(5)
            .map(|v| v.to_string())
            .collect();
        report.notes.push(format!(
            "{} vertices no face refers to were dropped (first: {})",
            report.dropped_vertices.len(),
            first.join(", ")
        ));
    }
    let positions: Vec<[f64; 3]> = vertex_origin
        .iter()
        .map(|&v| soup.positions[v as usize])
        .collect();
    let uvs = soup
        .uvs
        .as_ref()
        .map(|uv| vertex_origin.iter().map(|&v| uv[v as usize]).collect());
    let faces: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            [
                new_id[t[0] as usize],
                new_id[t[1] as usize],
                new_id[t[2] as usize],
            ]
        })
        .collect();
    let mesh = Mesh::from_triangles(positions.len(), faces).map_err(|e| match e {
        // Translate ids back to the input numbering in the message.
        Error::InvalidMesh { file, message } => Error::InvalidMesh {
            file,
            message: translate_vertex_ids(&message, &vertex_origin, &soup.vertex_lines),
        },
        other => other,
    })?;
    // Zero-area faces: area at most ZERO_AREA_RELATIVE × (bounding-box diagonal)², or
    // collinear corners to rounding (cross product ≤ 1e-14 × longest side²).
    let diag2 = {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>()
    };
    for (f, t) in mesh.faces().iter().enumerate() {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let area2 = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let scale =
            (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).max(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if area2 <= 1e-14 * scale || 0.5 * area2 <= ZERO_AREA_RELATIVE * diag2 {
            report.zero_area_faces.push(f as u32);
        }
    }
    if !report.zero_area_faces.is_empty() {
        let first: Vec<String> = report
            .zero_area_faces
            .iter()
            .take(5)
            .map(|&f| tri_src[f as usize].to_string())
            .collect();
        report.notes.push(format!(
            "{} faces have zero area (first: {})",
            report.zero_area_faces.len(),
            first.join(", ")
        ));
    }
    report.vertex_origin = vertex_origin;
    report.face_origin = tri_src;
    Ok((
        Surface {
            mesh,
            positions,
            uvs,
        },
        report,
    ))
}

/// Rewrite "vertex N" in a message from output ids to input ids (and add the line).
fn translate_vertex_ids(message: &str, origin: &[u32], lines: &Option<Vec<usize>>) -> String {
    let mut out = String::new();
    let mut rest = message;
    while let Some(pos) = rest.find("vertex ") {
        out.push_str(&rest[..pos + 7]);
        rest = &rest[pos + 7..];
        let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
        if let Ok(v) = digits.parse::<usize>() {
            let orig = origin.get(v).copied().unwrap_or(v as u32) as usize;
            out.push_str(&orig.to_string());
            out.push_str(&at_line(lines, orig));
            rest = &rest[digits.len()..];
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn soup(positions: Vec<[f64; 3]>, polygons: Vec<Vec<u32>>) -> PolygonSoup {
        PolygonSoup {
            positions,
            polygons,
            ..Default::default()
        }
    }

    fn square_grid(n: usize) -> PolygonSoup {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push([i as f64, j as f64, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut q = Vec::new();
        for j in 0..n {
            for i in 0..n {
                q.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        soup(p, q)
    }

    #[test]
    fn quads_are_triangulated_and_unreferenced_dropped() {
        let mut s = square_grid(3);
        s.positions.push([9.0, 9.0, 9.0]);
        let (surf, rep) = build_surface(s).unwrap();
        assert_eq!(surf.mesh.n_faces(), 18);
        assert_eq!(rep.triangulated_polygons, 9);
        assert_eq!(rep.dropped_vertices, vec![16]);
        assert_eq!(surf.mesh.boundary_loops().len(), 1);
    }

    #[test]
    fn inconsistent_faces_are_flipped() {
        let mut s = square_grid(2);
        s.polygons[1].reverse();
        s.polygons[3].reverse();
        let (surf, rep) = build_surface(s).unwrap();
        assert_eq!(rep.reoriented_faces, 4); // two quads = four triangles
        assert_eq!(surf.mesh.n_faces(), 8);
    }

    #[test]
    fn moebius_strip_is_refused() {
        // A strip of 6 quads whose ends are glued with a half twist.
        let n = 6;
        let mut p = Vec::new();
        for i in 0..n {
            let t = i as f64;
            p.push([t, 0.0, 0.0]);
            p.push([t, 1.0, 0.0]);
        }
        let mut q = Vec::new();
        for i in 0..n - 1 {
            q.push(vec![
                2 * i as u32,
                2 * i as u32 + 2,
                2 * i as u32 + 3,
                2 * i as u32 + 1,
            ]);
        }
        let l = 2 * (n - 1) as u32;
        q.push(vec![l, 1, 0, l + 1]); // twisted closure
        let e = build_surface(soup(p, q)).unwrap_err().to_string();
        assert!(e.contains("not orientable"), "{e}");
    }

    #[test]
    fn errors_name_the_culprit() {
        let e = build_surface(soup(vec![[0.0; 3]; 3], vec![vec![0, 1, 3]]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("face 0") && e.contains("vertex 3"), "{e}");
        let e = build_surface(soup(
            vec![[0.0, f64::NAN, 0.0], [1.0; 3], [2.0; 3]],
            vec![vec![0, 1, 2]],
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("vertex 0") && e.contains("non-finite"), "{e}");
        let e = build_surface(soup(vec![[0.0; 3]; 3], vec![vec![0, 1, 1]]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("face 0"), "{e}");
        let e = build_surface(soup(vec![[0.0; 3]; 3], vec![vec![0, 1, 2], vec![2, 1, 0]]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("duplicates"), "{e}");
        let e = build_surface(soup(vec![], vec![])).unwrap_err().to_string();
        assert!(e.contains("no faces"), "{e}");
    }

    #[test]
    fn pinched_vertex_is_named_in_input_numbering() {
        // Vertex 0 is unreferenced; two triangles touch at input vertex 1 only.
        let p = vec![
            [0.0; 3],
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        let e = build_surface(soup(p, vec![vec![1, 2, 3], vec![1, 4, 5]]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("non-manifold vertex 1"), "{e}");
    }
}
