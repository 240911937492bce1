//! Distortion of a map from a triangulated surface in R³ to the plane (a UV map), face by face.
//!
//! On face `f` the map is the affine map `J_f` taking the 3D triangle (in an orthonormal frame
//! of its plane) to its UV triangle. Its singular values `σ_max ≥ σ_min` give
//!
//! * the **quasi-conformal ratio** `qc_f = σ_max / σ_min` (1 for a similarity: a conformal map
//!   of the face; Hormann–Greiner 2000, Sawhney–Crane 2017 §7 report the same ratio);
//! * the **area ratio** `det J_f = σ_max σ_min · sign = A_uv / A_3d` (signed: a face whose UV
//!   triangle is clockwise has `det J_f < 0` and is *flipped*).
//!
//! The 2×2 singular values are computed in closed form: with `J = [[a, b], [c, d]]`,
//! `E = (a + d)/2`, `F = (a − d)/2`, `G = (c + b)/2`, `H = (c − b)/2`, `Q = √(E² + H²)`,
//! `R = √(F² + G²)`: `σ_max = Q + R`, `σ_min = |Q − R|`, `det J = Q² − R²` (Blinn's
//! decomposition into a similarity and an anti-similarity).
//!
//! [`DistortionStats`] summarises a map: flipped and degenerate faces, `qc` mean / 95th
//! percentile / max over the faces that are not flipped, and the area-weighted standard
//! deviation of `log(A_uv/A_3d)` (invariant under a global scale of the UVs; 0 for a map
//! that scales every face alike).

use serde::Serialize;

/// Per-face distortion of one face (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FaceDistortion {
    pub sigma_max: f64,
    pub sigma_min: f64,
    /// Signed `A_uv / A_3d` (negative: flipped).
    pub area_ratio: f64,
    /// Area of the 3D triangle.
    pub area_3d: f64,
}

impl FaceDistortion {
    /// `σ_max / σ_min` (infinite for a degenerate UV triangle).
    pub fn qc(&self) -> f64 {
        if self.sigma_min > 0.0 {
            self.sigma_max / self.sigma_min
        } else {
            f64::INFINITY
        }
    }
    pub fn flipped(&self) -> bool {
        self.area_ratio <= 0.0
    }
}

/// Singular values and signed determinant of the 2×2 matrix `[[a, b], [c, d]]`.
pub fn singular_values_2x2(a: f64, b: f64, c: f64, d: f64) -> (f64, f64, f64) {
    let e = 0.5 * (a + d);
    let f = 0.5 * (a - d);
    let g = 0.5 * (c + b);
    let h = 0.5 * (c - b);
    let q = e.hypot(h);
    let r = f.hypot(g);
    (q + r, (q - r).abs(), a * d - b * c)
}

/// The distortion of the affine map taking triangle `p` (R³) to triangle `q` (plane).
/// A degenerate 3D triangle gives `area_3d = 0` and NaN singular values.
pub fn face_distortion(p: [[f64; 3]; 3], q: [[f64; 2]; 3]) -> FaceDistortion {
    let e1 = sub3(p[1], p[0]);
    let e2 = sub3(p[2], p[0]);
    let l1 = norm3(e1);
    let x2 = dot3(e2, e1) / l1;
    let cr = cross3(e1, e2);
    let twice_area = norm3(cr);
    let y2 = twice_area / l1;
    let area_3d = 0.5 * twice_area;
    if !(l1 > 0.0 && y2 > 0.0) {
        return FaceDistortion {
            sigma_max: f64::NAN,
            sigma_min: f64::NAN,
            area_ratio: f64::NAN,
            area_3d: 0.0,
        };
    }
    // X = [[l1, x2], [0, y2]] (columns: the 3D edges in the frame), U = [[u1, u2], [v1, v2]].
    let u1 = q[1][0] - q[0][0];
    let v1 = q[1][1] - q[0][1];
    let u2 = q[2][0] - q[0][0];
    let v2 = q[2][1] - q[0][1];
    // J = U X⁻¹, X⁻¹ = [[1/l1, −x2/(l1 y2)], [0, 1/y2]].
    let a = u1 / l1;
    let b = (u2 - u1 * x2 / l1) / y2;
    let c = v1 / l1;
    let d = (v2 - v1 * x2 / l1) / y2;
    let (smax, smin, det) = singular_values_2x2(a, b, c, d);
    FaceDistortion {
        sigma_max: smax,
        sigma_min: smin,
        area_ratio: det,
        area_3d,
    }
}

/// Summary of a UV map's distortion (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DistortionStats {
    pub faces: usize,
    /// Faces whose UV triangle has non-positive signed area.
    pub flipped_faces: usize,
    /// Faces whose 3D triangle has zero area (not measured).
    pub degenerate_3d_faces: usize,
    pub qc_mean: f64,
    pub qc_p95: f64,
    pub qc_max: f64,
    /// Mean of qc weighted by 3D face area (the surface's average, whatever the triangle
    /// sizes; on a common subdivision its slivers count by their area, not as whole faces).
    pub qc_mean_area: f64,
    /// The qc below which 95 % of the measured 3D area lies (area-weighted p95).
    pub qc_p95_area: f64,
    /// Area-weighted standard deviation of `log(A_uv/A_3d)` over the faces not flipped.
    pub log_area_sigma: f64,
    /// Largest `|log(A_uv/A_3d) − mean|` over the faces not flipped.
    pub log_area_max: f64,
}

/// Per-face distortion of corner UVs (`corner_uv[3f + i]` for corner `i` of face `f`); the
/// faces are measured in parallel (each independently, so the same values in face order).
pub fn face_distortions(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    corner_uv: &[[f64; 2]],
) -> Vec<FaceDistortion> {
    use rayon::prelude::*;
    faces
        .par_iter()
        .enumerate()
        .map(|(f, t)| {
            let p = [
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            ];
            let q = [corner_uv[3 * f], corner_uv[3 * f + 1], corner_uv[3 * f + 2]];
            face_distortion(p, q)
        })
        .collect()
}

/// [`DistortionStats::qc_p95`] of per-face distortions alone, by selection instead of a sort
/// (the same order statistic: the qc at rank `round(0.95 (n − 1))` of the `n` faces measured).
pub fn qc_p95(d: &[FaceDistortion]) -> f64 {
    let mut qc: Vec<f64> = d
        .iter()
        .filter(|x| !(x.area_3d.is_nan() || x.area_3d <= 0.0 || x.flipped()))
        .map(|x| x.qc())
        .collect();
    let n = qc.len();
    if n == 0 {
        return f64::NAN;
    }
    let k = ((0.95 * (n - 1) as f64).round() as usize).min(n - 1);
    *qc.select_nth_unstable_by(k, f64::total_cmp).1
}

/// [`DistortionStats`] of per-face distortions.
pub fn stats(d: &[FaceDistortion]) -> DistortionStats {
    use rayon::slice::ParallelSliceMut;
    let mut qc = Vec::with_capacity(d.len());
    let mut qc_area: Vec<(f64, f64)> = Vec::with_capacity(d.len());
    let mut flipped = 0;
    let mut degenerate = 0;
    let (mut w, mut s1) = (0.0, 0.0);
    for x in d {
        if x.area_3d.is_nan() || x.area_3d <= 0.0 {
            degenerate += 1;
            continue;
        }
        if x.flipped() {
            flipped += 1;
            continue;
        }
        qc.push(x.qc());
        qc_area.push((x.qc(), x.area_3d));
        w += x.area_3d;
        s1 += x.area_3d * x.area_ratio.ln();
    }
    let mean = if w > 0.0 { s1 / w } else { 0.0 };
    let (mut s2, mut lmax) = (0.0f64, 0.0f64);
    for x in d {
        if x.area_3d > 0.0 && !x.flipped() {
            let dl = x.area_ratio.ln() - mean;
            s2 += x.area_3d * dl * dl;
            lmax = lmax.max(dl.abs());
        }
    }
    // Values equal under `total_cmp` are the same bits: any sort gives the same order.
    qc.par_sort_unstable_by(f64::total_cmp);
    let n = qc.len();
    let p95 = if n == 0 {
        f64::NAN
    } else {
        qc[((0.95 * (n - 1) as f64).round() as usize).min(n - 1)]
    };
    let (qc_mean_area, qc_p95_area) = area_weighted_qc(&mut qc_area, w);
    DistortionStats {
        faces: d.len(),
        flipped_faces: flipped,
        degenerate_3d_faces: degenerate,
        qc_mean: if n == 0 {
            f64::NAN
        } else {
            qc.iter().sum::<f64>() / n as f64
        },
        qc_p95: p95,
        qc_max: qc.last().copied().unwrap_or(f64::NAN),
        qc_mean_area,
        qc_p95_area,
        log_area_sigma: if w > 0.0 { (s2 / w).sqrt() } else { f64::NAN },
        log_area_max: lmax,
    }
}

/// Area-weighted mean and p95 of `(qc, area)` pairs (`total` their area): the p95 is the
/// smallest qc such that the faces with qc at most it cover ≥ 95 % of the area.
fn area_weighted_qc(qc_area: &mut [(f64, f64)], total: f64) -> (f64, f64) {
    use rayon::slice::ParallelSliceMut;
    if qc_area.is_empty() || total <= 0.0 {
        return (f64::NAN, f64::NAN);
    }
    let mean = qc_area.iter().map(|&(q, a)| q * a).sum::<f64>() / total;
    qc_area.par_sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut acc = 0.0;
    for &(q, a) in qc_area.iter() {
        acc += a;
        if acc >= 0.95 * total {
            return (mean, q);
        }
    }
    (mean, qc_area[qc_area.len() - 1].0)
}

/// [`stats`] of corner UVs on a surface.
pub fn uv_stats(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    corner_uv: &[[f64; 2]],
) -> DistortionStats {
    stats(&face_distortions(positions, faces, corner_uv))
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm3(a: [f64; 3]) -> f64 {
    dot3(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`qc_p95`] by selection equals [`stats`]' sorted one, with degenerate and flipped faces
    /// among the measured ones (both skipped) and ties.
    #[test]
    fn qc_p95_by_selection_equals_the_sorted_one() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, 0.8, 0.0]];
        let d: Vec<FaceDistortion> = (0..203)
            .map(|i| {
                let s = 1.0 + ((i * 37) % 23) as f64 * 0.1;
                let q = [
                    [0.0, 0.0],
                    [s, 0.0],
                    [0.3, 0.8 * if i % 17 == 0 { -1.0 } else { 1.0 }],
                ];
                let flat = [p[0], p[1], if i % 29 == 0 { p[1] } else { p[2] }];
                face_distortion(flat, q)
            })
            .collect();
        assert!(d.iter().any(|x| x.flipped()) && d.iter().any(|x| x.area_3d == 0.0));
        for len in [0, 1, 2, 50, 203] {
            let (a, b) = (qc_p95(&d[..len]), stats(&d[..len]).qc_p95);
            assert!(a == b || (a.is_nan() && b.is_nan()), "{len}: {a} vs {b}");
        }
    }

    /// Singular values against the eigenvalues of JᵀJ (closed form of a symmetric 2×2).
    #[test]
    fn singular_values_match_the_eigenvalues_of_jtj() {
        let mut s = 0x9e3779b97f4a7c15u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..1000 {
            let (a, b, c, d) = (rnd(), rnd(), rnd(), rnd());
            let (smax, smin, det) = singular_values_2x2(a, b, c, d);
            let (p, q, r) = (a * a + c * c, a * b + c * d, b * b + d * d);
            let disc = (0.25 * (p - r) * (p - r) + q * q).sqrt();
            let l1 = 0.5 * (p + r) + disc;
            let l2 = (0.5 * (p + r) - disc).max(0.0);
            assert!((smax - l1.sqrt()).abs() < 1e-12 * (1.0 + smax));
            assert!((smin - l2.sqrt()).abs() < 1e-6 * (1.0 + smax));
            assert!((smax * smin - det.abs()).abs() < 1e-12 * (1.0 + smax * smax));
        }
    }

    /// A similarity (rotation, scale 2, translation) of a 3D triangle: qc = 1, area ratio 4;
    /// its mirror image is flipped; a stretch by 3 along one axis has qc = 3.
    #[test]
    fn similarities_stretches_and_mirrors() {
        let p = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.3, 0.7, 1.0]];
        let (c, s) = (0.6f64, 0.8f64);
        let sim = |x: [f64; 3]| {
            [
                2.0 * (c * x[0] - s * x[1]) + 5.0,
                2.0 * (s * x[0] + c * x[1]),
            ]
        };
        let d = face_distortion(p, [sim(p[0]), sim(p[1]), sim(p[2])]);
        assert!((d.qc() - 1.0).abs() < 1e-12);
        assert!((d.area_ratio - 4.0).abs() < 1e-12);
        let mirror = |x: [f64; 3]| [x[0], -x[1]];
        let m = face_distortion(p, [mirror(p[0]), mirror(p[1]), mirror(p[2])]);
        assert!(m.flipped() && (m.area_ratio + 1.0).abs() < 1e-12);
        let st = |x: [f64; 3]| [3.0 * x[0], x[1]];
        let t = face_distortion(p, [st(p[0]), st(p[1]), st(p[2])]);
        assert!((t.qc() - 3.0).abs() < 1e-12);
        let all = stats(&[d, m, t]);
        assert_eq!(all.flipped_faces, 1);
        assert!((all.qc_max - 3.0).abs() < 1e-12);
    }
}
