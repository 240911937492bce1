//! The spline between the input vertices (issue 18): points on the input triangles as extra
//! data for [`super::fit_domain_mesh_on_triangles`] ([`super::DomainFitOptions::between_vertices`]),
//! and the distance of a fitted spline to the triangles between the vertices.

use super::{DomainFit, DomainFitOptions};
use crate::numeric::vec3::{cross, norm, sub};
use crate::spline::surface::MeshDistance;
use crate::spline::tspline::genus_domain::GenusDomain;

/// The data of a fit: targets (the data vertices, then points on the input `triangles`), their
/// weights, the number of vertices among them, and the triangle points.
#[allow(clippy::type_complexity)]
pub(super) fn data(
    domain: &GenusDomain,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    opts: &DomainFitOptions,
) -> (
    Vec<[f64; 3]>,
    Vec<f64>,
    usize,
    Vec<(usize, f64, f64, [f64; 3], f64)>,
) {
    let mut targets: Vec<[f64; 3]> = domain
        .points
        .iter()
        .map(|p| positions[p.vertex as usize])
        .collect();
    let n_vertices = targets.len();
    let extra = triangle_points(domain, positions, triangles, opts.between_vertices);
    let mut weights = vec![1.0; n_vertices];
    targets.extend(extra.iter().map(|e| e.3));
    weights.extend(extra.iter().map(|e| e.4));
    (targets, weights, n_vertices, extra)
}

/// Points on the input triangles whose three vertices are data points of one cylinder: the
/// centroid and the three edge midpoints, at the mean of the vertices' cylinder coordinates
/// (`u` unwrapped across the seam; triangles spanning more than a quarter of the circumference
/// are left out), as `(cylinder, u, v, position, weight)`; weight `w · area / mean area`.
pub fn triangle_points(
    domain: &GenusDomain,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    w: f64,
) -> Vec<(usize, f64, f64, [f64; 3], f64)> {
    if w <= 0.0 || triangles.is_empty() {
        return Vec::new();
    }
    let mut at = vec![usize::MAX; positions.len()];
    for (k, p) in domain.points.iter().enumerate() {
        if let Some(x) = at.get_mut(p.vertex as usize) {
            *x = k;
        }
    }
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        0.5 * norm(cross(sub(b, a), sub(c, a)))
    };
    let mean = triangles.iter().map(area).sum::<f64>() / triangles.len() as f64;
    let mut out = Vec::new();
    for t in triangles {
        let Some(k) = t
            .iter()
            .map(|&v| at.get(v as usize).copied().filter(|&k| k != usize::MAX))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let q = k.iter().map(|&k| domain.points[k]).collect::<Vec<_>>();
        let c = q[0].cylinder;
        if q.iter().any(|p| p.cylinder != c) {
            continue;
        }
        let l = domain.cylinders[c].circumference;
        let u: Vec<f64> = q
            .iter()
            .map(|p| q[0].u + (p.u - q[0].u + 0.5 * l).rem_euclid(l) - 0.5 * l)
            .collect();
        // a cylinder glued to itself: a triangle across that trajectory has `v` near 0 and `H`
        let h = domain.cylinders[c].height;
        if u.iter().any(|x| (x - u[0]).abs() > 0.25 * l)
            || q.iter().any(|p| (p.v - q[0].v).abs() > 0.25 * h)
        {
            continue;
        }
        let x = t.map(|v| positions[v as usize]);
        // the cylinder coordinates must be close to an affine image of the triangle (not so
        // around a zero, where the chart is branched): same orientation as the majority, and
        // the edges' lengths over their lengths in the chart within a factor 1.5 of each other
        let (du, dv) = (
            [u[1] - u[0], u[2] - u[0]],
            [q[1].v - q[0].v, q[2].v - q[0].v],
        );
        let signed = du[0] * dv[1] - du[1] * dv[0];
        let ratios: Vec<f64> = [(0, 1), (1, 2), (2, 0)]
            .iter()
            .map(|&(i, j)| norm(sub(x[i], x[j])) / (u[i] - u[j]).hypot(q[i].v - q[j].v).max(1e-300))
            .collect();
        let (lo, hi) = ratios
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
        if hi > 1.5 * lo || !hi.is_finite() {
            continue;
        }
        let wt = w * area(t) / mean.max(1e-300);
        let all = [
            [1.0 / 3.0; 3],
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
        ];
        for bary in all.iter() {
            let ub: f64 = (0..3).map(|i| bary[i] * u[i]).sum();
            let vb: f64 = (0..3).map(|i| bary[i] * q[i].v).sum();
            let p = std::array::from_fn(|d| (0..3).map(|i| bary[i] * x[i][d]).sum());
            out.push((c, ub.rem_euclid(l), vb, p, wt, signed > 0.0));
        }
    }
    // orientation: the charts of a holomorphic form keep it, so the minority is wrong
    let positive = out.iter().filter(|e| e.5).count();
    let keep = 2 * positive >= out.len();
    let out: Vec<_> = out
        .into_iter()
        .filter(|e| e.5 == keep)
        .map(|e| (e.0, e.1, e.2, e.3, e.4))
        .collect();
    out
}

/// Per cell, the largest distance of the spline to the input triangles at `k × k` points of
/// the cell (`((i + ½)/k, (j + ½)/k)`), and where: `(distance, s, t)` (distance in the
/// positions' units, `(s, t) ∈ [0, 1]²` the cell's local coordinates).
pub fn deviation_per_cell(
    fit: &DomainFit,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    k: usize,
) -> Vec<(f64, f64, f64)> {
    deviation_samples(fit, positions, triangles, k)
        .chunks(k.max(1) * k.max(1))
        .map(|d| {
            d.iter()
                .fold((0.0f64, 0.0, 0.0), |a, &b| if b.0 > a.0 { b } else { a })
        })
        .collect()
}

/// The distance of the spline to the triangles at the `k × k` points of every cell (cell
/// order, then the points), with the points' local coordinates.
fn deviation_samples(
    fit: &DomainFit,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    k: usize,
) -> Vec<(f64, f64, f64)> {
    use rayon::prelude::*;
    let k = k.max(1);
    let dist = MeshDistance::new(positions, triangles);
    (0..fit.mesh.n_cells() as u32)
        .into_par_iter()
        .flat_map_iter(|c| {
            let dist = &dist;
            // the cell's Bézier patch once, then its points
            let p = fit.mesh.patch(c, &fit.control, 0.0, 0.0);
            (0..k * k).map(move |ij| {
                let (s, t) = (
                    ((ij % k) as f64 + 0.5) / k as f64,
                    ((ij / k) as f64 + 0.5) / k as f64,
                );
                let x = p.point(p.u0 + s * (p.u1 - p.u0), p.v0 + t * (p.v1 - p.v0));
                (dist.distance(x), s, t)
            })
        })
        .collect()
}

/// Distance of the spline to the input triangles between the vertices: the fitted surface at
/// `k × k` points of every cell (`((i + ½)/k, (j + ½)/k)`) to the closest point of the
/// triangles (exact point–triangle distance, [`MeshDistance`]); `(max, rms)` in percent of the
/// longest bounding-box side ([`DomainFit::scale`]).
pub fn deviation_between_vertices(
    fit: &DomainFit,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    k: usize,
) -> (f64, f64) {
    let d = deviation_samples(fit, positions, triangles, k);
    let max = d.iter().fold(0.0f64, |a, b| a.max(b.0));
    let rms = (d.iter().map(|x| x.0 * x.0).sum::<f64>() / d.len().max(1) as f64).sqrt();
    let s = 100.0 / fit.scale.max(1e-300);
    (max * s, rms * s)
}
