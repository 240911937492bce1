//! The map of a surface `M` with boundary from the conformal flow on its double
//! ([`crate::flow::double::flow_on_double`]; issue 15, the disk whose boundary faces were split
//! off-centre; docs/notes/wave2-s7-dbl7.md "Not done / next step").
//!
//! The flow on the double `D = M ∪ σM` ends on a Delaunay triangulation `T_D` of `D` whose edges
//! may cross the fixed curve of `σ` (the boundary of `M`): an intrinsic triangulation of `M`
//! alone cannot carry that metric. The surface's own map is built from the double instead:
//!
//! 1. The common subdivision of the double's *input* (the mesh [`double_cover`] builds, with
//!    the mirrored lengths) and `T_D`, its crossings placed through the input metric's
//!    Delaunay triangulation ([`CommonSubdivision::from_triangulation_three_way`]: the
//!    ideal-triangle map of [`CommonSubdivision::from_triangulation`] crowds crossings of the
//!    boundary edges that the isometric flips removed into a boundary vertex),
//!    restricted to its pieces in the input faces `0..F` — the faces of `M`. Its vertices are
//!    `M`'s vertices (same ids) and the crossings of `T_D`'s edges with `M`'s edges, the
//!    boundary edges included (there the rungs `x – σx` of `T_D` cross `∂M`).
//! 2. The faces of `T_D` that hold such pieces (the region `R`: the faces meeting `M`) are
//!    unfolded in the plane face by face across their shared edges (breadth first, every face
//!    placed from its parent's two shared corners, copied exactly). For a disk `M`, `R` is a
//!    flat disk (the cones of `D` are `M`'s boundary vertices, on `∂R`), so the unfolding is a
//!    layout; the largest distance between the two placements of a corner across an edge of
//!    `R` outside the breadth-first tree is reported as `layout_gap` (rounding for a disk; a
//!    surface of higher genus or with several boundary loops needs the cut first — not done).
//! 3. The pieces' UVs by the projective interpolation of [`CommonSubdivision::uv`].
//!
//! E² only (the free-boundary and fixed-boundary-curvature targets of the flow on the double).

use super::subdivision_uv::SubdivisionUv;
use crate::error::{Error, Result};
use crate::flow::double::{double_triangulation, DoubleFlow};
use crate::mesh::double::{double_edge_origin, double_vertex_origin};
use crate::mesh::{double_cover, Mesh, NONE};
use crate::metric::common_subdivision::{CommonSubdivision, ThreeWayReport};
use crate::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use crate::metric::{Geometry, IntrinsicMetric};
use std::collections::VecDeque;

/// What [`half_subdivision`] built.
#[derive(Debug, Clone)]
pub struct HalfMap {
    /// The common subdivision of `M` and `T_D` with its UVs (vertices `0..V` are `M`'s).
    pub subdivision: SubdivisionUv,
    /// Faces of `T_D` meeting `M` (holding a piece of a face of `M`).
    pub region_faces: usize,
    /// Faces of `T_D` among them that hold pieces of faces of `σM` too (they cross `∂M`).
    pub crossing_faces: usize,
    /// Largest distance between the two placements of a corner across an edge of the region
    /// outside the unfolding's tree (0 up to rounding when the region is a flat disk).
    pub layout_gap: f64,
    /// The three-way overlay's report (crossings placed through the input metric's Delaunay
    /// triangulation).
    pub three_way: ThreeWayReport,
}

/// The map of `mesh` (positions, and the Euclidean `metric` the flow started from) from
/// `flow`, the E² flow on its double (module docs).
pub fn half_subdivision(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    metric: &IntrinsicMetric,
    flow: &DoubleFlow,
) -> Result<HalfMap> {
    let geometry = Geometry::Euclidean;
    metric.require(geometry, "the map of a surface from the flow on its double")?;
    let lengths = metric.lengths();
    if positions.len() != mesh.n_vertices() || lengths.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "{} positions and {} lengths for a mesh with {} vertices and {} edges",
            positions.len(),
            lengths.len(),
            mesh.n_vertices(),
            mesh.n_edges()
        )));
    }
    let (double, sigma) = double_cover(mesh)?;
    if sigma != flow.sigma {
        return Err(Error::input(
            "the flow on the double was not computed from this mesh (its σ differs)",
        ));
    }
    let origin = double_edge_origin(mesh, &double, &sigma)?;
    let d_lengths: Vec<f64> = origin.iter().map(|&e| lengths[e as usize]).collect();
    let d_positions: Vec<[f64; 3]> = (0..sigma.len() as u32)
        .map(|v| positions[double_vertex_origin(&sigma, v) as usize])
        .collect();
    let u = &flow.u_double;
    let (start, t) = renumbered(&double, mesh, lengths, &d_lengths, &flow.triangulation, u)?;
    let (full, three_way) =
        CommonSubdivision::from_triangulation_three_way(&double, start, &t, u, flow.initial_flips)?;
    let all_positions = full.positions(&double, &d_positions)?;
    let nf = mesh.n_faces() as u32;
    let n_tf = full.triangulation.n_faces();
    // Faces of T_D holding pieces of M, and of σM.
    let mut in_m = vec![false; n_tf];
    let mut in_mirror = vec![false; n_tf];
    for (&f0, &tf) in full.input_face.iter().zip(&full.t_face) {
        if f0 < nf {
            in_m[tf as usize] = true;
        } else {
            in_mirror[tf as usize] = true;
        }
    }
    let (corner, layout_gap) = unfold(&full.triangulation, u, &in_m)?;
    // The pieces in M's faces.
    let mut half = full.clone();
    let keep: Vec<usize> = (0..full.triangles.len())
        .filter(|&k| full.input_face[k] < nf)
        .collect();
    half.triangles = keep.iter().map(|&k| full.triangles[k]).collect();
    half.input_face = keep.iter().map(|&k| full.input_face[k]).collect();
    half.t_face = keep.iter().map(|&k| full.t_face[k]).collect();
    half.input_barycentric = keep
        .iter()
        .flat_map(|&k| full.input_barycentric[3 * k..3 * k + 3].to_vec())
        .collect();
    half.t_weights = keep
        .iter()
        .flat_map(|&k| full.t_weights[3 * k..3 * k + 3].to_vec())
        .collect();
    let uv = half.uv(geometry, u, &corner)?;
    let flipped_faces = half.flipped_triangles(geometry, &uv);
    // Renumber: M's vertices keep their ids, the crossings on M's edges follow.
    let nv = mesh.n_vertices();
    let mut id = vec![NONE; full.n_vertices()];
    for (v, slot) in id.iter_mut().enumerate().take(nv) {
        *slot = v as u32;
    }
    let mut locations: Vec<(u32, [f64; 3])> = vec![(NONE, [f64::NAN; 3]); nv];
    let mut out_positions: Vec<[f64; 3]> = positions.to_vec();
    let mut triangles = Vec::with_capacity(half.triangles.len());
    for (k, tr) in half.triangles.iter().enumerate() {
        let mut out = [0u32; 3];
        for (i, &v) in tr.iter().enumerate() {
            let v = v as usize;
            if id[v] == NONE {
                if v < sigma.len() {
                    return Err(Error::numerical(format!(
                        "a piece of face {} of the surface has a corner at vertex {v} of σM",
                        half.input_face[k]
                    )));
                }
                id[v] = locations.len() as u32;
                locations.push((NONE, [f64::NAN; 3]));
                out_positions.push(all_positions[v]);
            }
            let w = id[v] as usize;
            if locations[w].0 == NONE {
                locations[w] = (half.input_face[k], half.input_barycentric[3 * k + i]);
            }
            out[i] = id[v];
        }
        triangles.push(out);
    }
    if let Some(v) = locations.iter().position(|l| l.0 == NONE) {
        return Err(Error::numerical(format!(
            "vertex {v} of the surface is in no piece of the common subdivision"
        )));
    }
    let t_flipped_faces = (0..n_tf)
        .filter(|&f| {
            let o = orientation(&corner[3 * f..3 * f + 3]);
            in_m[f] && (o.is_nan() || o <= 0.0)
        })
        .count();
    let region_faces = in_m.iter().filter(|&&b| b).count();
    let crossing_faces = (0..n_tf).filter(|&f| in_m[f] && in_mirror[f]).count();
    let crossings = locations.len() - nv;
    Ok(HalfMap {
        subdivision: SubdivisionUv {
            locations,
            positions: out_positions,
            triangles,
            input_face: half.input_face.clone(),
            corner_uv: uv,
            sphere_points: Vec::new(),
            flipped_faces,
            seam_faces: 0,
            t_flipped_faces,
            recentred_faces: 0,
            nudged_uvs: 0,
            crossings,
            t_faces: region_faces,
        },
        region_faces,
        crossing_faces,
        layout_gap,
        three_way,
    })
}

/// `t` (a triangulation of the double built by [`double_triangulation`], after flips) with its
/// edges renumbered as the edges of [`IntrinsicTriangulation::from_mesh`] of the double's mesh
/// (the half-edges are the same: face `F + f` of both is the mirror of face `f`), and the
/// double's mesh as a triangulation with the `edge_he` choices of [`double_triangulation`], so
/// that the flip log replays on it to `t`; the coordinates are those of the final metric
/// (`t`'s scaled by `u`), as [`CommonSubdivision::from_triangulation_on`] takes them.
fn renumbered(
    double: &Mesh,
    mesh: &Mesh,
    lengths: &[f64],
    d_lengths: &[f64],
    t: &IntrinsicTriangulation,
    u: &[f64],
) -> Result<(IntrinsicTriangulation, IntrinsicTriangulation)> {
    let geometry = Geometry::Euclidean;
    let (t0, _, _) = double_triangulation(mesh, geometry, lengths)?;
    let mut d0 = IntrinsicTriangulation::from_mesh(double, geometry, d_lengths)?;
    if t0.origin != d0.origin || t0.n_edges() != d0.n_edges() || t.n_edges() != t0.n_edges() {
        return Err(Error::numerical(
            "the double's Δ-complex and the double's mesh do not have the same half-edges",
        ));
    }
    let map: Vec<u32> = t0.edge_he.iter().map(|&h| d0.edge[h as usize]).collect();
    if (0..t0.n_halfedges()).any(|h| map[t0.edge[h] as usize] != d0.edge[h]) {
        return Err(Error::numerical(
            "the double's Δ-complex and the double's mesh pair their half-edges differently",
        ));
    }
    let mut r = t.clone();
    for (h, e) in r.edge.iter_mut().enumerate() {
        *e = map[t.edge[h] as usize];
    }
    for (e, &m) in map.iter().enumerate() {
        r.edge_he[m as usize] = t.edge_he[e];
        // The final metric's coordinates (`t` holds the base ones, `u` not applied).
        r.lambda[m as usize] = t.scaled_lambda(e as u32, u);
    }
    r.flip_log = t.flip_log.iter().map(|&e| map[e as usize]).collect();
    for (e, &m) in map.iter().enumerate() {
        d0.edge_he[m as usize] = t0.edge_he[e];
    }
    Ok((d0, r))
}

/// Twice the signed area of a triangle in the plane.
fn orientation(p: &[[f64; 2]]) -> f64 {
    (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0])
}

/// The third corner `c` of a triangle with `|c − a| = la`, `|c − b| = lb`, `|b − a| = lab`,
/// to the left of `a → b`.
fn third(a: [f64; 2], b: [f64; 2], lab: f64, la: f64, lb: f64) -> [f64; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let d = dx.hypot(dy);
    let (ex, ey) = (dx / d, dy / d);
    let x = (la * la - lb * lb + lab * lab) / (2.0 * lab);
    let y = (la * la - x * x).max(0.0).sqrt();
    [a[0] + x * ex - y * ey, a[1] + x * ey + y * ex]
}

/// Corner positions (`3f + i`) of the faces of `tri` with `region[f]`, unfolded breadth first
/// in the plane with the metric `tri.lambda` scaled by `u` (others at the origin), and the
/// largest gap across a non-tree edge of the region (module docs).
fn unfold(
    tri: &IntrinsicTriangulation,
    u: &[f64],
    region: &[bool],
) -> Result<(Vec<[f64; 2]>, f64)> {
    let len = |h: usize| length_of_lambda(Geometry::Euclidean, tri.scaled_lambda(tri.edge[h], u));
    let nf = tri.n_faces();
    let mut corner = vec![[0.0f64; 2]; 3 * nf];
    let mut placed = vec![false; nf];
    let mut gap = 0.0f64;
    for start in 0..nf {
        if !region[start] || placed[start] {
            continue;
        }
        let b = 3 * start;
        corner[b] = [0.0, 0.0];
        corner[b + 1] = [len(b), 0.0];
        corner[b + 2] = third(corner[b], corner[b + 1], len(b), len(b + 2), len(b + 1));
        placed[start] = true;
        let mut queue = VecDeque::from([start]);
        while let Some(f) = queue.pop_front() {
            for i in 0..3 {
                let h = 3 * f + i;
                let t = tri.twin[h];
                if t == NONE {
                    continue;
                }
                let (g, j) = (t as usize / 3, t as usize % 3);
                if !region[g] {
                    continue;
                }
                // t runs from corner i + 1 of f to corner i of f.
                let (a, bb) = (corner[3 * f + (i + 1) % 3], corner[h]);
                if placed[g] {
                    let ga = corner[3 * g + j];
                    let gb = corner[3 * g + (j + 1) % 3];
                    gap = gap
                        .max((ga[0] - a[0]).hypot(ga[1] - a[1]))
                        .max((gb[0] - bb[0]).hypot(gb[1] - bb[1]));
                    continue;
                }
                let bg = 3 * g;
                corner[bg + j] = a;
                corner[bg + (j + 1) % 3] = bb;
                corner[bg + (j + 2) % 3] = third(
                    a,
                    bb,
                    len(bg + j),
                    len(bg + (j + 2) % 3),
                    len(bg + (j + 1) % 3),
                );
                placed[g] = true;
                queue.push_back(g);
            }
        }
    }
    if corner
        .iter()
        .any(|p| !p[0].is_finite() || !p[1].is_finite())
    {
        return Err(Error::numerical(
            "the unfolding of the faces meeting the surface has a non-finite point",
        ));
    }
    Ok((corner, gap))
}
