//! Finite-difference checks of every derivative of the metric module, for every scheme ×
//! geometry: angles by lengths, lengths by u, the assembled Hessian ∂K/∂u (and its symmetry,
//! per face and assembled), and the energy gradient K − K̄.

#![allow(clippy::needless_range_loop)]

mod flow_support;

use ricci::mesh::Surface;
use ricci::metric::kernel::{angle_derivatives, triangle_angles};
use ricci::metric::{
    ConformalStructure, Euclidean, Evaluator, Geometry, Hyperbolic, Scheme, Spherical,
};

const SCHEMES: [Scheme; 4] = [
    Scheme::Thurston,
    Scheme::Tangential,
    Scheme::Inversive,
    Scheme::Yamabe,
];
const GEOMETRIES: [Geometry; 3] = [
    Geometry::Euclidean,
    Geometry::Hyperbolic,
    Geometry::Spherical,
];

/// Deterministic pseudo-random numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A level-1 icosphere with jittered vertices (closed, 42 vertices) and a jittered cap
/// (with boundary), as test meshes.
fn test_meshes() -> Vec<(&'static str, Surface)> {
    let mut rng = Lcg(7);
    let mut s = flow_support::icosphere(1);
    for p in s.positions.iter_mut() {
        for x in p.iter_mut() {
            *x += 0.08 * (rng.next() - 0.5);
        }
    }
    let mut d = flow_support::disk(3);
    for p in d.positions.iter_mut() {
        for x in p.iter_mut().take(2) {
            *x += 0.05 * (rng.next() - 0.5);
        }
    }
    vec![("jittered icosphere", s), ("jittered cap", d)]
}

/// Input scale per geometry: hyperbolic and spherical metrics on a unit-ish mesh.
fn scale_for(g: Geometry) -> f64 {
    match g {
        Geometry::Euclidean => 1.0,
        Geometry::Hyperbolic => 0.8,
        Geometry::Spherical => 0.9,
    }
}

fn rel_close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * scale.max(a.abs()).max(b.abs())
}

#[test]
fn angles_by_lengths_match_finite_differences_in_all_geometries() {
    let mut rng = Lcg(3);
    let mut checked = 0;
    for _ in 0..200 {
        let l = [0.2 + rng.next(), 0.2 + rng.next(), 0.2 + rng.next()];
        // Stay away from degenerate triangles, where finite differences lose accuracy.
        let sig = 0.5 * (l[0] + l[1] + l[2]);
        if l.iter().any(|&x| sig - x < 0.05 * sig) {
            continue;
        }
        let sc = 0.4 + 0.8 * rng.next(); // also smaller triangles
        let l = l.map(|x| x * sc);
        for g in GEOMETRIES {
            let (th, d) = match g {
                Geometry::Euclidean => {
                    let (t, d, _) = angle_derivatives::<Euclidean>(l);
                    (t, d)
                }
                Geometry::Hyperbolic => {
                    let (t, d, _) = angle_derivatives::<Hyperbolic>(l);
                    (t, d)
                }
                Geometry::Spherical => {
                    let (t, d, _) = angle_derivatives::<Spherical>(l);
                    (t, d)
                }
            };
            // Angles agree with the plain cosine law of the background.
            for i in 0..3 {
                let c = g.angle(l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
                assert!((th[i] - c).abs() < 1e-12, "{g}: angle {i} {} vs {c}", th[i]);
            }
            let ang = |l: [f64; 3]| match g {
                Geometry::Euclidean => triangle_angles::<Euclidean>(l).0,
                Geometry::Hyperbolic => triangle_angles::<Hyperbolic>(l).0,
                Geometry::Spherical => triangle_angles::<Spherical>(l).0,
            };
            for j in 0..3 {
                let h = 1e-6 * l[j];
                let (mut lp, mut lm) = (l, l);
                lp[j] += h;
                lm[j] -= h;
                let (tp, tm) = (ang(lp), ang(lm));
                for i in 0..3 {
                    let fd = (tp[i] - tm[i]) / (2.0 * h);
                    assert!(
                        rel_close(d[i][j], fd, 1e-3, 1e-6),
                        "{g}: ∂θ{i}/∂l{j} = {} but finite differences give {fd} at l = {l:?}",
                        d[i][j]
                    );
                }
            }
            // Euclidean: ∂θ/∂l sums to zero along rows weighted by l (scale invariance).
            if g == Geometry::Euclidean {
                for i in 0..3 {
                    let s: f64 = (0..3).map(|j| d[i][j] * l[j]).sum();
                    assert!(s.abs() < 1e-10, "Euclidean angles are scale invariant");
                }
            }
            checked += 1;
        }
    }
    assert!(checked > 300);
}

#[test]
fn lengths_by_u_match_finite_differences_for_every_scheme_and_geometry() {
    let mut rng = Lcg(11);
    for (name, s) in test_meshes() {
        let lengths = s.edge_lengths();
        for g in GEOMETRIES {
            for sc in SCHEMES {
                let st = ConformalStructure::new(&s.mesh, &lengths, g, sc, scale_for(g)).unwrap();
                let n = s.mesh.n_vertices();
                let ne = s.mesh.n_edges();
                let u: Vec<f64> = st
                    .u0
                    .iter()
                    .map(|&x| x + 0.05 * (rng.next() - 0.5))
                    .collect();
                let mut l = vec![0.0; ne];
                let mut d = vec![[0.0; 2]; ne];
                st.lengths_and_derivatives(&s.mesh, &u, &mut l, &mut d);
                for e in 0..ne {
                    let [a, b] = s.mesh.edge_vertices(e as u32);
                    for (k, v) in [a, b].into_iter().enumerate() {
                        let h = 1e-6;
                        let mut up = u.clone();
                        let mut um = u.clone();
                        up[v as usize] += h;
                        um[v as usize] -= h;
                        let fd =
                            (st.lengths(&s.mesh, &up)[e] - st.lengths(&s.mesh, &um)[e]) / (2.0 * h);
                        assert!(
                            rel_close(d[e][k], fd, 1e-3 * l[e], 1e-6),
                            "{name}, {g}, {sc}: ∂l{e}/∂u{v} = {} vs finite differences {fd}",
                            d[e][k]
                        );
                    }
                }
                assert_eq!(n, u.len());
                // At u⁰, inversive distance and vertex scaling reproduce the input exactly.
                if matches!(sc, Scheme::Inversive | Scheme::Yamabe) {
                    assert!(
                        st.initial_length_error < 1e-12,
                        "{name}, {g}, {sc}: initial length error {}",
                        st.initial_length_error
                    );
                }
            }
        }
    }
}

#[test]
fn hessian_matches_finite_differences_of_curvature_and_is_symmetric() {
    let mut rng = Lcg(5);
    for (name, s) in test_meshes() {
        let lengths = s.edge_lengths();
        for g in GEOMETRIES {
            for sc in SCHEMES {
                let st = ConformalStructure::new(&s.mesh, &lengths, g, sc, scale_for(g)).unwrap();
                let n = s.mesh.n_vertices();
                let u: Vec<f64> = st
                    .u0
                    .iter()
                    .map(|&x| x + 0.05 * (rng.next() - 0.5))
                    .collect();
                let mut ev = Evaluator::new(&s.mesh, st);
                let trip = ev.hessian_triplets(&u).expect("inside the domain");
                let mut h = vec![0.0; n * n];
                for &(i, j, v) in &trip {
                    h[i as usize * n + j as usize] += v;
                }
                // Per-face blocks are symmetric (the curvature 1-form is closed face by face).
                ev.evaluate(&u);
                for f in 0..s.mesh.n_faces() {
                    let d = ev.face_jacobian(f);
                    for a in 0..3 {
                        for b in 0..a {
                            assert!(
                                rel_close(d[a][b], d[b][a], 1e-3, 1e-9),
                                "{name}, {g}, {sc}: face {f} block not symmetric: {} vs {}",
                                d[a][b],
                                d[b][a]
                            );
                        }
                    }
                }
                let hmax = h.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                for j in 0..n {
                    let step = 1e-6;
                    let mut up = u.clone();
                    let mut um = u.clone();
                    up[j] += step;
                    um[j] -= step;
                    ev.evaluate(&up);
                    let kp = ev.ws.curvature.clone();
                    ev.evaluate(&um);
                    let km = ev.ws.curvature.clone();
                    for i in 0..n {
                        let fd = (kp[i] - km[i]) / (2.0 * step);
                        let hij = h[i * n + j];
                        assert!(
                            rel_close(hij, fd, 1e-4 * hmax, 1e-6),
                            "{name}, {g}, {sc}: H[{i}][{j}] = {hij} but ∂K{i}/∂u{j} by finite \
                             differences = {fd}"
                        );
                        // Symmetry of the assembled matrix, checked against the FD column.
                        assert!(rel_close(h[j * n + i], fd, 1e-4 * hmax, 1e-6));
                    }
                }
                // Signs: ∂K_i/∂u_i > 0 away from S² (docs/DESIGN.md §3).
                if g != Geometry::Spherical {
                    for i in 0..n {
                        assert!(h[i * n + i] > 0.0, "{name}, {g}, {sc}: H[{i}][{i}] ≤ 0");
                    }
                }
                // Euclidean: constants are in the kernel (global scaling).
                if g == Geometry::Euclidean {
                    for i in 0..n {
                        let row: f64 = (0..n).map(|j| h[i * n + j]).sum();
                        assert!(
                            row.abs() < 1e-9 * hmax,
                            "{name}, {sc}: row {i} sums to {row}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn energy_gradient_is_curvature_minus_target() {
    let mut rng = Lcg(9);
    let (_, s) = test_meshes().remove(0);
    let lengths = s.edge_lengths();
    for g in GEOMETRIES {
        for sc in SCHEMES {
            let st = ConformalStructure::new(&s.mesh, &lengths, g, sc, scale_for(g)).unwrap();
            let n = s.mesh.n_vertices();
            let target: Vec<f64> = (0..n).map(|_| 0.1 * (rng.next() - 0.5)).collect();
            let u: Vec<f64> = st
                .u0
                .iter()
                .map(|&x| x + 0.05 * (rng.next() - 0.5))
                .collect();
            let mut ev = Evaluator::new(&s.mesh, st);
            ev.evaluate(&u);
            let grad: Vec<f64> = (0..n).map(|i| ev.ws.curvature[i] - target[i]).collect();
            for j in (0..n).step_by(5) {
                let h = 1e-5;
                let mut up = u.clone();
                let mut um = u.clone();
                up[j] += h;
                um[j] -= h;
                let ep = ev.energy(&up, &target).unwrap();
                let em = ev.energy(&um, &target).unwrap();
                let fd = (ep - em) / (2.0 * h);
                assert!(
                    rel_close(grad[j], fd, 1e-2, 1e-6),
                    "{g}, {sc}: ∂E/∂u{j} = {fd} by finite differences, K − K̄ = {}",
                    grad[j]
                );
            }
        }
    }
}
