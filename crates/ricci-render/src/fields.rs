//! Quantities worth looking at, computed from plain slices (positions, triangles, UVs) for
//! pictures: corner angles, angle defect (discrete Gaussian curvature, docs/DESIGN.md §3), pointwise
//! Gaussian and mean curvature (cotangent Laplacian with mixed Voronoi areas, Meyer et al.
//! 2003), the log area distortion of a parameterization (paper 000 Sec. 4, Fig. 10) and corner
//! angle ratios (paper 001 Fig. 7d).
//!
//! These are for visualisation; the `ricci` library has its own intrinsic versions for the
//! flow. Values that do not exist (mean curvature on the boundary, isolated vertices) are NaN
//! and render as grey.

use crate::camera::{cross, dot, norm, sub};
use crate::{check_mesh, input_err, Result};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Interior angle at each corner: corner `3f + i` is at vertex `i` of face `f` (radians).
/// Computed as atan2(|a × b|, a · b), accurate for needle triangles.
pub fn corner_angles(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<f64>> {
    check_mesh(positions, triangles)?;
    let mut out = Vec::with_capacity(3 * triangles.len());
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        for i in 0..3 {
            out.push(angle(p[i], p[(i + 1) % 3], p[(i + 2) % 3]));
        }
    }
    Ok(out)
}

/// Corner angles of a planar layout (one UV per vertex), same order as [`corner_angles`].
pub fn corner_angles_2d(uvs: &[[f64; 2]], triangles: &[[u32; 3]]) -> Result<Vec<f64>> {
    let p: Vec<[f64; 3]> = uvs.iter().map(|q| [q[0], q[1], 0.0]).collect();
    corner_angles(&p, triangles)
}

#[inline]
fn angle(o: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let (u, v) = (sub(a, o), sub(b, o));
    norm(cross(u, v)).atan2(dot(u, v))
}

/// Which vertices lie on the boundary (on an edge with exactly one incident face).
pub fn boundary_vertices(n_vertices: usize, triangles: &[[u32; 3]]) -> Vec<bool> {
    let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut on = vec![false; n_vertices];
    for ((a, b), c) in count {
        if c == 1 {
            on[a as usize] = true;
            on[b as usize] = true;
        }
    }
    on
}

/// Angle defect K_i = 2π − Σθ at interior vertices and π − Σθ on the boundary (the discrete
/// Gaussian curvature the Ricci flow works with; Σ K_i = 2πχ). Isolated vertices get NaN.
pub fn angle_defect(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<f64>> {
    let theta = corner_angles(positions, triangles)?;
    let mut sum = vec![0.0; positions.len()];
    let mut used = vec![false; positions.len()];
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            sum[t[i] as usize] += theta[3 * f + i];
            used[t[i] as usize] = true;
        }
    }
    let bd = boundary_vertices(positions.len(), triangles);
    Ok((0..positions.len())
        .map(|v| {
            if !used[v] {
                f64::NAN
            } else if bd[v] {
                PI - sum[v]
            } else {
                2.0 * PI - sum[v]
            }
        })
        .collect())
}

/// Mixed Voronoi area of each vertex (Meyer, Desbrun, Schröder, Barr 2003): Voronoi area
/// inside non-obtuse triangles, half/quarter of the triangle otherwise. Sums to the total
/// area.
pub fn mixed_areas(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<f64>> {
    check_mesh(positions, triangles)?;
    let mut area = vec![0.0; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let a = 0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        if a <= 0.0 {
            continue;
        }
        let th = [0, 1, 2].map(|i| angle(p[i], p[(i + 1) % 3], p[(i + 2) % 3]));
        let obtuse = th.iter().position(|&x| x > 0.5 * PI);
        for i in 0..3 {
            let add = match obtuse {
                Some(o) if o == i => 0.5 * a,
                Some(_) => 0.25 * a,
                None => {
                    // (|e_ij|² cot θ_k + |e_ik|² cot θ_j) / 8
                    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                    let eij = sub(p[j], p[i]);
                    let eik = sub(p[k], p[i]);
                    (dot(eij, eij) / th[k].tan() + dot(eik, eik) / th[j].tan()) / 8.0
                }
            };
            area[t[i] as usize] += add;
        }
    }
    Ok(area)
}

/// Pointwise Gaussian curvature: angle defect over mixed area (NaN on the boundary).
pub fn gaussian_curvature(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<f64>> {
    let k = angle_defect(positions, triangles)?;
    let a = mixed_areas(positions, triangles)?;
    let bd = boundary_vertices(positions.len(), triangles);
    Ok((0..k.len())
        .map(|v| {
            if bd[v] || a[v] <= 0.0 {
                f64::NAN
            } else {
                k[v] / a[v]
            }
        })
        .collect())
}

/// Mean curvature H = −(Δx · n)/2 with the cotangent Laplace–Beltrami operator and mixed
/// areas; positive where the surface bends away from its outward normal (a sphere of radius
/// r has H = 1/r with outward-oriented faces). NaN on the boundary.
pub fn mean_curvature(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Vec<f64>> {
    let area = mixed_areas(positions, triangles)?;
    let normals = crate::render::vertex_normals(positions, triangles);
    let mut lap = vec![[0.0f64; 3]; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        for k in 0..3 {
            // Edge (i, j) opposite corner k gets weight cot θ_k / 2 in both directions.
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let (u, v) = (sub(p[i], p[k]), sub(p[j], p[k]));
            let s = norm(cross(u, v));
            if s <= 0.0 {
                continue;
            }
            let w = 0.5 * dot(u, v) / s;
            let d = sub(p[j], p[i]);
            for c in 0..3 {
                lap[t[i] as usize][c] += w * d[c];
                lap[t[j] as usize][c] -= w * d[c];
            }
        }
    }
    let bd = boundary_vertices(positions.len(), triangles);
    Ok((0..positions.len())
        .map(|v| {
            if bd[v] || area[v] <= 0.0 {
                f64::NAN
            } else {
                -0.5 * dot(lap[v], normals[v]) / area[v]
            }
        })
        .collect())
}

/// Log area distortion per face of a parameterization with one UV per vertex:
/// `ln(s_f / Σs) − ln(S_f / ΣS)` where S is the area on the surface and s in the plane
/// (the per-face term of paper 000 Sec. 4, normalised so a global scale is no distortion).
/// 0 = area preserved, > 0 = enlarged in the parameter domain. Degenerate faces give NaN.
pub fn area_distortion(
    positions: &[[f64; 3]],
    uvs: &[[f64; 2]],
    triangles: &[[u32; 3]],
) -> Result<Vec<f64>> {
    check_mesh(positions, triangles)?;
    if uvs.len() != positions.len() {
        return input_err(format!(
            "there are {} texture coordinates for {} vertices",
            uvs.len(),
            positions.len()
        ));
    }
    let mut s3 = Vec::with_capacity(triangles.len());
    let mut s2 = Vec::with_capacity(triangles.len());
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        s3.push(0.5 * norm(cross(sub(p[1], p[0]), sub(p[2], p[0]))));
        let q = t.map(|i| uvs[i as usize]);
        let a = 0.5
            * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]))
                .abs();
        s2.push(a);
    }
    let (t3, t2): (f64, f64) = (s3.iter().sum(), s2.iter().sum());
    if !(t3 > 0.0 && t2 > 0.0) {
        return input_err("the surface or its parameterization has zero total area");
    }
    Ok(s3
        .iter()
        .zip(&s2)
        .map(|(&a3, &a2)| {
            if a3 > 0.0 && a2 > 0.0 {
                (a2 / t2).ln() - (a3 / t3).ln()
            } else {
                f64::NAN
            }
        })
        .collect())
}

/// Ratio of each corner angle on the surface to the same corner in the parameterization
/// (paper 001 Fig. 7d: "the ratio of the original angle value and the new one after
/// mapping"); 1 everywhere for a conformal map of a fine mesh.
pub fn angle_ratios(
    positions: &[[f64; 3]],
    uvs: &[[f64; 2]],
    triangles: &[[u32; 3]],
) -> Result<Vec<f64>> {
    if uvs.len() != positions.len() {
        return input_err(format!(
            "there are {} texture coordinates for {} vertices",
            uvs.len(),
            positions.len()
        ));
    }
    let a3 = corner_angles(positions, triangles)?;
    let a2 = corner_angles_2d(uvs, triangles)?;
    Ok(a3
        .iter()
        .zip(&a2)
        .map(|(&x, &y)| if y > 0.0 { x / y } else { f64::NAN })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    #[test]
    fn angle_defect_satisfies_gauss_bonnet() {
        let s = shapes::icosphere(2);
        let k: f64 = angle_defect(&s.positions, &s.triangles)
            .unwrap()
            .iter()
            .sum();
        assert!((k - 4.0 * PI).abs() < 1e-9, "sphere: {k}");
        let t = shapes::torus(2.0, 0.7, 30, 17);
        let k: f64 = angle_defect(&t.positions, &t.triangles)
            .unwrap()
            .iter()
            .sum();
        assert!(k.abs() < 1e-9, "torus: {k}");
        let g = shapes::grid(7, 1.0);
        let k = angle_defect(&g.positions, &g.triangles).unwrap();
        assert!((k.iter().sum::<f64>() - 2.0 * PI).abs() < 1e-9, "disk");
        // A flat grid has no curvature inside; corners of the square carry π/2 each.
        assert!((k[0] - 0.5 * PI).abs() < 1e-12 && k[9 * 4].abs() < 1e-12);
    }

    #[test]
    fn icosahedron_vertices_have_defect_pi_over_3() {
        let s = shapes::icosphere(0);
        for k in angle_defect(&s.positions, &s.triangles).unwrap() {
            assert!((k - PI / 3.0).abs() < 1e-12);
        }
    }

    #[test]
    fn mean_curvature_matches_closed_forms() {
        // Sphere of radius 2: H = 1/2 everywhere (outward faces).
        let mut s = shapes::icosphere(4);
        for p in &mut s.positions {
            *p = p.map(|c| 2.0 * c);
        }
        let h = mean_curvature(&s.positions, &s.triangles).unwrap();
        for v in &h {
            assert!((v - 0.5).abs() < 0.01, "sphere H = {v}");
        }
        // Mixed areas sum to the surface area (4π r² up to discretisation).
        let a: f64 = mixed_areas(&s.positions, &s.triangles)
            .unwrap()
            .iter()
            .sum();
        assert!((a / (16.0 * PI) - 1.0).abs() < 0.01);
        // Torus (R, r) = (2, 0.8): outer equator H = (1/r + 1/(R+r))/2, inner
        // (1/r − 1/(R−r))/2; vertex i*m + j sits at angles (2πi/n, 2πj/m).
        let (n, m) = (240, 120);
        let t = shapes::torus(2.0, 0.8, n, m);
        let h = mean_curvature(&t.positions, &t.triangles).unwrap();
        let outer = 0.5 * (1.0 / 0.8 + 1.0 / 2.8);
        let inner = 0.5 * (1.0 / 0.8 - 1.0 / 1.2);
        assert!((h[0] - outer).abs() < 0.01 * outer, "{} vs {outer}", h[0]);
        assert!(
            (h[m / 2] - inner).abs() < 0.02 * inner,
            "{} vs {inner}",
            h[m / 2]
        );
        // Gaussian curvature at the outer equator: 1/(r (R + r)).
        let k = gaussian_curvature(&t.positions, &t.triangles).unwrap();
        let want = 1.0 / (0.8 * 2.8);
        assert!((k[0] - want).abs() < 0.01 * want, "{} vs {want}", k[0]);
    }

    #[test]
    fn boundary_mean_curvature_is_missing() {
        let g = shapes::grid(4, 1.0);
        let h = mean_curvature(&g.positions, &g.triangles).unwrap();
        assert!(h[0].is_nan());
        assert!(h[2 * 5 + 2].abs() < 1e-12);
    }

    #[test]
    fn distortion_of_similarities_and_stretches() {
        let g = shapes::grid(6, 1.0);
        let sim: Vec<[f64; 2]> = g
            .positions
            .iter()
            .map(|p| [3.0 * p[1] + 1.0, -3.0 * p[0]])
            .collect();
        for d in area_distortion(&g.positions, &sim, &g.triangles).unwrap() {
            assert!(d.abs() < 1e-12);
        }
        for r in angle_ratios(&g.positions, &sim, &g.triangles).unwrap() {
            assert!((r - 1.0).abs() < 1e-12);
        }
        // Stretch x by 2: areas scale uniformly (no distortion), right angles stay right,
        // but the 45° corners become atan(1/2) and atan(2).
        let st: Vec<[f64; 2]> = g.positions.iter().map(|p| [2.0 * p[0], p[1]]).collect();
        for d in area_distortion(&g.positions, &st, &g.triangles).unwrap() {
            assert!(d.abs() < 1e-12);
        }
        let r = angle_ratios(&g.positions, &st, &g.triangles).unwrap();
        let far = r.iter().filter(|x| (*x - 1.0).abs() > 0.1).count();
        assert_eq!(far, 2 * r.len() / 3);
        let want = (PI / 4.0) / 0.5f64.atan();
        assert!(r.iter().any(|x| (x - want).abs() < 1e-12));
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(angle_defect(&[[0.0; 3]], &[[0, 1, 2]]).is_err());
        assert!(angle_defect(&[[f64::NAN, 0.0, 0.0]; 3], &[[0, 1, 2]]).is_err());
        let g = shapes::grid(1, 1.0);
        assert!(area_distortion(&g.positions, &[[0.0; 2]], &g.triangles).is_err());
    }
}
