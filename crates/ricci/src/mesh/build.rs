//! From a polygon soup (what a file holds) to a validated [`Surface`].
//!
//! Checks, in order, each failing with one sentence naming the culprit in the file's own
//! numbering (0-based vertex and face ids, plus the line when the reader recorded it):
//! non-finite coordinates, indices out of range, polygons with fewer than three distinct
//! corners, duplicate faces, non-manifold edges, non-orientable components, non-manifold
//! vertices. Accepted with a note: polygons (fan-triangulated), unreferenced vertices
//! (dropped), inconsistently oriented faces in an orientable component (flipped), zero-area
//! faces (listed).

use super::{Mesh, Surface, NONE};
use crate::error::{Error, Result};

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
    /// Texture coordinates per polygon corner (flat, in polygon order), when every corner of
    /// the file has one (OBJ `f v/vt`) — also across texture seams, where `uvs` is `None`.
    pub corner_uvs: Option<Vec<[f64; 2]>>,
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

/// Half-edges of a triangle list grouped by undirected edge; edges are numbered in the
/// lexicographic order of their (smaller, larger) vertex ids, like [`Mesh::from_triangles`].
struct EdgeGroups {
    /// The other interior half-edge of the same edge; `NONE` on the boundary.
    partner: Vec<u32>,
    /// Paired half-edges that go the same way (their faces disagree on orientation).
    n_same_direction: usize,
    /// Edge id of every interior half-edge.
    he_edge: Vec<u32>,
    n_edges: usize,
    /// First pair of duplicate faces (same three vertices), and how many pairs there are.
    duplicate: Option<(u32, u32)>,
    n_duplicates: usize,
    /// First edge with more than two faces: its vertices and faces; and how many there are.
    non_manifold: Option<(u32, u32, Vec<u32>)>,
    n_non_manifold: usize,
}

/// Group the half-edges of `tris` by edge in linear time: a counting sort by the smaller
/// vertex, then a tiny sort of each vertex's bucket by the larger one.
fn group_edges(n_vertices: usize, tris: &[[u32; 3]]) -> EdgeGroups {
    let nh = 3 * tris.len();
    let mut start = vec![0u32; n_vertices + 1];
    for t in tris {
        for i in 0..3 {
            start[t[i].min(t[(i + 1) % 3]) as usize + 1] += 1;
        }
    }
    for v in 0..n_vertices {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut slots = vec![(0u32, 0u32); nh];
    for (f, t) in tris.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let lo = a.min(b) as usize;
            // The top bit records the direction (h < 2³¹ since 3F < 2³¹).
            slots[fill[lo] as usize] = (a.max(b), (3 * f + i) as u32 | ((a > b) as u32) << 31);
            fill[lo] += 1;
        }
    }
    drop(fill);
    const H: u32 = !(1 << 31);
    let third = |h: u32| tris[(h & H) as usize / 3][((h & H) as usize % 3 + 2) % 3];
    let mut g = EdgeGroups {
        partner: vec![NONE; nh],
        n_same_direction: 0,
        he_edge: vec![NONE; nh],
        n_edges: 0,
        duplicate: None,
        n_duplicates: 0,
        non_manifold: None,
        n_non_manifold: 0,
    };
    let mut e = 0u32;
    for v in 0..n_vertices {
        let bucket = &mut slots[start[v] as usize..start[v + 1] as usize];
        bucket.sort_unstable();
        let mut i = 0;
        while i < bucket.len() {
            let mut j = i + 1;
            while j < bucket.len() && bucket[j].0 == bucket[i].0 {
                j += 1;
            }
            let group = &bucket[i..j];
            for x in group {
                g.he_edge[(x.1 & H) as usize] = e;
            }
            if group.len() == 2 {
                let (h0, h1) = (group[0].1 & H, group[1].1 & H);
                g.partner[h0 as usize] = h1;
                g.partner[h1 as usize] = h0;
                if (group[0].1 ^ group[1].1) >> 31 == 0 {
                    g.n_same_direction += 1;
                }
            }
            for (k, x) in group.iter().enumerate() {
                for y in &group[k + 1..] {
                    if third(x.1) == third(y.1) {
                        g.n_duplicates += 1;
                        if g.duplicate.is_none() {
                            let (f0, f1) = ((x.1 & H) / 3, (y.1 & H) / 3);
                            g.duplicate = Some((f0.min(f1), f0.max(f1)));
                        }
                    }
                }
            }
            if group.len() > 2 {
                g.n_non_manifold += 1;
                if g.non_manifold.is_none() {
                    let mut faces: Vec<u32> = group.iter().map(|x| (x.1 & H) / 3).collect();
                    faces.sort_unstable();
                    g.non_manifold = Some((v as u32, group[0].0, faces));
                }
            }
            e += 1;
            i = j;
        }
    }
    g.n_edges = e as usize;
    g
}

/// Validate a polygon soup and build the surface. See the module docs for what is checked.
///
/// Runs in time linear in the size of the soup (no hashing, no global sort).
pub fn build_surface(soup: PolygonSoup) -> Result<(Surface, BuildReport)> {
    let mut report = BuildReport {
        notes: soup.notes.clone(),
        ..Default::default()
    };
    let nv_in = soup.positions.len();
    let vline = |v: usize| at_line(&soup.vertex_lines, v);
    if soup.polygons.is_empty() {
        return Err(Error::invalid_mesh("the file contains no faces"));
    }
    if nv_in >= NONE as usize {
        return Err(Error::input("mesh too large for 32-bit indices"));
    }
    for (i, p) in soup.positions.iter().enumerate() {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid_mesh(format!(
                "vertex {i}{} has a non-finite coordinate ({}, {}, {})",
                vline(i),
                p[0],
                p[1],
                p[2]
            )));
        }
    }
    let (mut tris, tri_src) = triangulate(&soup, &mut report)?;
    let groups = group_edges(nv_in, &tris);
    check_edge_groups(&groups, &tris, &tri_src, &soup)?;
    // Orientation: propagate over faces through their edges, flipping where needed.
    let nf = tris.len();
    let state = orientation(&tris, &groups, &tri_src)?;
    let flipped = |f: usize| state[f] == 2;
    report.reoriented_faces = state.iter().filter(|&&s| s == 2).count();
    let n_edges = groups.n_edges;
    let (partner, he_edge) = if report.reoriented_faces == 0 {
        (groups.partner, groups.he_edge)
    } else {
        // Half-edge i of a flipped face becomes half-edge 2 − i.
        let remap = |h: u32| {
            if h != NONE && flipped(h as usize / 3) {
                3 * (h / 3) + 2 - h % 3
            } else {
                h
            }
        };
        let mut partner = vec![NONE; 3 * nf];
        let mut he_edge = vec![NONE; 3 * nf];
        for h in 0..(3 * nf) as u32 {
            partner[remap(h) as usize] = remap(groups.partner[h as usize]);
            he_edge[remap(h) as usize] = groups.he_edge[h as usize];
        }
        for (f, t) in tris.iter_mut().enumerate() {
            if flipped(f) {
                t.swap(1, 2);
            }
        }
        (partner, he_edge)
    };
    if report.reoriented_faces > 0 {
        report.notes.push(format!(
            "{} faces were flipped to agree with the orientation of their neighbours",
            report.reoriented_faces
        ));
    }
    // Drop unreferenced vertices (the renumbering is monotone, so edge order is kept).
    let mut new_id = vec![NONE; nv_in];
    for t in &tris {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut vertex_origin = Vec::with_capacity(nv_in);
    for (v, id) in new_id.iter_mut().enumerate() {
        if *id == 0 {
            *id = vertex_origin.len() as u32;
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
    for t in &mut tris {
        *t = t.map(|v| new_id[v as usize]);
    }
    drop(new_id);
    let positions: Vec<[f64; 3]> = vertex_origin
        .iter()
        .map(|&v| soup.positions[v as usize])
        .collect();
    let uvs = soup.uvs.as_ref().and_then(|uv| {
        (uv.len() == nv_in).then(|| vertex_origin.iter().map(|&v| uv[v as usize]).collect())
    });
    let mesh = connect(positions.len(), tris, partner, he_edge, n_edges).map_err(|v| {
        let orig = vertex_origin[v as usize] as usize;
        Error::invalid_mesh(format!(
            "non-manifold vertex {orig}{}: its faces form more than one fan (the surface is pinched there)",
            vline(orig)
        ))
    })?;
    report.zero_area_faces = zero_area_faces(&mesh, &positions);
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

/// Fan-triangulate the polygons, checking their indices (against the `positions`), their
/// size and repeated corners; returns the triangles and the polygon of each.
#[allow(clippy::type_complexity)]
fn triangulate(soup: &PolygonSoup, report: &mut BuildReport) -> Result<(Vec<[u32; 3]>, Vec<u32>)> {
    let nv_in = soup.positions.len();
    let pline = |p: usize| at_line(&soup.polygon_lines, p);
    let n_tris: usize = soup
        .polygons
        .iter()
        .map(|p| p.len().saturating_sub(2))
        .sum();
    if 3 * n_tris >= (NONE as usize) / 2 {
        return Err(Error::input("mesh too large for 32-bit indices"));
    }
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(n_tris);
    let mut tri_src: Vec<u32> = Vec::with_capacity(n_tris);
    for (pi, poly) in soup.polygons.iter().enumerate() {
        if let Some(&v) = poly.iter().find(|&&v| v as usize >= nv_in) {
            return Err(Error::invalid_mesh(format!(
                "face {pi}{} refers to vertex {v}, but the file has only {nv_in} vertices",
                pline(pi)
            )));
        }
        if poly.len() < 3 {
            return Err(Error::invalid_mesh(format!(
                "face {pi}{} has only {} corners; a face needs at least three",
                pline(pi),
                poly.len()
            )));
        }
        if let Some(v) = repeated_vertex(poly) {
            let corners: Vec<String> = poly.iter().map(|v| v.to_string()).collect();
            return Err(Error::invalid_mesh(format!(
                "face {pi}{} uses vertex {v} more than once (corners {}); a face needs distinct vertices",
                pline(pi),
                corners.join(" ")
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
    Ok((tris, tri_src))
}

/// Duplicate faces and non-manifold edges found by [`group_edges`], as errors naming the
/// input polygons and vertices with their lines.
fn check_edge_groups(
    groups: &EdgeGroups,
    tris: &[[u32; 3]],
    tri_src: &[u32],
    soup: &PolygonSoup,
) -> Result<()> {
    let vline = |v: usize| at_line(&soup.vertex_lines, v);
    let pline = |p: usize| at_line(&soup.polygon_lines, p);
    let src = |f: u32| tri_src[f as usize] as usize;
    if let Some((f, g)) = groups.duplicate {
        let (a, b) = (src(f), src(g));
        let mut k = tris[f as usize];
        k.sort_unstable();
        // Two faces with the same vertices meet on all three of their edges.
        let more = match groups.n_duplicates / 3 {
            0 | 1 => String::new(),
            n => format!("; {n} pairs of duplicate faces in all"),
        };
        return Err(Error::invalid_mesh(format!(
            "faces {a}{} and {b}{} are duplicates (both use vertices {}, {}, {}){more}",
            pline(a),
            pline(b),
            k[0],
            k[1],
            k[2]
        )));
    }
    if let Some((a, b, faces)) = &groups.non_manifold {
        let list: Vec<String> = faces.iter().map(|&f| src(f).to_string()).collect();
        let more = match groups.n_non_manifold {
            1 => String::new(),
            n => format!("; {n} non-manifold edges in all"),
        };
        return Err(Error::invalid_mesh(format!(
            "non-manifold edge between vertices {a}{} and {b}{}: it is shared by {} faces ({}){more}",
            vline(*a as usize),
            vline(*b as usize),
            faces.len(),
            list.join(", ")
        )));
    }
    Ok(())
}

/// Orientation: propagate over faces through their edges; per face 1 (keep) or 2 (flip), or
/// all 0 when no two neighbours disagree. A surface that cannot be oriented is an error naming
/// two input polygons and their edge.
fn orientation(tris: &[[u32; 3]], groups: &EdgeGroups, tri_src: &[u32]) -> Result<Vec<u8>> {
    let src = |f: u32| tri_src[f as usize] as usize;
    let nf = tris.len();
    let origin = |h: u32| tris[h as usize / 3][h as usize % 3];
    let mut state = vec![0u8; nf]; // 0 unvisited, 1 keep, 2 flip
    let mut stack = Vec::new();
    // Nothing to do when no two neighbours disagree (the usual case).
    let seeds = if groups.n_same_direction == 0 { 0 } else { nf };
    for seed in 0..seeds {
        if state[seed] != 0 {
            continue;
        }
        state[seed] = 1;
        stack.push(seed as u32);
        while let Some(f) = stack.pop() {
            let f_flipped = state[f as usize] == 2;
            for h in 3 * f..3 * f + 3 {
                let g = groups.partner[h as usize];
                if g == NONE {
                    continue;
                }
                // Consistent iff the two faces traverse the edge in opposite directions.
                let same = origin(h) == origin(g);
                let want = if same ^ f_flipped { 2 } else { 1 };
                let gf = (g / 3) as usize;
                if state[gf] == 0 {
                    state[gf] = want;
                    stack.push(gf as u32);
                } else if state[gf] != want {
                    let (a, b) = (origin(h), tris[h as usize / 3][(h as usize % 3 + 1) % 3]);
                    return Err(Error::invalid_mesh(format!(
                        "the surface is not orientable: going around it through faces {} and {} \
                         (along the edge between vertices {a} and {b}) reverses the orientation",
                        src(f),
                        src(g / 3)
                    )));
                }
            }
        }
    }
    Ok(state)
}

/// Zero-area faces: area at most [`ZERO_AREA_RELATIVE`] × (bounding-box diagonal)², or
/// collinear corners to rounding (cross product ≤ 1e-14 × longest side²).
fn zero_area_faces(mesh: &Mesh, positions: &[[f64; 3]]) -> Vec<u32> {
    let mut out = Vec::new();
    let diag2 = {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in positions {
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
            out.push(f as u32);
        }
    }
    out
}

/// A vertex that occurs twice in the polygon, if any.
fn repeated_vertex(poly: &[u32]) -> Option<u32> {
    if poly.len() <= 16 {
        for (i, &v) in poly.iter().enumerate() {
            if poly[i + 1..].contains(&v) {
                return Some(v);
            }
        }
        None
    } else {
        let mut s = poly.to_vec();
        s.sort_unstable();
        s.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }
}

/// Assemble the half-edge arrays of consistently oriented triangles whose interior half-edges
/// are already paired (`partner`, `NONE` on the boundary) and numbered by edge. The result is
/// identical to [`Mesh::from_triangles`] on the same faces. Fails with the (output) id of a
/// non-manifold vertex.
fn connect(
    n_vertices: usize,
    faces: Vec<[u32; 3]>,
    partner: Vec<u32>,
    he_edge: Vec<u32>,
    n_edges: usize,
) -> std::result::Result<Mesh, u32> {
    let nh = 3 * faces.len();
    let origin = |h: u32| faces[h as usize / 3][h as usize % 3];
    let mut edge_he = vec![NONE; n_edges];
    for h in 0..nh as u32 {
        let e = he_edge[h as usize] as usize;
        if edge_he[e] == NONE {
            edge_he[e] = h; // half-edges come in increasing order: this is the smaller one
        }
    }
    let boundary_of: Vec<u32> = edge_he
        .iter()
        .copied()
        .filter(|&h| partner[h as usize] == NONE)
        .collect();
    let nb = boundary_of.len();
    let mut twin = partner;
    twin.resize(nh + nb, NONE);
    let mut he_edge = he_edge;
    he_edge.resize(nh + nb, NONE);
    let mut boundary_origin = vec![NONE; nb];
    let mut out_boundary = vec![NONE; n_vertices];
    for (k, &h) in boundary_of.iter().enumerate() {
        let b = (nh + k) as u32;
        twin[h as usize] = b;
        twin[b as usize] = h;
        he_edge[b as usize] = he_edge[h as usize];
        let tip = faces[h as usize / 3][(h as usize % 3 + 1) % 3];
        boundary_origin[k] = tip;
        if out_boundary[tip as usize] != NONE {
            return Err(tip); // two boundary fans meet at `tip`
        }
        out_boundary[tip as usize] = b;
    }
    let boundary_next: Vec<u32> = boundary_of
        .iter()
        .map(|&h| out_boundary[origin(h) as usize])
        .collect();
    drop(out_boundary);
    let mut vertex_he = vec![NONE; n_vertices];
    for h in (0..nh as u32).rev() {
        vertex_he[origin(h) as usize] = h;
    }
    for &h in &boundary_of {
        vertex_he[origin(h) as usize] = h;
    }
    let mesh = Mesh {
        n_vertices,
        faces,
        twin,
        boundary_next,
        boundary_origin,
        he_edge,
        edge_he,
        vertex_he,
    };
    // Every vertex must have a single fan: walking around it must meet all its corners.
    let mut corners = vec![0u32; n_vertices];
    for t in mesh.faces() {
        for &v in t {
            corners[v as usize] += 1;
        }
    }
    for (v, &count) in corners.iter().enumerate() {
        if count == 0 {
            continue;
        }
        let fan = mesh.vertex_faces(v as u32).take(count as usize + 1).count();
        if fan != count as usize {
            return Err(v as u32);
        }
    }
    Ok(mesh)
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

    /// xorshift64*: deterministic pseudo-random numbers for the tests.
    fn rng(seed: u64) -> impl FnMut(u64) -> u64 {
        let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        move |n| {
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) % n
        }
    }

    /// A torus grid (closed) or a square grid (disk) of triangles, with random faces removed,
    /// random faces reversed and the vertices randomly renumbered.
    fn scrambled_grid(seed: u64) -> (usize, Vec<Vec<u32>>) {
        let mut r = rng(seed);
        let (n, m) = (3 + r(5) as usize, 3 + r(5) as usize);
        let closed = r(2) == 0;
        let (cols, rows) = if closed { (n, m) } else { (n + 1, m + 1) };
        let id = |i: usize, j: usize| ((i % cols) * rows + (j % rows)) as u32;
        let mut perm: Vec<u32> = (0..(cols * rows) as u32).collect();
        for k in (1..perm.len()).rev() {
            perm.swap(k, r(k as u64 + 1) as usize);
        }
        let holes = r(4);
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..m {
                for t in [
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                    [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
                ] {
                    if holes > 0 && r(10) < holes {
                        continue;
                    }
                    let mut f: Vec<u32> = t.iter().map(|&v| perm[v as usize]).collect();
                    if r(3) == 0 {
                        f.reverse();
                    }
                    faces.push(f);
                }
            }
        }
        (cols * rows, faces)
    }

    #[test]
    fn linear_builder_matches_from_triangles() {
        let (mut accepted, mut refused) = (0, 0);
        for seed in 0..300 {
            let (nv, faces) = scrambled_grid(seed);
            if faces.is_empty() {
                continue;
            }
            let positions = (0..nv)
                .map(|i| [i as f64, (i * i % 7) as f64, 0.5])
                .collect();
            match build_surface(soup(positions, faces)) {
                Ok((s, rep)) => {
                    accepted += 1;
                    let reference =
                        Mesh::from_triangles(s.mesh.n_vertices(), s.mesh.faces().to_vec())
                            .expect("the builder's output is a valid mesh");
                    assert_eq!(s.mesh, reference, "seed {seed}");
                    assert_eq!(rep.face_origin.len(), s.mesh.n_faces());
                }
                Err(e) => {
                    refused += 1;
                    let e = e.to_string();
                    assert!(e.contains("non-manifold vertex"), "seed {seed}: {e}");
                }
            }
        }
        // Both outcomes must have been exercised.
        assert!(
            accepted > 100 && refused > 10,
            "{accepted} accepted, {refused} refused"
        );
    }
}
