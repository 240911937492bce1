//! Re-triangulations of one surface, for checking that conformal invariants belong to the
//! surface and not to its triangulation (docs/DESIGN.md §5 "Re-triangulation"), and irregular
//! meshes of a surface with a known conformal structure.
//!
//! * [`midpoint_subdivision`] — every face split 1 → 4 at its edge midpoints: the same
//!   polyhedral surface (new vertices on the old edges), a finer triangulation.
//! * [`random_face_splits`] — a given fraction of the faces split 1 → 3 at a random,
//!   off-centre interior point (barycentric coordinates drawn away from the centroid): the
//!   same polyhedral surface, worse triangles.
//! * [`split_off_centre`] — a number of faces drawn at random split 1 → 3 at a point near
//!   one of their corners (thin triangles; boundary faces too if asked), and
//!   [`bumpy_split_disk`], the bumpy disk so split that the tests of the conformal flow on the
//!   double and of the common subdivision use (issue 15).
//! * [`irregular_torus`] — a torus of revolution `(R, r)` sampled at random points of its
//!   parameter square `(u, v) ∈ [0, 2π)²` and triangulated by the periodic Delaunay
//!   triangulation **in the parameter square** (not in conformal coordinates, so the
//!   triangles are stretched on the surface and many are slivers). The smooth torus is
//!   conformal to the rectangle of side ratio `√(R² − r²) / r` (long side around the axis);
//!   a fine irregular mesh tends to it.
//!
//! All are deterministic for a given seed and keep the input vertices (ids and
//! positions) first.

use crate::error::{Error, Result};
use crate::mesh::Surface;
use std::collections::HashMap;
use std::f64::consts::PI;

/// Deterministic xorshift64* numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Split every face 1 → 4 at the midpoints of its edges (input vertices first, then one
/// vertex per edge in edge-id order).
pub fn midpoint_subdivision(s: &Surface) -> Result<Surface> {
    let m = &s.mesh;
    let nv = m.n_vertices();
    let mut positions = s.positions.clone();
    for e in 0..m.n_edges() as u32 {
        let [a, b] = m.edge_vertices(e);
        let (p, q) = (s.positions[a as usize], s.positions[b as usize]);
        positions.push([
            0.5 * (p[0] + q[0]),
            0.5 * (p[1] + q[1]),
            0.5 * (p[2] + q[2]),
        ]);
    }
    let mut faces = Vec::with_capacity(4 * m.n_faces());
    for f in 0..m.n_faces() as u32 {
        let [a, b, c] = m.face(f);
        let hs = m.face_halfedges(f); // a→b, b→c, c→a
        let mid = |h: u32| (nv + m.he_edge(h) as usize) as u32;
        let (ab, bc, ca) = (mid(hs[0]), mid(hs[1]), mid(hs[2]));
        faces.push([a, ab, ca]);
        faces.push([ab, b, bc]);
        faces.push([ca, bc, c]);
        faces.push([ab, bc, ca]);
    }
    Surface::new(positions, faces)
}

/// Split about `fraction` of the faces (each face with that probability) 1 → 3 at an
/// off-centre interior point: barycentric coordinates `(w₀, w₁, w₂)` drawn uniformly from the
/// triangle and pushed away from the centroid (`w ← (w + t(w − 1/3))` with the largest `t ≤ 2`
/// that keeps every coordinate ≥ 0.02), so the new triangles are thin.
pub fn random_face_splits(s: &Surface, fraction: f64, seed: u64) -> Result<Surface> {
    if !(0.0..=1.0).contains(&fraction) {
        return Err(Error::input(format!(
            "random face splits: the fraction {fraction} is not in [0, 1]"
        )));
    }
    let m = &s.mesh;
    let mut rng = Rng::new(seed);
    let mut positions = s.positions.clone();
    let mut faces = Vec::with_capacity(m.n_faces() + 2 * m.n_faces());
    for f in 0..m.n_faces() as u32 {
        let [a, b, c] = m.face(f);
        if rng.next() >= fraction {
            faces.push([a, b, c]);
            continue;
        }
        // Uniform point of the triangle, then pushed away from the centroid.
        let (r1, r2) = (rng.next(), rng.next());
        let sq = r1.sqrt();
        let mut w = [1.0 - sq, sq * (1.0 - r2), sq * r2];
        let floor = 0.02;
        let mut t = 2.0f64;
        for x in w {
            let d = x - 1.0 / 3.0;
            if d < 0.0 {
                t = t.min((floor - x) / d);
            }
        }
        let t = t.max(0.0);
        for x in w.iter_mut() {
            *x += t * (*x - 1.0 / 3.0);
        }
        let p = [a, b, c].map(|v| s.positions[v as usize]);
        let q = [0, 1, 2].map(|k| w[0] * p[0][k] + w[1] * p[1][k] + w[2] * p[2][k]);
        let n = positions.len() as u32;
        positions.push(q);
        faces.push([a, b, n]);
        faces.push([b, c, n]);
        faces.push([c, a, n]);
    }
    Surface::new(positions, faces)
}

/// Split `count` faces drawn at random 1 → 3 at a point near one of their corners: the
/// barycentric weights are `(near − 0.1 r₁, (1 − near)(1 + r₂)/2, rest)`, so the new
/// triangles are thin and the metric is far from Delaunay. A face is drawn among all faces so
/// far (new ones included; a draw may hit the same face twice); a draw that hits a face with a
/// vertex on the boundary of `s` is skipped unless `boundary`. The numbers come from the
/// linear congruential generator `x ← 6364136223846793005 x + 1442695040888963407` started
/// at `seed` (top 53 bits), the generator of the tests of issue 15 that built these disks.
pub fn split_off_centre(
    s: &Surface,
    count: usize,
    seed: u64,
    near: f64,
    boundary: bool,
) -> Result<Surface> {
    if !(0.1..=1.0).contains(&near) {
        return Err(Error::input(format!(
            "off-centre splits: the corner weight {near} is not in [0.1, 1]"
        )));
    }
    let mut state = seed;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let m = &s.mesh;
    let mut pos = s.positions.clone();
    let mut faces = m.faces().to_vec();
    if faces.is_empty() {
        return Err(Error::input("off-centre splits: the surface has no faces"));
    }
    for _ in 0..count {
        let f = ((next() * faces.len() as f64) as usize).min(faces.len() - 1);
        let [a, b, c] = faces[f];
        let on_boundary = |v: u32| (v as usize) < m.n_vertices() && m.is_boundary_vertex(v);
        if !boundary && [a, b, c].into_iter().any(on_boundary) {
            continue;
        }
        let w0 = near - 0.1 * next();
        let w1 = 0.5 * (1.0 - near) * (1.0 + next());
        let w = [w0, w1, 1.0 - w0 - w1];
        let (pa, pb, pc) = (pos[a as usize], pos[b as usize], pos[c as usize]);
        let p = [0, 1, 2].map(|k| w[0] * pa[k] + w[1] * pb[k] + w[2] * pc[k]);
        let v = pos.len() as u32;
        pos.push(p);
        faces[f] = [a, b, v];
        faces.push([b, c, v]);
        faces.push([c, a, v]);
    }
    Surface::new(pos, faces)
}

/// The bumpy disk of issue 15: [`super::disk`]`(16)` lifted to the height field
/// `z = sin(3x) cos(2y) / 2 + 0.7 x²`, then [`split_off_centre`] (`count`, `seed`, `near`,
/// `boundary`). With `boundary` the faces at the boundary are split too, which a flow on the
/// surface itself cannot repair (boundary edges never flip; the flow on the double can).
pub fn bumpy_split_disk(count: usize, seed: u64, near: f64, boundary: bool) -> Result<Surface> {
    let d = super::disk(16)?;
    let pos: Vec<[f64; 3]> = d
        .positions
        .iter()
        .map(|p| {
            let (x, y) = (p[0], p[1]);
            [x, y, 0.5 * (3.0 * x).sin() * (2.0 * y).cos() + 0.7 * x * x]
        })
        .collect();
    let s = Surface::new(pos, d.mesh.faces().to_vec())?;
    split_off_centre(&s, count, seed, near, boundary)
}

/// A torus of revolution `(major, minor)` through `points` random points of its parameter
/// square, triangulated by the periodic Delaunay triangulation of the parameter square (see
/// the module docs). Its smooth conformal modulus is `√(R² − r²) / r` (ratio of the flat
/// torus's side around the axis to the side around the tube).
pub fn irregular_torus(major: f64, minor: f64, points: usize, seed: u64) -> Result<Surface> {
    use spade::{DelaunayTriangulation, Point2, Triangulation};
    if !(major.is_finite() && minor.is_finite()) || minor <= 0.0 || major <= minor {
        return Err(Error::input(format!(
            "irregular torus: the radii must satisfy 0 < minor < major (got {major}, {minor})"
        )));
    }
    if !(16..=5_000_000).contains(&points) {
        return Err(Error::input(format!(
            "irregular torus: {points} points is not in 16..=5000000"
        )));
    }
    let mut rng = Rng::new(seed);
    let base: Vec<[f64; 2]> = (0..points).map(|_| [rng.next(), rng.next()]).collect();
    // Nine periodic copies; a triangle of the big triangulation is kept when its centroid
    // lies in the unit square (exactly one of the nine copies of each periodic triangle).
    let mut pts = Vec::with_capacity(9 * points);
    let mut index: HashMap<(u64, u64), u32> = HashMap::with_capacity(9 * points);
    for dx in [-1.0, 0.0, 1.0] {
        for dy in [-1.0, 0.0, 1.0] {
            for (i, p) in base.iter().enumerate() {
                let q = Point2::new(p[0] + dx, p[1] + dy);
                index.insert((q.x.to_bits(), q.y.to_bits()), i as u32);
                pts.push(q);
            }
        }
    }
    let dt: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::bulk_load(pts)
        .map_err(|e| Error::numerical(format!("irregular torus: Delaunay failed ({e:?})")))?;
    let mut faces = Vec::with_capacity(2 * points);
    for f in dt.inner_faces() {
        let vs = f.vertices().map(|v| v.position());
        let cx = (vs[0].x + vs[1].x + vs[2].x) / 3.0;
        let cy = (vs[0].y + vs[1].y + vs[2].y) / 3.0;
        if !((0.0..1.0).contains(&cx) && (0.0..1.0).contains(&cy)) {
            continue;
        }
        let mut t = [0u32; 3];
        for k in 0..3 {
            t[k] = *index
                .get(&(vs[k].x.to_bits(), vs[k].y.to_bits()))
                .ok_or_else(|| Error::numerical("irregular torus: a vertex was lost"))?;
        }
        faces.push(t);
    }
    let positions = base
        .iter()
        .map(|p| {
            let (u, v) = (2.0 * PI * p[0], 2.0 * PI * p[1]);
            let rho = major + minor * v.cos();
            [rho * u.cos(), rho * u.sin(), minor * v.sin()]
        })
        .collect();
    Surface::new(positions, faces).map_err(|e| {
        Error::numerical(format!(
            "irregular torus: the periodic triangulation of {points} points is not a torus \
             mesh ({e}); use more points"
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::torus;
    use crate::mesh::quality::face_angles;

    fn chi(s: &Surface) -> i64 {
        s.mesh.n_vertices() as i64 - s.mesh.n_edges() as i64 + s.mesh.n_faces() as i64
    }
    fn min_angle(s: &Surface, f: u32) -> f64 {
        face_angles(s, f).into_iter().fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn retriangulations_keep_the_surface() {
        let s = torus(1.0, 0.4, 12).unwrap();
        let a0 = s.area();
        let m = midpoint_subdivision(&s).unwrap();
        assert_eq!(m.mesh.n_faces(), 4 * s.mesh.n_faces());
        assert_eq!(chi(&m), chi(&s));
        assert!((m.area() - a0).abs() <= 1e-12 * a0);
        let r = random_face_splits(&s, 0.5, 7).unwrap();
        let split = (r.mesh.n_faces() - s.mesh.n_faces()) / 2;
        assert!(
            split > s.mesh.n_faces() / 4 && split < 3 * s.mesh.n_faces() / 4,
            "{split}"
        );
        assert!((r.area() - a0).abs() <= 1e-12 * a0);
        // Off-centre: the new vertices are not at the centroids.
        let nv = s.mesh.n_vertices();
        let mut worst = f64::INFINITY;
        for f in 0..r.mesh.n_faces() as u32 {
            let t = r.mesh.face(f);
            if t.iter().any(|&v| v as usize >= nv) {
                worst = worst.min(min_angle(&r, f));
            }
        }
        assert!(worst < 5f64.to_radians(), "some split triangles are thin");
    }

    #[test]
    fn irregular_torus_is_a_torus_with_slivers() {
        let s = irregular_torus(1.0, 0.3, 2000, 3).unwrap();
        let t = crate::mesh::topology(&s.mesh);
        assert_eq!(t.components.len(), 1);
        assert_eq!(t.components[0].genus, 1);
        assert_eq!(t.components[0].boundary_loops, 0);
        assert_eq!(s.mesh.n_vertices(), 2000);
        let min = (0..s.mesh.n_faces() as u32)
            .map(|f| min_angle(&s, f))
            .fold(f64::INFINITY, f64::min);
        assert!(min < 1f64.to_radians(), "min angle {}°", min.to_degrees());
        // Area close to the smooth torus's 4π² R r.
        let smooth = 4.0 * PI * PI * 0.3;
        assert!((s.area() - smooth).abs() < 0.01 * smooth, "{}", s.area());
    }
}
