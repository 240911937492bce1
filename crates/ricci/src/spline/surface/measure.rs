//! Step 3 of the manifold spline surface (paper 000 §5, Table 1): the measurements — the
//! continuity of the spline across the domain's edges and seams, and distances from spline
//! samples to the input mesh.

use crate::atlas::FlatCharts;
use crate::error::{Error, Result};
use crate::spline::dms::Workspace;
use crate::spline::hole::{Hole, SeamReport};
use crate::spline::manifold::{apply, rotate_partials, ManifoldSpace};
use crate::spline::simplex::{n_partials, Point};
use crate::spline::space::evaluate;

/// Measured jumps across the interior edges of the spline domain.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ContinuityReport {
    /// Sample points (three per interior edge between active faces).
    pub samples: usize,
    /// Per order `k = 0..=n`: the largest jump of a partial of order `k`, relative to the
    /// largest such partial over all samples.
    pub relative_jumps: Vec<f64>,
    /// Largest `k` with all relative jumps of orders `≤ k` below `tolerance` (`C^k`).
    pub smoothness: Option<usize>,
    pub tolerance: f64,
    /// Edges whose two faces have different canonical charts (sampled chart boundaries).
    pub chart_boundary_edges: usize,
    /// Fill patches: the seam measurements.
    pub seams: Vec<SeamReport>,
    /// Largest normal-angle jump along any seam (degrees).
    pub max_seam_normal_jump_deg: f64,
    /// `"C^k"` plus `", G^1 fill"` when there are fill patches.
    pub class: String,
}

/// Step 3: the continuity of `control`'s spline (module docs). `tolerance` is the relative
/// jump below which an order counts as continuous (1e-8 in the tests).
pub fn continuity<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    control: &[f64],
    holes: &[Hole],
    tolerance: f64,
) -> Result<ContinuityReport> {
    use rayon::prelude::*;
    let n = space.degree();
    let np = n_partials(n);
    let charts = space.charts();
    let mesh = charts.mesh();
    let edges: Vec<(u32, u32, u32)> = (0..mesh.n_corners() as u32)
        .filter_map(|h| {
            let t = mesh.he_twin(h);
            if mesh.is_boundary_halfedge(t) || t < h {
                return None;
            }
            let (g1, g2) = (h / 3, t / 3);
            (space.is_active(g1) && space.is_active(g2)).then_some((h, g1, g2))
        })
        .collect();
    let boundary_edges = edges
        .iter()
        .filter(|(_, a, b)| space.canonical_chart(*a) != space.canonical_chart(*b))
        .count();
    // Per edge sample: the two limits in g1's canonical chart.
    let per: Vec<Vec<(Vec<f64>, Vec<f64>)>> = edges
        .par_iter()
        .map(|&(h, g1, g2)| -> Result<Vec<(Vec<f64>, Vec<f64>)>> {
            let mut ws = Workspace::default();
            let i = h as usize % 3;
            let c1 = space.canonical_coords(g1);
            let c2 = space.canonical_coords(g2);
            let t = mesh.he_twin(h) as usize % 3;
            let mut out = Vec::new();
            for s in [0.25, 0.5, 0.75] {
                let mut b1 = [0.0; 3];
                b1[i] = 1.0 - s;
                b1[(i + 1) % 3] = s;
                let mut b2 = [0.0; 3];
                b2[(t + 1) % 3] = 1.0 - s;
                b2[t] = s;
                let u1: Point = std::array::from_fn(|k| (0..3).map(|m| b1[m] * c1[m][k]).sum());
                let u2: Point = std::array::from_fn(|k| (0..3).map(|m| b2[m] * c2[m][k]).sum());
                let mut a = vec![0.0; np * 3];
                evaluate(space, control, 3, g1, u1, n, &mut ws, &mut a)?;
                let mut b = vec![0.0; np * 3];
                evaluate(space, control, 3, g2, u2, n, &mut ws, &mut b)?;
                // g2's canonical chart → g1's: transition on g2.
                let (m, _) = charts
                    .transition(space.canonical_chart(g1), space.canonical_chart(g2), g2)
                    .ok_or_else(|| {
                        Error::input(format!(
                            "continuity: face {g2} is not in the canonical chart of face {g1}"
                        ))
                    })?;
                debug_assert!({
                    let w = apply(&m, u1);
                    (w[0] - u2[0]).hypot(w[1] - u2[1]) < 1e-6 * (1.0 + u2[0].abs() + u2[1].abs())
                });
                // b holds partials w.r.t. g2's chart coordinates w = m(u): rotate into u.
                let mut bt = vec![0.0; np * 3];
                for d in 0..3 {
                    let mut col: Vec<f64> = (0..np).map(|k| b[k * 3 + d]).collect();
                    rotate_partials(n, m.rot, &mut col);
                    for k in 0..np {
                        bt[k * 3 + d] = col[k];
                    }
                }
                out.push((a, bt));
            }
            Ok(out)
        })
        .collect::<Result<_>>()?;
    let mut scale = vec![0.0f64; n + 1];
    let mut jump = vec![0.0f64; n + 1];
    let mut samples = 0;
    for e in &per {
        for (a, b) in e {
            samples += 1;
            for k in 0..=n {
                for idx in n_partials(k) - (k + 1)..n_partials(k) {
                    for d in 0..3 {
                        let (x, y) = (a[idx * 3 + d], b[idx * 3 + d]);
                        scale[k] = scale[k].max(x.abs()).max(y.abs());
                        jump[k] = jump[k].max((x - y).abs());
                    }
                }
            }
        }
    }
    let relative_jumps: Vec<f64> = jump
        .iter()
        .zip(&scale)
        .map(|(j, s)| if *s > 0.0 { j / s } else { 0.0 })
        .collect();
    let mut smoothness = None;
    for (k, &j) in relative_jumps.iter().enumerate() {
        if j <= tolerance {
            smoothness = Some(k);
        } else {
            break;
        }
    }
    let mut seams = Vec::new();
    for h in holes {
        seams.push(h.seam_normal_jump(space, control, 360)?);
    }
    let max_seam = seams
        .iter()
        .map(|s| s.max_normal_jump_deg)
        .fold(0.0, f64::max);
    let mut class = match smoothness {
        Some(k) => format!("C^{k}"),
        None => "discontinuous".to_string(),
    };
    if !seams.is_empty() {
        class.push_str(", G^1 fill");
    }
    Ok(ContinuityReport {
        samples,
        relative_jumps,
        smoothness,
        tolerance,
        chart_boundary_edges: boundary_edges,
        seams,
        max_seam_normal_jump_deg: max_seam,
        class,
    })
}

/// Distances from points to a triangle mesh (exact point–triangle distance, uniform grid of
/// the triangles' bounding boxes).
pub struct MeshDistance {
    tris: Vec<[[f64; 3]; 3]>,
    lo: [f64; 3],
    /// Upper corner of the triangles' bounding box (the grid may end before it: at most 512
    /// cells per axis, the last one holding the rest).
    hi: [f64; 3],
    cell: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
    /// Bounding-box diagonal of the mesh.
    pub diagonal: f64,
}

use crate::numeric::vec3::{dot as dot3, sub as sub3};

/// Distance from `p` to triangle `t` (Ericson, *Real-Time Collision Detection*, 5.1.5).
pub fn point_triangle_distance(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    let [a, b, c] = *t;
    let ab = sub3(b, a);
    let ac = sub3(c, a);
    let ap = sub3(p, a);
    let d1 = dot3(ab, ap);
    let d2 = dot3(ac, ap);
    let q = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub3(p, b);
        let d3 = dot3(ab, bp);
        let d4 = dot3(ac, bp);
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else {
            let vc = d1 * d4 - d3 * d2;
            if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
                let v = d1 / (d1 - d3);
                [a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]]
            } else {
                let cp = sub3(p, c);
                let d5 = dot3(ab, cp);
                let d6 = dot3(ac, cp);
                if d6 >= 0.0 && d5 <= d6 {
                    c
                } else {
                    let vb = d5 * d2 - d1 * d6;
                    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
                        let w = d2 / (d2 - d6);
                        [a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]]
                    } else {
                        let va = d3 * d6 - d5 * d4;
                        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
                            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
                            let bc = sub3(c, b);
                            [b[0] + w * bc[0], b[1] + w * bc[1], b[2] + w * bc[2]]
                        } else {
                            let denom = 1.0 / (va + vb + vc);
                            let v = vb * denom;
                            let w = vc * denom;
                            [
                                a[0] + ab[0] * v + ac[0] * w,
                                a[1] + ab[1] * v + ac[1] * w,
                                a[2] + ab[2] * v + ac[2] * w,
                            ]
                        }
                    }
                }
            }
        }
    };
    let d = sub3(p, q);
    dot3(d, d).sqrt()
}

impl MeshDistance {
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> MeshDistance {
        let tris: Vec<[[f64; 3]; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| positions[v as usize]))
            .collect();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut mean = 0.0;
        for t in &tris {
            for p in t {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            mean += dot3(sub3(t[1], t[0]), sub3(t[1], t[0])).sqrt();
        }
        mean /= tris.len().max(1) as f64;
        let diagonal = dot3(sub3(hi, lo), sub3(hi, lo)).sqrt();
        let cell = (2.0 * mean).max(diagonal / 256.0).max(1e-300);
        let dims: [usize; 3] =
            std::array::from_fn(|k| (((hi[k] - lo[k]) / cell).floor() as usize + 1).min(512));
        let cidx =
            |p: f64, k: usize| (((p - lo[k]) / cell).floor().max(0.0) as usize).min(dims[k] - 1);
        let ncell = dims[0] * dims[1] * dims[2];
        let mut count = vec![0u32; ncell + 1];
        let ranges: Vec<[usize; 6]> = tris
            .iter()
            .map(|t| {
                let mut r = [0usize; 6];
                for k in 0..3 {
                    let a = t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
                    let b = t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
                    r[2 * k] = cidx(a, k);
                    r[2 * k + 1] = cidx(b, k);
                }
                r
            })
            .collect();
        let cell_of = |x: usize, y: usize, z: usize| (z * dims[1] + y) * dims[0] + x;
        for r in &ranges {
            for z in r[4]..=r[5] {
                for y in r[2]..=r[3] {
                    for x in r[0]..=r[1] {
                        count[cell_of(x, y, z) + 1] += 1;
                    }
                }
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[ncell] as usize];
        for (ti, r) in ranges.iter().enumerate() {
            for z in r[4]..=r[5] {
                for y in r[2]..=r[3] {
                    for x in r[0]..=r[1] {
                        let c = cell_of(x, y, z);
                        items[fill[c] as usize] = ti as u32;
                        fill[c] += 1;
                    }
                }
            }
        }
        MeshDistance {
            tris,
            lo,
            hi,
            cell,
            dims,
            start: count,
            items,
            diagonal,
        }
    }

    /// Distance from `p` to the mesh (searches growing shells of grid cells); NaN for a point
    /// that is not finite.
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        if p.iter().any(|x| !x.is_finite()) {
            // (no cell is near it: the search below would visit every shell of the grid)
            return f64::NAN;
        }
        // Start from the nearest cell of the grid (points outside the box are clamped in; the
        // shell bound below then loses one cell, hence `r − 1`).
        let c: [i64; 3] = std::array::from_fn(|k| {
            (((p[k] - self.lo[k]) / self.cell).floor() as i64).clamp(0, self.dims[k] as i64 - 1)
        });
        let mut best = f64::INFINITY;
        let maxr = self.dims.iter().copied().max().unwrap_or(1) as i64 + 1;
        for r in 0..=maxr {
            // The cells of the shell inside the grid: whole rows where y or z is on the shell,
            // else the row's two ends in x (O(r²) cells per shell, not the (2r + 1)³ of the
            // block: a point far outside the box visited ~r⁴ cells).
            let dx = self.dims[0] as i64;
            let within = |k: usize| (c[k] - r).max(0)..=(c[k] + r).min(self.dims[k] as i64 - 1);
            for z in within(2) {
                for y in within(1) {
                    let face = (z - c[2]).abs() == r || (y - c[1]).abs() == r;
                    let (step, mut x, end) = if face {
                        (1, (c[0] - r).max(0), (c[0] + r).min(dx - 1))
                    } else {
                        (2 * r, c[0] - r, c[0] + r)
                    };
                    while x <= end {
                        if (0..dx).contains(&x) {
                            let cell = (z as usize * self.dims[1] + y as usize) * self.dims[0]
                                + x as usize;
                            let (a, b) = (self.start[cell] as usize, self.start[cell + 1] as usize);
                            for &t in &self.items[a..b] {
                                best = best.min(point_triangle_distance(p, &self.tris[t as usize]));
                            }
                        }
                        x += step;
                    }
                }
            }
            // Every triangle not yet seen is at least r cells away.
            if best <= (r as f64 - 1.0).max(0.0) * self.cell {
                break;
            }
            // Sharper: a triangle not yet seen lies in cells outside the block of cells within
            // r of `c`, so in some axis k beyond one of the block's faces that still has cells
            // behind it, and inside the bounding box in the other axes: it is at least
            // sqrt(gap_k² + Σ_{j≠k} out_j²) from `p` (`out_j`: how far `p` lies outside the box
            // in axis j), less a margin for the rounding of cell indices. Most points inside
            // stop after one cell instead of 5³, far points once the shells reach the
            // surface's near side; every cell seen: no face left, the search ends.
            let out: [f64; 3] =
                std::array::from_fn(|k| (self.lo[k] - p[k]).max(p[k] - self.hi[k]).max(0.0));
            let gap = (0..3)
                .map(|k| {
                    let below = self.lo[k] + (c[k] - r) as f64 * self.cell;
                    let above = self.lo[k] + (c[k] + r + 1) as f64 * self.cell;
                    let mut g = f64::INFINITY;
                    if c[k] - r > 0 {
                        g = g.min(p[k] - below);
                    }
                    if c[k] + r < self.dims[k] as i64 - 1 {
                        g = g.min(above - p[k]);
                    }
                    let g = g.max(0.0);
                    let o: f64 = (0..3).filter(|&j| j != k).map(|j| out[j] * out[j]).sum();
                    (g * g + o).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            if best <= gap - 1e-9 * (self.cell + self.diagonal) || gap == f64::INFINITY {
                break;
            }
        }
        best
    }
}

/// RMS and maximum distance of `points` to the mesh, in percent of its bounding-box diagonal.
pub fn error_percent(dist: &MeshDistance, points: &[[f64; 3]]) -> (f64, f64) {
    use rayon::prelude::*;
    let d: Vec<f64> = points.par_iter().map(|&p| dist.distance(p)).collect();
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
    let max = d.iter().fold(0.0f64, |a, &b| a.max(b));
    let s = 100.0 / dist.diagonal.max(1e-300);
    (rms * s, max * s)
}
