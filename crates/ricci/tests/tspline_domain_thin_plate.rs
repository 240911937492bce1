//! The genus ≥ 2 domain-mesh fit with the thin-plate fairness (`DomainFitOptions::thin_plate`,
//! issue 18, paper 003 §3.3) on genus3.off (with `$RICCI_MESHES`): the spline between the
//! vertices — measured here, not by the library: the spline from its blending functions at
//! 3 × 3 points of every cell to the input triangles (closest points computed here, triangles
//! bucketed in a grid) — is within 3 % of the bounding box (the second differences alone: 6.4 %),
//! the vertices within the 0.5 % tolerance (recomputed from the Bézier patches), and the T-spline
//! is still C² off the zeros and G¹ at them (`check_t_spline`).

mod ricci_meshes;
mod tspline_cases;

use crate::tspline_domain_mesh::{check_t_spline, Rng};
use ricci::spline::tspline::domain_fit::{fit_domain_mesh_on_triangles, DomainFitOptions};
use ricci::spline::tspline::fit::bbox_scale;
use std::collections::HashMap;
use tspline_cases::{glued_domain, max_vertex_error};

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The closest point of triangle `abc` to `p` (Ericson, Real-Time Collision Detection §5.1.5).
fn closest_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let at = |x: [f64; 3], d: [f64; 3], t: f64| [x[0] + t * d[0], x[1] + t * d[1], x[2] + t * d[2]];
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(a, ab, d1 / (d1 - d3));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(a, ac, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return at(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ]
}

/// Distances up to `reach` to the triangles: each triangle in the grid cells (side `reach`)
/// its bounding box grown by `reach` meets; a point farther than `reach` from every triangle
/// gets `f64::INFINITY`.
struct Near<'a> {
    positions: &'a [[f64; 3]],
    triangles: &'a [[u32; 3]],
    reach: f64,
    grid: HashMap<[i64; 3], Vec<usize>>,
}

impl<'a> Near<'a> {
    fn new(positions: &'a [[f64; 3]], triangles: &'a [[u32; 3]], reach: f64) -> Self {
        let key = |x: f64| (x / reach).floor() as i64;
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            let p = tri.map(|v| positions[v as usize]);
            let lo: [i64; 3] = std::array::from_fn(|d| {
                key(p.iter().map(|x| x[d]).fold(f64::INFINITY, f64::min) - reach)
            });
            let hi: [i64; 3] = std::array::from_fn(|d| {
                key(p.iter().map(|x| x[d]).fold(f64::NEG_INFINITY, f64::max) + reach)
            });
            for i in lo[0]..=hi[0] {
                for j in lo[1]..=hi[1] {
                    for k in lo[2]..=hi[2] {
                        grid.entry([i, j, k]).or_default().push(t);
                    }
                }
            }
        }
        Near {
            positions,
            triangles,
            reach,
            grid,
        }
    }

    fn distance(&self, p: [f64; 3]) -> f64 {
        let k = p.map(|x| (x / self.reach).floor() as i64);
        let mut best = f64::INFINITY;
        for &t in self.grid.get(&k).map_or(&[][..], |v| &v[..]) {
            let [a, b, c] = self.triangles[t].map(|v| self.positions[v as usize]);
            let q = closest_on_triangle(p, a, b, c);
            best = best.min(dot(sub(p, q), sub(p, q)).sqrt());
        }
        if best <= self.reach {
            best
        } else {
            f64::INFINITY
        }
    }
}

#[test]
fn genus3_with_the_thin_plate_stays_near_the_triangles_between_the_vertices() {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES is not set: genus3.off skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join("genus3.off"))
        .unwrap()
        .0;
    let (d, g, _) = glued_domain(&s);
    let side = bbox_scale(&s.positions);
    let opts = DomainFitOptions {
        thin_plate: 0.1,
        ..DomainFitOptions::default()
    };
    let tris = s.mesh.faces();
    let f = fit_domain_mesh_on_triangles(&d, &g, &s.positions, tris, &opts).unwrap();
    let vertex = max_vertex_error(&d, &f, &s.positions) / side;
    // the spline from its blending functions (not the library's Bézier patches) at 3 × 3
    // points of every cell
    let near = Near::new(&s.positions, tris, 0.03 * side);
    let (mut max, mut sum, mut count) = (0.0f64, 0.0, 0usize);
    for c in 0..f.mesh.n_cells() as u32 {
        for ij in 0..9 {
            let (a, b) = (
                (ij % 3) as f64 / 3.0 + 1.0 / 6.0,
                (ij / 3) as f64 / 3.0 + 1.0 / 6.0,
            );
            let e = near.distance(f.mesh.point(c, a, b, &f.control)) / side;
            max = max.max(e);
            sum += e * e;
            count += 1;
        }
    }
    let rms = (sum / count as f64).sqrt();
    eprintln!(
        "genus3 0.5 %, thin plate 0.1: {} control points, L∞ {:.4} % at the vertices, between them {:.3} / {:.4} % (max / rms, {count} points); {:#?}",
        f.mesh.n_control_points(),
        100.0 * vertex,
        100.0 * max,
        100.0 * rms,
        f.refinements
    );
    assert!(
        f.converged && vertex <= 0.005,
        "L∞ at the vertices {vertex}"
    );
    assert!(
        max <= 0.03,
        "between the vertices {max} (∞: farther than 3 %)"
    );
    let mut rng = Rng(0x9b05688c2b3e6c1f);
    check_t_spline("genus3 thin plate", &f.mesh, f.mesh.n_vertices(), &mut rng);
}
