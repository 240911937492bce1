//! Tests of the procedural surfaces (`ricci::mesh::generate`): topology, triangle quality,
//! geometry against closed forms, determinism, parameter validation.

use proptest::prelude::*;
use ricci::mesh::generate::*;
use ricci::mesh::quality::angle_stats;
use ricci::mesh::{topology, Surface};
use ricci::Error;
use std::collections::HashMap;
use std::f64::consts::PI;

type P = [f64; 3];
fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: P) -> f64 {
    dot(a, a).sqrt()
}

fn tri(s: &Surface, f: usize) -> [P; 3] {
    s.mesh.faces()[f].map(|v| s.positions[v as usize])
}

/// Total area and enclosed volume (divergence theorem; positive for outward orientation).
fn area_volume(s: &Surface) -> (f64, f64) {
    let (mut a, mut vol) = (0.0, 0.0);
    for f in 0..s.mesh.n_faces() {
        let [p, q, r] = tri(s, f);
        a += 0.5 * norm(cross(sub(q, p), sub(r, p)));
        vol += dot(p, cross(q, r)) / 6.0;
    }
    (a, vol)
}

/// One component with the claimed genus and number of boundary loops, χ = 2 − 2g − b, and
/// closed exactly when b = 0.
fn assert_topology(s: &Surface, genus: i64, loops: usize, what: &str) {
    let t = topology(&s.mesh);
    assert_eq!(t.components.len(), 1, "{what}: components");
    let c = &t.components[0];
    assert_eq!(c.genus, genus, "{what}: genus");
    assert_eq!(c.boundary_loops, loops, "{what}: boundary loops");
    assert_eq!(
        c.euler_characteristic,
        2 - 2 * genus - loops as i64,
        "{what}: χ"
    );
    assert_eq!(c.vertices, s.mesh.n_vertices(), "{what}: unused vertices");
    assert_eq!(s.mesh.has_boundary(), loops > 0, "{what}: closedness");
    assert_eq!(s.mesh.boundary_loops().len(), loops, "{what}: loop walk");
}

/// Faces of a planar mesh are all counter-clockwise, and their areas add up to `area`.
fn assert_planar_cover(s: &Surface, area: f64, what: &str) {
    let mut total = 0.0;
    for f in 0..s.mesh.n_faces() {
        let [p, q, r] = tri(s, f);
        assert!(p[2] == 0.0 && q[2] == 0.0 && r[2] == 0.0);
        let a2 = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
        assert!(a2 > 0.0, "{what}: face {f} is not counter-clockwise");
        total += 0.5 * a2;
    }
    assert!(
        (total - area).abs() < 1e-12 * area.max(1.0) * s.mesh.n_faces() as f64,
        "{what}: faces cover {total}, the domain polygon has area {area}"
    );
}

/// Area of the regular `n`-gon inscribed in a circle of radius `r`.
fn polygon_area(n: usize, r: f64) -> f64 {
    0.5 * n as f64 * r * r * (2.0 * PI / n as f64).sin()
}

/// Every boundary loop lies on one of the circles `(centre, radius)`, uniformly sampled (all
/// its edges have the same length); returns the loop sizes per circle, in the order given.
fn boundary_circles(s: &Surface, circles: &[([f64; 2], f64)], what: &str) -> Vec<usize> {
    let mut sizes = vec![0; circles.len()];
    for lp in s.mesh.boundary_loops() {
        let p0 = s.positions[lp[0] as usize];
        let on = |c: &([f64; 2], f64), p: P| ((p[0] - c.0[0]).hypot(p[1] - c.0[1]) - c.1).abs();
        let k = (0..circles.len())
            .find(|&k| on(&circles[k], p0) < 1e-12)
            .unwrap_or_else(|| panic!("{what}: a boundary loop is on none of the circles"));
        assert_eq!(sizes[k], 0, "{what}: two loops on circle {k}");
        sizes[k] = lp.len();
        let chord = 2.0 * circles[k].1 * (PI / lp.len() as f64).sin();
        for i in 0..lp.len() {
            let (a, b) = (
                s.positions[lp[i] as usize],
                s.positions[lp[(i + 1) % lp.len()] as usize],
            );
            assert!(on(&circles[k], a) < 1e-12, "{what}: off the circle");
            assert!(
                (norm(sub(a, b)) - chord).abs() < 1e-9,
                "{what}: boundary not uniformly sampled"
            );
        }
    }
    sizes
}

// ---------------------------------------------------------------- sphere

#[test]
fn icosphere_counts_unit_sphere_and_convergence() {
    let mut prev_err = f64::INFINITY;
    for s in 0..=5u32 {
        let m = icosphere(s).unwrap();
        assert_eq!(m.mesh.n_faces(), 20 << (2 * s));
        assert_eq!(m.mesh.n_vertices(), (10 << (2 * s)) + 2);
        assert_topology(&m, 0, 0, "icosphere");
        for p in &m.positions {
            assert!((norm(*p) - 1.0).abs() < 1e-14, "vertex off the unit sphere");
        }
        // Outward orientation, volume converging to 4π/3 from below.
        let (_, vol) = area_volume(&m);
        let err = 4.0 * PI / 3.0 - vol;
        assert!(
            err > 0.0 && err < prev_err / 3.0,
            "volume {vol} at level {s}"
        );
        prev_err = err;
    }
    assert!(prev_err < 2e-3 * 4.0 * PI / 3.0, "{prev_err}");
}

// ---------------------------------------------------------------- torus

#[test]
fn torus_vertices_satisfy_the_torus_equation() {
    for (rr, r, n) in [
        (1.0, 0.5, 48),
        (3.0, 1.0, 30),
        (1.0, 0.9, 20),
        (2.0, 0.1, 64),
    ] {
        let s = torus(rr, r, n).unwrap();
        assert_topology(&s, 1, 0, "torus");
        for p in &s.positions {
            let rho = p[0].hypot(p[1]);
            let e = ((rho - rr).powi(2) + p[2] * p[2]).sqrt() - r;
            assert!(e.abs() < 1e-12, "vertex off the torus by {e}");
        }
        let (_, n_w, _) = torus_grid(rr, r, n).unwrap();
        assert_eq!(s.mesh.n_faces(), 2 * n as usize * n_w as usize);
        assert_eq!(n_w % 2, 0);
    }
}

/// The grid is equilateral in conformal coordinates, so the triangles become equilateral in
/// R³ as the resolution grows (a grid uniform in the angle v would not); area and volume
/// converge to 4π²Rr and 2π²Rr².
#[test]
fn torus_triangles_become_equilateral_and_area_volume_converge() {
    let (rr, r) = (1.0, 0.6);
    let mut prev_dev = 90.0;
    for n in [24, 48, 96, 192] {
        let s = torus(rr, r, n).unwrap();
        let q = angle_stats(&s);
        let dev = (q.max_angle_deg - 60.0).max(60.0 - q.min_angle_deg);
        assert!(dev < 0.7 * prev_dev, "angle deviation {dev} at n = {n}");
        prev_dev = dev;
        let (a, v) = area_volume(&s);
        let (a0, v0) = (4.0 * PI * PI * rr * r, 2.0 * PI * PI * rr * r * r);
        let tol = 40.0 / (n * n) as f64;
        assert!((a - a0).abs() < tol * a0, "area {a} vs {a0} at n = {n}");
        assert!((v - v0).abs() < tol * v0, "volume {v} vs {v0} at n = {n}");
    }
    assert!(prev_dev < 1.5, "{prev_dev}");
}

/// Dirichlet energy `Σ_e w_e (u_b − u_a + s_e)²` (cotangent weights `w = (cot α + cot β)/2`)
/// of the discrete harmonic function with period 1 along the angle `angle(p)`: `s_e` is the
/// jump (−1, 0, 1) of the edge across the branch cut of `angle`. Minimised by conjugate
/// gradients on the (singular, consistent) cotangent Laplacian.
fn harmonic_period_energy(s: &Surface, angle: impl Fn(P) -> f64) -> f64 {
    let m = &s.mesh;
    let nv = m.n_vertices();
    let theta: Vec<f64> = s.positions.iter().map(|&p| angle(p)).collect();
    let mut edges = Vec::new(); // (a, b, w, s)
    for e in 0..m.n_edges() as u32 {
        let h = m.edge_halfedge(e);
        let mut w = 0.0;
        for g in [h, m.he_twin(h)] {
            let f = m.he_face(g) as usize;
            let t = m.faces()[f];
            let i = (0..3).find(|&i| t[i] == m.he_origin(g)).unwrap();
            let [a, b, c] = [t[i], t[(i + 1) % 3], t[(i + 2) % 3]].map(|v| s.positions[v as usize]);
            let (u, v) = (sub(a, c), sub(b, c));
            w += 0.5 * dot(u, v) / norm(cross(u, v));
        }
        let [a, b] = m.edge_vertices(e);
        let raw = theta[b as usize] - theta[a as usize];
        let jump = -(raw / (2.0 * PI)).round();
        edges.push((a as usize, b as usize, w, jump));
    }
    let apply = |x: &[f64], y: &mut [f64]| {
        y.iter_mut().for_each(|v| *v = 0.0);
        for &(a, b, w, _) in &edges {
            let d = w * (x[b] - x[a]);
            y[b] += d;
            y[a] -= d;
        }
    };
    // Gradient of the energy at u = 0 is −rhs: rhs_b = −Σ w s, rhs_a = +Σ w s.
    let mut rhs = vec![0.0; nv];
    for &(a, b, w, j) in &edges {
        rhs[b] -= w * j;
        rhs[a] += w * j;
    }
    let mut u = vec![0.0; nv];
    let mut r = rhs.clone();
    let mut p = r.clone();
    let mut ap = vec![0.0; nv];
    let mut rr: f64 = r.iter().map(|x| x * x).sum();
    let stop = 1e-24 * rr.max(1e-300);
    for _ in 0..10 * nv {
        if rr <= stop {
            break;
        }
        apply(&p, &mut ap);
        let alpha = rr / p.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>();
        for i in 0..nv {
            u[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        let rr_new: f64 = r.iter().map(|x| x * x).sum();
        for i in 0..nv {
            p[i] = r[i] + rr_new / rr * p[i];
        }
        rr = rr_new;
    }
    edges
        .iter()
        .map(|&(a, b, w, j)| w * (u[b] - u[a] + j).powi(2))
        .sum()
}

/// The closed form the Ricci-flow tests use: the torus of revolution is conformal to the flat
/// torus `[0, 2π] × [0, W]`, `W/2π = r/√(R² − r²)`. For a rectangle torus the harmonic
/// function with period 1 around the major circle has Dirichlet energy `W/2π`, the one with
/// period 1 around the tube `2π/W`; the discrete energies converge to both.
#[test]
fn torus_harmonic_energies_match_the_conformal_modulus() {
    for (rr, r) in [(1.0f64, 0.5f64), (2.0, 0.6)] {
        let modulus = r / (rr * rr - r * r).sqrt();
        let mut prev = f64::INFINITY;
        for n in [24, 48, 96] {
            let s = torus(rr, r, n).unwrap();
            let e_major = harmonic_period_energy(&s, |p| p[1].atan2(p[0]));
            let e_tube = harmonic_period_energy(&s, |p| p[2].atan2(p[0].hypot(p[1]) - rr));
            let err = (e_major / modulus - 1.0)
                .abs()
                .max((e_tube * modulus - 1.0).abs());
            eprintln!("R = {rr}, r = {r}, n = {n}: {e_major} vs {modulus}, {e_tube}; {err:.2e}");
            // O(h²): the error drops by about 4 when the resolution doubles.
            assert!(
                err < 0.05 && err < 0.4 * prev,
                "relative error {err} at n = {n}"
            );
            prev = err;
        }
        assert!(prev < 5e-3, "{prev}");
    }
}

/// The conformal height W = 2πr/√(R² − r²) of the grid: rows are spaced √3/2 of a column.
#[test]
fn torus_grid_follows_the_conformal_modulus() {
    for (rr, r) in [(1.0, 0.5), (2.0, 0.3), (1.0, 0.95)] {
        let n = 60;
        let (_, n_w, height) = torus_grid(rr, r, n).unwrap();
        let w = 2.0 * PI * r / (rr * rr - r * r).sqrt();
        assert!((height - w).abs() < 1e-12);
        let a = 2.0 * PI / n as f64;
        let ratio = (height / n_w as f64) / (a * 3f64.sqrt() / 2.0);
        assert!(
            (ratio - 1.0).abs() < 2.0 / n_w as f64,
            "row/column ratio {ratio}"
        );
    }
}

#[test]
fn extreme_radii_scale_instead_of_overflowing() {
    // Same shape at any scale: the mesh is the unit one, scaled.
    let (a, b) = (
        torus(1.0, 0.5, 24).unwrap(),
        torus(1e300, 0.5e300, 24).unwrap(),
    );
    assert_eq!(a.mesh.faces(), b.mesh.faces());
    for (p, q) in a.positions.iter().zip(&b.positions) {
        for k in 0..3 {
            assert!(
                (p[k] * 1e300 - q[k]).abs() <= 1e-12 * 1e300,
                "{p:?} vs {q:?}"
            );
        }
    }
    let (a, b) = (
        annulus(0.25, 1.0, 32).unwrap(),
        annulus(0.5e300, 2e300, 32).unwrap(),
    );
    assert_eq!(a.mesh.faces(), b.mesh.faces());
    assert!(b.positions.iter().all(|p| p.iter().all(|x| x.is_finite())));
    assert_planar_cover(&a, polygon_area(32, 1.0) - polygon_area(8, 0.25), "annulus");
}

// ---------------------------------------------------------------- planar

#[test]
fn disk_annulus_pants_cover_their_polygons_with_uniform_boundaries() {
    let s = disk(64).unwrap();
    assert_topology(&s, 0, 1, "disk");
    let sizes = boundary_circles(&s, &[([0.0, 0.0], 1.0)], "disk");
    assert_eq!(sizes, vec![64]);
    assert_planar_cover(&s, polygon_area(64, 1.0), "disk");

    let s = annulus(0.3, 1.5, 50).unwrap();
    assert_topology(&s, 0, 2, "annulus");
    let sizes = boundary_circles(&s, &[([0.0, 0.0], 1.5), ([0.0, 0.0], 0.3)], "annulus");
    assert_eq!(sizes[0], 50);
    assert_eq!(sizes[1], 10); // same spacing: 50 · 0.3 / 1.5
    let area = polygon_area(50, 1.5) - polygon_area(sizes[1], 0.3);
    assert_planar_cover(&s, area, "annulus");

    let s = pair_of_pants(64).unwrap();
    assert_topology(&s, 0, 3, "pants");
    let mut circles = vec![([0.0, 0.0], 1.0)];
    circles.extend(PANTS_HOLE_CENTERS.iter().map(|&c| (c, PANTS_HOLE_RADIUS)));
    let sizes = boundary_circles(&s, &circles, "pants");
    assert_eq!(sizes, vec![64, 16, 16]);
    let area = polygon_area(64, 1.0) - 2.0 * polygon_area(16, PANTS_HOLE_RADIUS);
    assert_planar_cover(&s, area, "pants");
}

// ---------------------------------------------------------------- quality at the defaults

#[test]
fn default_resolutions_have_min_angle_at_least_30_degrees() {
    for name in [
        "sphere", "torus", "disk", "annulus", "pants", "genus2", "genus3", "genus4",
    ] {
        let kind = GeneratorKind::parse(name, None).unwrap();
        let s = generate(
            kind,
            &GeneratorParams::default(),
            &mut ricci::progress::NoProgress,
        )
        .unwrap();
        let (g, b) = kind.topology();
        assert_topology(&s, g as i64, b as usize, name);
        let q = angle_stats(&s);
        eprintln!(
            "{name}: V = {}, F = {}, angles {:.2}°–{:.2}°",
            s.mesh.n_vertices(),
            s.mesh.n_faces(),
            q.min_angle_deg,
            q.max_angle_deg
        );
        assert!(
            q.min_angle_deg >= 30.0,
            "{name}: min angle {}",
            q.min_angle_deg
        );
        assert!(
            q.max_angle_deg <= 120.0,
            "{name}: max angle {}",
            q.max_angle_deg
        );
    }
}

// ---------------------------------------------------------------- genus g

/// Independent check of the shape: with `d_i` the distance to the centre circle of torus i,
/// a vertex lies on the tube `min d_i = r` away from the blends; inside a blend (two `d_i`
/// within the blend width k) the smooth minimum lowers the value by at most k/6, so
/// `r ≤ min d_i ≤ r + k/6`.
#[test]
fn genus_vertices_lie_on_the_blended_tori() {
    let (big_r, r, k) = (1.0, 0.4, 0.3);
    for g in [2u32, 3] {
        let s = genus(g, 24).unwrap();
        let field = ToriChain::new(g);
        let mut blended = 0;
        for p in &s.positions {
            let mut d: Vec<f64> = (0..g)
                .map(|i| {
                    let cx = 2.0 * i as f64 - (g as f64 - 1.0);
                    let rho = (p[0] - cx).hypot(p[1]);
                    (rho - big_r).hypot(p[2])
                })
                .collect();
            d.sort_by(f64::total_cmp);
            if d.len() < 2 || d[1] - d[0] >= k {
                assert!(
                    (d[0] - r).abs() < 1e-9,
                    "vertex {p:?} off the tube: {}",
                    d[0]
                );
            } else {
                blended += 1;
                assert!(
                    d[0] >= r - 1e-9 && d[0] <= r + k / 6.0 + 1e-9,
                    "{p:?}: {d:?}"
                );
            }
            assert!(field.value(*p).abs() < 1e-9);
        }
        eprintln!(
            "genus {g}: {blended} of {} vertices in a blend",
            s.mesh.n_vertices()
        );
        assert!(blended > 0 && blended < s.mesh.n_vertices() / 2);
    }
}

/// Area and enclosed volume converge as the resolution doubles (inscribed polyhedra:
/// error O(h²)), and are below those of g separate tori (the union overlaps).
#[test]
fn genus_area_and_volume_converge() {
    let g = 2u32;
    let (a1, v1) = area_volume(&genus(g, 20).unwrap());
    let (a2, v2) = area_volume(&genus(g, 40).unwrap());
    let (a3, v3) = area_volume(&genus(g, 80).unwrap());
    eprintln!("areas {a1} {a2} {a3}, volumes {v1} {v2} {v3}");
    let (ta, tv) = (
        g as f64 * 4.0 * PI * PI * 0.4,
        g as f64 * 2.0 * PI * PI * 0.16,
    );
    for (a, v) in [(a1, v1), (a2, v2), (a3, v3)] {
        assert!(a < ta && a > 0.8 * ta, "area {a} vs tori {ta}");
        assert!(
            v > 0.0 && v < 1.05 * tv && v > 0.8 * tv,
            "volume {v} vs tori {tv}"
        );
    }
    // O(h²) convergence: successive differences shrink by about 4 when h halves, and the
    // Richardson extrapolations x₂ + (x₂ − x₁)/3 from both pairs agree.
    for (x1, x2, x3, what) in [(a1, a2, a3, "area"), (v1, v2, v3, "volume")] {
        let ratio = (x2 - x1) / (x3 - x2);
        assert!(
            (2.5..7.0).contains(&ratio),
            "{what}: difference ratio {ratio}"
        );
        let (e12, e23) = (x2 + (x2 - x1) / 3.0, x3 + (x3 - x2) / 3.0);
        assert!(
            (e12 - e23).abs() < 3e-3 * e23,
            "{what}: extrapolations {e12} vs {e23}"
        );
    }
}

/// Squared distance from point `p` to segment `[a, b]` … and to triangle `t` (Ericson,
/// "Real-Time Collision Detection" 5.1.5), and between segments (5.1.9).
fn point_triangle_dist(p: P, t: [P; 3]) -> f64 {
    let [a, b, c] = t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let closest = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(ab, cp), dot(ac, cp));
        let (vc, vb, va) = (d1 * d4 - d3 * d2, d5 * d2 - d1 * d6, d3 * d6 - d5 * d4);
        let at = |o: P, d: P, s: f64| [o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]];
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            at(a, ab, d1 / (d1 - d3))
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            at(a, ac, d2 / (d2 - d6))
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            at(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))
        } else {
            let den = 1.0 / (va + vb + vc);
            let (v, w) = (vb * den, vc * den);
            [
                a[0] + ab[0] * v + ac[0] * w,
                a[1] + ab[1] * v + ac[1] * w,
                a[2] + ab[2] * v + ac[2] * w,
            ]
        }
    };
    norm(sub(p, closest))
}

fn segment_segment_dist(p1: P, q1: P, p2: P, q2: P) -> f64 {
    let (d1, d2, r) = (sub(q1, p1), sub(q2, p2), sub(p1, p2));
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let c = dot(d1, r);
    let b = dot(d1, d2);
    let den = a * e - b * b;
    let mut s = if den > 1e-300 {
        ((b * f - c * e) / den).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    let c1 = [p1[0] + d1[0] * s, p1[1] + d1[1] * s, p1[2] + d1[2] * s];
    let c2 = [p2[0] + d2[0] * t, p2[1] + d2[1] * t, p2[2] + d2[2] * t];
    norm(sub(c1, c2))
}

/// Whether segment `[p, q]` crosses triangle `t` (Möller–Trumbore on the segment).
fn segment_hits_triangle(p: P, q: P, t: [P; 3]) -> bool {
    let d = sub(q, p);
    let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let h = cross(d, e2);
    let a = dot(e1, h);
    if a.abs() < 1e-300 {
        return false;
    }
    let s = sub(p, t[0]);
    let u = dot(s, h) / a;
    let qv = cross(s, e1);
    let v = dot(d, qv) / a;
    let w = dot(e2, qv) / a;
    (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&w)
}

/// Distance between two triangles (0 when they intersect).
fn triangle_distance(s: [P; 3], t: [P; 3]) -> f64 {
    for i in 0..3 {
        if segment_hits_triangle(s[i], s[(i + 1) % 3], t)
            || segment_hits_triangle(t[i], t[(i + 1) % 3], s)
        {
            return 0.0;
        }
    }
    let mut d = f64::INFINITY;
    for i in 0..3 {
        d = d.min(point_triangle_dist(s[i], t));
        d = d.min(point_triangle_dist(t[i], s));
        for j in 0..3 {
            d = d.min(segment_segment_dist(
                s[i],
                s[(i + 1) % 3],
                t[j],
                t[(j + 1) % 3],
            ));
        }
    }
    d
}

/// The smallest distance between two faces that share no vertex (grid hash with cells as
/// large as the longest edge, so close faces share a cell).
fn min_nonadjacent_face_distance(s: &Surface) -> f64 {
    let lmax = s.edge_lengths().into_iter().fold(0.0, f64::max);
    let cell = |p: P| p.map(|x| (x / lmax).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for f in 0..s.mesh.n_faces() {
        let t = tri(s, f);
        let lo = cell([0, 1, 2].map(|k| t.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min)));
        let hi = cell([0, 1, 2].map(|k| t.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max)));
        for i in lo[0]..=hi[0] {
            for j in lo[1]..=hi[1] {
                for k in lo[2]..=hi[2] {
                    grid.entry([i, j, k]).or_default().push(f as u32);
                }
            }
        }
    }
    let mut best = f64::INFINITY;
    for faces in grid.values() {
        for (x, &f) in faces.iter().enumerate() {
            for &g in &faces[x + 1..] {
                let (a, b) = (s.mesh.face(f), s.mesh.face(g));
                if a.iter().any(|v| b.contains(v)) {
                    continue;
                }
                best = best.min(triangle_distance(tri(s, f as usize), tri(s, g as usize)));
            }
        }
    }
    best
}

/// No self-intersection at the default resolution: faces that share no vertex stay at least
/// a fifth of the mean edge length apart, and neighbouring faces never fold onto each other
/// (their normals make less than 90°).
#[test]
fn genus_surfaces_do_not_self_intersect() {
    for g in [2u32, 3, 4] {
        let s = genus(g, default_resolution(&GeneratorKind::Genus(g))).unwrap();
        let lengths = s.edge_lengths();
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        let d = min_nonadjacent_face_distance(&s);
        assert!(
            d > 0.2 * mean,
            "genus {g}: faces {d} apart, mean edge {mean}"
        );
        for e in 0..s.mesh.n_edges() as u32 {
            let h = s.mesh.edge_halfedge(e);
            let (f0, f1) = (s.mesh.he_face(h), s.mesh.he_face(s.mesh.he_twin(h)));
            let n = |f: u32| {
                let [p, q, r] = tri(&s, f as usize);
                cross(sub(q, p), sub(r, p))
            };
            assert!(dot(n(f0), n(f1)) > 0.0, "genus {g}: fold at edge {e}");
        }
    }
}

#[test]
fn the_self_intersection_check_can_fail() {
    // Two disjoint icospheres: far apart, then overlapping.
    let s = icosphere(1).unwrap();
    let nv = s.positions.len() as u32;
    for (shift, apart) in [(3.0, true), (1.5, false)] {
        let mut pos = s.positions.clone();
        pos.extend(s.positions.iter().map(|p| [p[0] + shift, p[1], p[2]]));
        let mut faces = s.mesh.faces().to_vec();
        faces.extend(s.mesh.faces().iter().map(|t| t.map(|v| v + nv)));
        let two = Surface::new(pos, faces).unwrap();
        let d = min_nonadjacent_face_distance(&two);
        assert_eq!(d > 0.1, apart, "distance {d}");
    }
}

// ---------------------------------------------------------------- determinism, parameters

#[test]
fn generators_are_deterministic() {
    for (a, b) in [
        (genus(2, 16).unwrap(), genus(2, 16).unwrap()),
        (pair_of_pants(40).unwrap(), pair_of_pants(40).unwrap()),
    ] {
        assert_eq!(a.mesh.faces(), b.mesh.faces());
        assert_eq!(a.positions, b.positions);
    }
}

fn input_error(r: ricci::Result<Surface>, needle: &str) {
    match r {
        Err(Error::InvalidInput { message }) => {
            assert!(message.contains(needle), "`{message}` lacks `{needle}`")
        }
        Err(e) => panic!("wrong error kind: {e}"),
        Ok(_) => panic!("accepted bad parameters (expected `{needle}`)"),
    }
}

#[test]
fn bad_parameters_are_refused_with_a_sentence() {
    input_error(torus(0.5, 1.0, 48), "0 < minor < major");
    input_error(torus(1.0, f64::NAN, 48), "minor");
    input_error(torus(1.0, 0.5, 2), "resolution");
    input_error(torus(1.0, 0.5, 1_000_000), "limit");
    input_error(icosphere(11), "subdivisions");
    input_error(annulus(1.0, 0.5, 32), "0 < inner < outer");
    input_error(annulus(0.0, 1.0, 32), "inner");
    input_error(annulus(1e-9, 1.0, 32), "too small");
    input_error(annulus(1.0, f64::INFINITY, 32), "outer");
    input_error(disk(3), "resolution");
    input_error(disk(1_000_000), "limit");
    input_error(pair_of_pants(8), "resolution");
    input_error(genus(0, 40), "g = 0");
    input_error(genus(2, 4), "resolution");
    input_error(genus(2, 100_000), "limit");
    let p = |f: fn(&mut GeneratorParams)| {
        let mut q = GeneratorParams::default();
        f(&mut q);
        q
    };
    let none = &mut ricci::progress::NoProgress;
    input_error(
        generate(GeneratorKind::Sphere, &p(|q| q.major = Some(2.0)), none),
        "major",
    );
    input_error(
        generate(GeneratorKind::Disk, &p(|q| q.subdivisions = Some(2)), none),
        "subdivisions",
    );
    input_error(
        generate(GeneratorKind::Torus, &p(|q| q.inner = Some(0.2)), none),
        "inner",
    );
}

#[test]
fn kind_names_parse() {
    assert_eq!(
        GeneratorKind::parse("genus3", None).unwrap(),
        GeneratorKind::Genus(3)
    );
    assert_eq!(
        GeneratorKind::parse("genus", Some(5)).unwrap(),
        GeneratorKind::Genus(5)
    );
    assert_eq!(
        GeneratorKind::parse("Sphere", None).unwrap(),
        GeneratorKind::Sphere
    );
    assert_eq!(
        GeneratorKind::parse("pair-of-pants", None).unwrap(),
        GeneratorKind::Pants
    );
    for (name, g, needle) in [
        ("genus", None, "needs the genus"),
        ("genus2", Some(3), "genus 2"),
        ("genus0", None, "out of range"),
        ("torus", Some(2), "does not take"),
        ("cube", None, "sphere, torus"),
        ("genusX", None, "unknown"),
    ] {
        match GeneratorKind::parse(name, g) {
            Err(Error::InvalidInput { message }) => assert!(message.contains(needle), "{message}"),
            other => panic!("{name}: {other:?}"),
        }
    }
    for name in GeneratorKind::NAMES.iter().filter(|n| **n != "genus") {
        let k = GeneratorKind::parse(name, None).unwrap();
        assert_eq!(&k.name(), name);
    }
}

// ---------------------------------------------------------------- property tests

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    #[test]
    fn prop_sphere_torus_topology(s in 0u32..5, rr in 0.5f64..5.0, frac in 0.05f64..0.95,
                                  n in 6u32..80) {
        assert_topology(&icosphere(s).unwrap(), 0, 0, "icosphere");
        let t = torus(rr, frac * rr, n).unwrap();
        assert_topology(&t, 1, 0, "torus");
        let (_, v) = area_volume(&t);
        prop_assert!(v > 0.0, "torus not oriented outward");
    }

    #[test]
    fn prop_planar_topology(n in 8u32..120, r_in in 0.05f64..0.9, r_out in 0.5f64..3.0) {
        let d = disk(n).unwrap();
        assert_topology(&d, 0, 1, "disk");
        assert_planar_cover(&d, polygon_area(n as usize, 1.0), "disk");
        let r_in = r_in * r_out;
        let a = annulus(r_in, r_out, n);
        if r_in / r_out > annulus_max_ratio(n) {
            // Too thin for n segments: refused with a sentence that says so.
            let e = a.expect_err("a too thin annulus is refused").to_string();
            prop_assert!(e.contains("too thin"), "{}", e);
            return Ok(());
        }
        let a = a.unwrap();
        assert_topology(&a, 0, 2, "annulus");
        let sizes = boundary_circles(&a, &[([0.0, 0.0], r_out), ([0.0, 0.0], r_in)], "annulus");
        let area = polygon_area(sizes[0], r_out) - polygon_area(sizes[1], r_in);
        assert_planar_cover(&a, area, "annulus");
        if n >= 16 {
            assert_topology(&pair_of_pants(n).unwrap(), 0, 3, "pants");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    #[test]
    fn prop_genus_topology(g in 1u32..6, n in 12u32..36) {
        let s = genus(g, n).unwrap();
        assert_topology(&s, g as i64, 0, "genus");
        let (_, v) = area_volume(&s);
        prop_assert!(v > 0.0, "not oriented outward");
    }
}

/// Just inside `annulus_max_ratio` every resolution triangulates to an annulus; just outside,
/// the generator refuses with a sentence instead of failing inside the mesh builder (it used
/// to report "non-manifold vertex 0: two boundary fans meet there" for e.g. n = 8, 0.85).
#[test]
fn thin_annuli_triangulate_or_are_refused() {
    for n in [8u32, 10, 12, 14, 16, 20, 24, 32, 48, 64] {
        let max = annulus_max_ratio(n);
        for q in [max - 0.002, max - 0.02, max - 0.06] {
            let a = annulus(q * 0.5, 0.5, n).unwrap_or_else(|e| panic!("n = {n}, ratio {q}: {e}"));
            assert_topology(&a, 0, 2, "thin annulus");
        }
        let e = annulus((max + 0.002).min(0.999) * 0.5, 0.5, n)
            .unwrap_err()
            .to_string();
        assert!(e.contains("too thin"), "n = {n}: {e}");
    }
}
