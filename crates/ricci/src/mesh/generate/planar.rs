//! Planar domains bounded by circles (disk, annulus, pair of pants), meshed with uniform
//! spacing.
//!
//! 1. Every boundary circle is sampled uniformly with spacing close to `h = 2πρ₀ / n` (`ρ₀`
//!    the outer radius, `n` the resolution); a hole gets `max(8, round(2πρ/h))` points.
//! 2. Interior seeds: a hexagonal lattice of spacing `h`, keeping points at least `0.6 h` from
//!    every boundary circle.
//! 3. Constrained Delaunay triangulation (the `spade` crate, boundary segments as
//!    constraints), then optimal Delaunay triangulation smoothing (Chen & Xu 2004): every
//!    interior vertex moves to the area-weighted mean of the circumcentres of its triangles
//!    (the centroid mean where that would leave the domain), and the Delaunay triangulation
//!    is rebuilt; 25 rounds.
//! 4. A final pattern search moves interior vertices whose star has an angle below 40° to raise
//!    the smallest angle, followed by a last Delaunay rebuild.
//!
//! Faces are counter-clockwise in the plane `z = 0`; the outer loop runs counter-clockwise,
//! holes clockwise (surface on the left).

use super::geom::*;
use crate::error::{Error, Result};
use crate::mesh::Surface;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::f64::consts::PI;

/// A disk of radius `outer` around the origin with round holes `(centre, radius)`.
pub(crate) struct Domain {
    pub outer: f64,
    pub holes: Vec<([f64; 2], f64)>,
}

impl Domain {
    fn contains(&self, p: [f64; 2]) -> bool {
        (p[0] * p[0] + p[1] * p[1]).sqrt() < self.outer
            && self
                .holes
                .iter()
                .all(|(c, r)| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() > *r)
    }
    /// Distance from an interior point to the boundary.
    fn boundary_distance(&self, p: [f64; 2]) -> f64 {
        let mut d = self.outer - (p[0] * p[0] + p[1] * p[1]).sqrt();
        for (c, r) in &self.holes {
            d = d.min(((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() - r);
        }
        d
    }
}

const ODT_ROUNDS: usize = 25;

/// Mesh the domain with `n` segments on the outer circle.
pub(crate) fn mesh_domain(name: &str, dom: &Domain, n: u32) -> Result<Surface> {
    let h = 2.0 * PI * dom.outer / n as f64;
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let mut constraints: Vec<[usize; 2]> = Vec::new();
    let mut circle = |centre: [f64; 2], radius: f64, count: usize, ccw: bool| {
        let first = pts.len();
        for i in 0..count {
            let t = 2.0 * PI * i as f64 / count as f64;
            let t = if ccw { t } else { -t };
            pts.push([centre[0] + radius * t.cos(), centre[1] + radius * t.sin()]);
            constraints.push([first + i, first + (i + 1) % count]);
        }
    };
    circle([0.0, 0.0], dom.outer, n as usize, true);
    for &(c, r) in &dom.holes {
        let m = ((2.0 * PI * r / h).round() as usize).max(8);
        circle(c, r, m, false);
    }
    let n_boundary = pts.len();
    let dy = h * 3f64.sqrt() / 2.0;
    let rows = (dom.outer / dy).ceil() as i64;
    let cols = (dom.outer / h).ceil() as i64 + 1;
    for j in -rows..=rows {
        let shift = if j.rem_euclid(2) == 1 { 0.5 } else { 0.0 };
        for i in -cols..=cols {
            let p = [(i as f64 + shift) * h, j as f64 * dy];
            if dom.contains(p) && dom.boundary_distance(p) >= 0.6 * h {
                pts.push(p);
            }
        }
    }
    let mut faces = triangulate(name, dom, &pts, &constraints)?;
    for _ in 0..ODT_ROUNDS {
        odt_step(dom, &mut pts, &faces, n_boundary, h);
        faces = triangulate(name, dom, &pts, &constraints)?;
    }
    for _ in 0..2 {
        improve_angles(&mut pts, &faces, n_boundary, h);
        faces = triangulate(name, dom, &pts, &constraints)?;
    }
    let positions = pts.iter().map(|p| [p[0], p[1], 0.0]).collect();
    Surface::new(positions, faces)
}

/// Constrained Delaunay triangulation of the points, keeping the faces inside the domain,
/// counter-clockwise.
fn triangulate(
    name: &str,
    dom: &Domain,
    pts: &[[f64; 2]],
    constraints: &[[usize; 2]],
) -> Result<Vec<[u32; 3]>> {
    let vertices: Vec<Point2<f64>> = pts.iter().map(|p| Point2::new(p[0], p[1])).collect();
    let mut conflict = false;
    let cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::try_bulk_load_cdt(vertices, constraints.to_vec(), |_| {
            conflict = true
        })
        .map_err(|e| Error::numerical(format!("{name}: triangulation failed: {e:?}")))?;
    if conflict || cdt.num_vertices() != pts.len() {
        return Err(Error::numerical(format!(
            "{name}: triangulation failed (two mesh points coincide or boundary segments cross)"
        )));
    }
    let mut faces = Vec::with_capacity(cdt.num_inner_faces());
    for f in cdt.inner_faces() {
        let v = f.vertices().map(|v| v.fix().index());
        let p = v.map(|i| pts[i]);
        let c = [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
        ];
        if !dom.contains(c) {
            continue;
        }
        let area2 =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
        let t = v.map(|i| i as u32);
        faces.push(if area2 > 0.0 { t } else { [t[0], t[2], t[1]] });
    }
    Ok(faces)
}

fn circumcenter(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Option<[f64; 2]> {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    if d.abs() < 1e-300 {
        return None;
    }
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    Some([
        a[0] + (cy * b2 - by * c2) / d,
        a[1] + (bx * c2 - cx * b2) / d,
    ])
}

/// One round of ODT smoothing of the interior vertices (indices ≥ `fixed`).
fn odt_step(dom: &Domain, pts: &mut [[f64; 2]], faces: &[[u32; 3]], fixed: usize, h: f64) {
    let n = pts.len();
    let mut acc_cc = vec![[0.0f64; 3]; n]; // Σ|T| c_T, Σ|T|
    let mut acc_ct = vec![[0.0f64; 3]; n]; // Σ|T| centroid, Σ|T|
    for t in faces {
        let p = t.map(|v| pts[v as usize]);
        let area = 0.5
            * ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]))
                .abs();
        let cen = [
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
        ];
        let cc = circumcenter(p[0], p[1], p[2]).unwrap_or(cen);
        for &v in t {
            let v = v as usize;
            acc_cc[v][0] += area * cc[0];
            acc_cc[v][1] += area * cc[1];
            acc_cc[v][2] += area;
            acc_ct[v][0] += area * cen[0];
            acc_ct[v][1] += area * cen[1];
            acc_ct[v][2] += area;
        }
    }
    for v in fixed..n {
        if acc_cc[v][2] <= 0.0 {
            continue;
        }
        let odt = [acc_cc[v][0] / acc_cc[v][2], acc_cc[v][1] / acc_cc[v][2]];
        let cpt = [acc_ct[v][0] / acc_ct[v][2], acc_ct[v][1] / acc_ct[v][2]];
        let ok = |q: [f64; 2]| dom.contains(q) && dom.boundary_distance(q) > 0.3 * h;
        if ok(odt) {
            pts[v] = odt;
        } else if ok(cpt) {
            pts[v] = cpt;
        }
    }
}

/// Pattern search on interior vertices whose star has an angle below 40°.
fn improve_angles(pts: &mut [[f64; 2]], faces: &[[u32; 3]], fixed: usize, h: f64) {
    let n = pts.len();
    // Star of every vertex as (other two vertices in counter-clockwise order).
    let mut star: Vec<Vec<[u32; 2]>> = vec![Vec::new(); n];
    for t in faces {
        for i in 0..3 {
            star[t[i] as usize].push([t[(i + 1) % 3], t[(i + 2) % 3]]);
        }
    }
    let up = [0.0, 0.0, 1.0];
    let p3 = |p: [f64; 2]| [p[0], p[1], 0.0];
    let quality = |pts: &[[f64; 2]], v: usize, p: [f64; 2]| {
        star[v]
            .iter()
            .map(|&[x, y]| {
                oriented_min_angle(p3(p), p3(pts[x as usize]), p3(pts[y as usize]), up, 0.0)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let threshold = 40f64.to_radians();
    for v in fixed..n {
        let mut p = pts[v];
        let mut q = quality(pts, v, p);
        if q >= threshold {
            continue;
        }
        let mut step = 0.2 * h;
        while step > 1e-3 * h {
            let mut best = (q, p);
            for k in 0..8 {
                let th = k as f64 * PI / 4.0;
                let c = [p[0] + step * th.cos(), p[1] + step * th.sin()];
                let qc = quality(pts, v, c);
                if qc > best.0 {
                    best = (qc, c);
                }
            }
            if best.0 > q {
                (q, p) = best;
            } else {
                step *= 0.5;
            }
        }
        pts[v] = p;
    }
}
