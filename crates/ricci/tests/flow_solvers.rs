//! Ricci flow on procedurally generated surfaces (no mesh files needed): convergence of Newton
//! for every scheme and geometry, closed forms (stereographic projection of a hemisphere, the
//! round sphere), the gradient flow reaching Newton's metric, and the refusals (Gauss–Bonnet,
//! Chow–Luo).

#![allow(clippy::needless_range_loop)]

mod flow_support;

use ricci::flow::{
    ricci_flow, separated_vertices, FlowOptions, FlowResult, Solver, SphereRoute, TargetSpec,
};
use ricci::mesh::generate;
use ricci::mesh::Surface;
use ricci::metric::{self, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

const SCHEMES: [Scheme; 4] = [
    Scheme::Thurston,
    Scheme::Tangential,
    Scheme::Inversive,
    Scheme::Yamabe,
];

fn run(s: &Surface, geometry: Geometry, scheme: Scheme, target: TargetSpec) -> FlowResult {
    let o = FlowOptions {
        geometry,
        scheme,
        target,
        ..FlowOptions::default()
    };
    ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress)
        .unwrap_or_else(|e| panic!("{geometry}, {scheme}: {e}"))
}

/// The acceptance bar of issue 3: max |K − K̄| ≤ 1e-10, Gauss–Bonnet ≤ 1e-9, ≤ 30 Newton steps,
/// and the final lengths really have the reported curvature.
fn assert_converged(what: &str, s: &Surface, r: &FlowResult) {
    assert!(
        r.converged && r.max_curvature_error <= 1e-10,
        "{what}: not converged (max |K − K̄| = {:.3e} after {} steps; notes: {:?})",
        r.max_curvature_error,
        r.iterations,
        r.notes
    );
    assert!(
        r.gauss_bonnet_error <= 1e-9,
        "{what}: Gauss–Bonnet {:.3e}",
        r.gauss_bonnet_error
    );
    assert!(r.iterations <= 30, "{what}: {} Newton steps", r.iterations);
    // Independent recomputation from the final lengths.
    let k = metric::curvature(&s.mesh, r.geometry, &r.lengths);
    for v in 0..k.len() {
        if !r.fixed[v] {
            assert!(
                (k[v] - r.target[v]).abs() <= 1e-9,
                "{what}: vertex {v} has K = {} for K̄ = {}",
                k[v],
                r.target[v]
            );
        }
    }
    let gb = metric::gauss_bonnet_residual(&s.mesh, r.geometry, &r.lengths);
    assert!(
        gb <= 1e-9,
        "{what}: recomputed Gauss–Bonnet residual {gb:.3e}"
    );
}

#[test]
fn flat_torus_for_every_scheme() {
    let s = generate::torus(2.0, 1.0, 24).unwrap();
    for sc in SCHEMES {
        let r = run(&s, Geometry::Euclidean, sc, TargetSpec::Uniform);
        assert_converged(&format!("torus E² {sc}"), &s, &r);
        // Euclidean results keep the input area.
        let a0 = metric::total_area(&s.mesh, Geometry::Euclidean, &s.edge_lengths());
        assert!((r.area - a0).abs() < 1e-9 * a0, "area {} vs {a0}", r.area);
    }
}

#[test]
fn hyperbolic_genus_two_for_every_scheme_and_flat_cones() {
    let s = generate::genus(2, 16).unwrap();
    let chi = metric::euler_characteristic(&s.mesh);
    assert_eq!(chi, -2);
    for sc in SCHEMES {
        let r = run(&s, Geometry::Hyperbolic, sc, TargetSpec::Uniform);
        assert_converged(&format!("genus 2 H² {sc}"), &s, &r);
        // Hyperbolic area of a genus-2 surface is −2πχ = 4π.
        assert!((r.area - 4.0 * PI).abs() < 1e-9, "area {}", r.area);
    }
    // E² with 2g − 2 cones of −2π at well-separated vertices of valence ≥ 6.
    let cones = separated_vertices(&s.mesh, 2, 6);
    assert_eq!(cones.len(), 2);
    let spec = TargetSpec::Cones(cones.iter().map(|&v| (v, -2.0 * PI)).collect());
    // (Vertex scaling cannot reach these cones without changing the connectivity: its energy
    // minimizer has degenerate triangles here, so it is not in the list.)
    for sc in [Scheme::Thurston, Scheme::Tangential, Scheme::Inversive] {
        let r = run(&s, Geometry::Euclidean, sc, spec.clone());
        assert_converged(&format!("genus 2 E² two cones {sc}"), &s, &r);
        assert!((r.curvature[cones[0] as usize] + 2.0 * PI).abs() < 1e-10);
    }
}

#[test]
fn single_cone_on_genus_two_is_refused_by_chow_luo_at_low_valence() {
    let s = generate::genus(2, 16).unwrap();
    let v = (0..s.mesh.n_vertices() as u32)
        .find(|&v| s.mesh.valence(v) <= 6)
        .unwrap();
    let o = FlowOptions {
        target: TargetSpec::SingleCone(Some(v)),
        ..FlowOptions::default()
    };
    let e = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("Chow–Luo"), "{msg}");
    assert!(msg.contains(&format!("vertex {v}")), "{msg}");
}

#[test]
fn gauss_bonnet_refusals_say_by_how_much() {
    let s = generate::icosphere(2).unwrap();
    // A sphere has no flat metric: Σ K̄ = 0 ≠ 4π.
    let o = FlowOptions::default();
    let msg = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("Gauss–Bonnet") && msg.contains("off by"),
        "{msg}"
    );
    assert!(msg.contains("-1.2566e1") || msg.contains("12.566"), "{msg}");
    // Nor a hyperbolic one.
    let o = FlowOptions {
        geometry: Geometry::Hyperbolic,
        ..FlowOptions::default()
    };
    let msg = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("Gauss–Bonnet") && msg.contains("positive"),
        "{msg}"
    );
    // A torus with a cone that is not balanced.
    let t = generate::torus(2.0, 1.0, 12).unwrap();
    let o = FlowOptions {
        target: TargetSpec::Cones(vec![(0, 0.5)]),
        ..FlowOptions::default()
    };
    let msg = ricci_flow(&t.mesh, &t.edge_lengths(), &o, &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("off by 5.000e-1"), "{msg}");
}

#[test]
fn round_sphere_is_already_spherical() {
    let s = generate::icosphere(3).unwrap();
    let l = s.edge_lengths();
    // Vertex scaling reads the input as chords of a sphere: the unit-sphere geodesic metric is in
    // its conformal class, and the flow must find it (u constant by the icosahedral symmetry).
    let o = FlowOptions {
        geometry: Geometry::Spherical,
        scheme: Scheme::Yamabe,
        tolerance: 1e-13,
        ..FlowOptions::default()
    };
    let r = ricci_flow(&s.mesh, &l, &o, &mut NoProgress).unwrap();
    assert_converged("icosphere S² yamabe", &s, &r);
    let mean = r.u.iter().sum::<f64>() / r.u.len() as f64;
    let spread = r.u.iter().fold(0.0f64, |m, x| m.max((x - mean).abs()));
    assert!(spread < 1e-9, "u varies by {spread:.3e}");
    for e in 0..l.len() {
        let geodesic = 2.0 * (0.5 * l[e]).asin();
        assert!((r.lengths[e] - geodesic).abs() < 1e-9, "edge {e}");
    }
    assert!((r.area - 4.0 * PI).abs() < 1e-9);
    // The default scheme: a spherical circle packing whose angles stay close to the sphere's.
    let r = run(
        &s,
        Geometry::Spherical,
        Scheme::Thurston,
        TargetSpec::Uniform,
    );
    assert_converged("icosphere S² thurston", &s, &r);
    let geo: Vec<f64> = l.iter().map(|&x| 2.0 * (0.5 * x).asin()).collect();
    let a0 = metric::corner_angles(&s.mesh, Geometry::Spherical, &geo);
    let a1 = metric::corner_angles(&s.mesh, Geometry::Spherical, &r.lengths);
    let dev: Vec<f64> = a0
        .iter()
        .zip(&a1)
        .map(|(x, y)| (y / x - 1.0).abs())
        .collect();
    let worst = dev.iter().fold(0.0f64, |m, &x| m.max(x));
    let mean = dev.iter().sum::<f64>() / dev.len() as f64;
    eprintln!(
        "icosphere(3) S² Thurston: corner angle ratio |θ/θ_sphere − 1| mean {mean:.3e}, max {worst:.3e}"
    );
    // Thurston's packing replaces the metric by tangent circles (clamped φ) on most edges, so
    // it is only close: a few percent on average (measured: mean 4.1e-2, max 1.26e-1).
    assert!(mean < 0.06 && worst < 0.2, "mean {mean}, max {worst}");
    // Inversive distance starts at the exact input metric; its sphere is the round one up to a
    // Möbius map (here none, by symmetry).
    let r = run(
        &s,
        Geometry::Spherical,
        Scheme::Inversive,
        TargetSpec::Uniform,
    );
    assert_converged("icosphere S² inversive", &s, &r);
    let a2 = metric::corner_angles(&s.mesh, Geometry::Spherical, &r.lengths);
    let worst = a0
        .iter()
        .zip(&a2)
        .map(|(x, y)| (y / x - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-6, "inversive: angles differ by {worst:.3e}");
}

#[test]
fn spherical_puncture_route_agrees_with_spherical_newton() {
    let mut s = generate::icosphere(2).unwrap();
    // Break the symmetry a little.
    for (i, p) in s.positions.iter_mut().enumerate() {
        let f = 1.0 + 0.15 * ((i * 7919 % 13) as f64 / 13.0 - 0.5);
        *p = p.map(|x| x * f);
    }
    for sc in [Scheme::Thurston, Scheme::Yamabe] {
        let mut results = Vec::new();
        for route in [SphereRoute::Newton, SphereRoute::Puncture] {
            let o = FlowOptions {
                geometry: Geometry::Spherical,
                scheme: sc,
                sphere_route: route,
                ..FlowOptions::default()
            };
            let r = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap();
            assert_converged(&format!("bumpy icosphere S² {sc} {route:?}"), &s, &r);
            results.push(r);
        }
        assert_eq!(results[0].route, "newton");
        assert_eq!(results[1].route, "puncture");
        // Both are conformal to the input and spherical: they differ by a Möbius map, so
        // cross-ratio-like invariants agree. Compare the corner angles of the two metrics up to
        // the Möbius freedom via the conformal invariant of each edge (length cross ratio of the
        // two triangles at it) — for vertex scaling it is exact.
        if sc == Scheme::Yamabe {
            let m = &s.mesh;
            for e in 0..m.n_edges() as u32 {
                let h = m.edge_halfedge(e);
                let t = m.he_twin(h);
                let lcr = |l: &[f64]| {
                    let a = l[m.he_edge(m.he_next(h)) as usize];
                    let b = l[m.he_edge(m.he_prev(h)) as usize];
                    let c = l[m.he_edge(m.he_next(t)) as usize];
                    let d = l[m.he_edge(m.he_prev(t)) as usize];
                    // With chords c = 2 sin(l/2): a Möbius-invariant length cross ratio.
                    let ch = |x: f64| (0.5 * x).sin();
                    (ch(a) * ch(c)) / (ch(b) * ch(d))
                };
                let (x, y) = (lcr(&results[0].lengths), lcr(&results[1].lengths));
                assert!((x / y - 1.0).abs() < 1e-8, "edge {e}: {x} vs {y}");
            }
        }
    }
}

#[test]
fn hemisphere_free_boundary_is_stereographic_projection() {
    // Closed form: the stereographic projection from the south pole maps the upper hemisphere
    // onto the unit disk and scales chords exactly by 1/√((1+z_i)(1+z_j)); the image is a flat
    // triangulation with the boundary (z = 0) unscaled. So vertex-scaling flow with u = 0 on
    // the boundary and K̄ = 0 inside must return u_i = −log(1 + z_i).
    let s = flow_support::hemisphere(10);
    let r = run(
        &s,
        Geometry::Euclidean,
        Scheme::Yamabe,
        TargetSpec::FreeBoundary,
    );
    assert_converged("hemisphere E² yamabe free-boundary", &s, &r);
    let mut worst = 0.0f64;
    for (v, p) in s.positions.iter().enumerate() {
        worst = worst.max((r.u[v] + (1.0 + p[2]).ln()).abs());
    }
    assert!(worst < 1e-9, "u differs from −log(1 + z) by {worst:.3e}");
    // The same with a round boundary: the boundary becomes a circle, interior flat, and the
    // angles are those of the stereographic image up to a Möbius map (here: a similarity, by
    // symmetry of the construction).
    for sc in SCHEMES {
        let r = run(&s, Geometry::Euclidean, sc, TargetSpec::RoundBoundary);
        assert_converged(&format!("hemisphere E² {sc} round-boundary"), &s, &r);
    }
}

#[test]
fn free_and_round_boundary_disks_for_every_scheme() {
    let s = generate::disk(40).unwrap();
    for sc in SCHEMES {
        for t in [TargetSpec::FreeBoundary, TargetSpec::RoundBoundary] {
            let r = run(&s, Geometry::Euclidean, sc, t.clone());
            assert_converged(&format!("disk E² {sc} {t}"), &s, &r);
            if t == TargetSpec::RoundBoundary {
                // The boundary is a circle in an independent layout.
                let spread = flow_support::boundary_circle_spread(&s.mesh, &r.lengths);
                assert!(spread <= 1e-8, "disk {sc}: radius spread {spread:e}");
                // Each boundary vertex gets its share of 2π.
                let total: f64 = (0..s.mesh.n_vertices() as u32)
                    .filter(|&v| s.mesh.is_boundary_vertex(v))
                    .map(|v| r.curvature[v as usize])
                    .sum();
                assert!((total - 2.0 * PI).abs() < 1e-9);
            } else {
                // Free boundary: boundary lengths are kept.
                let l = s.edge_lengths();
                for e in 0..s.mesh.n_edges() as u32 {
                    if s.mesh.is_boundary_edge(e) {
                        let rel = (r.lengths[e as usize] / l[e as usize] - 1.0).abs();
                        if sc.is_circle_packing() && sc != Scheme::Inversive {
                            continue; // packings only approximate the input lengths
                        }
                        assert!(rel < 1e-12, "{sc}: boundary edge {e} changed by {rel}");
                    }
                }
            }
        }
    }
    // Multiply connected: round boundaries of +2π (outer loop) and −2π (holes).
    let p = generate::pair_of_pants(40).unwrap();
    for sc in SCHEMES {
        let r = run(&p, Geometry::Euclidean, sc, TargetSpec::RoundBoundary);
        assert_converged(&format!("pants round-boundary {sc}"), &p, &r);
    }
    // The annulus, every scheme. (Thurston's packing used to stall near 1e-4 here with a
    // symmetrized Jacobian; the exact non-symmetric one converges in 3 steps.)
    let a = generate::annulus(0.5, 1.0, 40).unwrap();
    for sc in SCHEMES {
        let r = run(&a, Geometry::Euclidean, sc, TargetSpec::RoundBoundary);
        assert_converged(&format!("annulus round-boundary {sc}"), &a, &r);
    }
    // And a hyperbolic pair of pants with geodesic boundaries.
    let p = generate::pair_of_pants(40).unwrap();
    let r = run(
        &p,
        Geometry::Hyperbolic,
        Scheme::Thurston,
        TargetSpec::GeodesicBoundary,
    );
    assert_converged("pair of pants H² geodesic-boundary", &p, &r);
    assert!(
        (r.area - 2.0 * PI).abs() < 1e-9,
        "area −2πχ = 2π, got {}",
        r.area
    );
}

#[test]
fn gradient_flow_reaches_the_newton_metric() {
    let s = generate::torus(2.0, 1.0, 10).unwrap();
    for (g, sc, t) in [
        (Geometry::Euclidean, Scheme::Thurston, TargetSpec::Uniform),
        (Geometry::Euclidean, Scheme::Yamabe, TargetSpec::Uniform),
    ] {
        let newton = run(&s, g, sc, t.clone());
        let o = FlowOptions {
            geometry: g,
            scheme: sc,
            target: t,
            solver: Solver::Gradient,
            gradient_step: 0.1,
            tolerance: 1e-11,
            ..FlowOptions::default()
        };
        let grad = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap();
        assert!(grad.converged, "gradient flow: {:?}", grad.notes);
        assert!(grad.iterations > 10 * newton.iterations);
        let worst = newton
            .lengths
            .iter()
            .zip(&grad.lengths)
            .map(|(a, b)| (a / b - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-8, "{sc}: lengths differ by {worst:.3e}");
    }
    // Hyperbolic too, on a genus-2 surface.
    let s = generate::genus(2, 12).unwrap();
    let newton = run(
        &s,
        Geometry::Hyperbolic,
        Scheme::Thurston,
        TargetSpec::Uniform,
    );
    let o = FlowOptions {
        geometry: Geometry::Hyperbolic,
        solver: Solver::Gradient,
        gradient_step: 0.2,
        tolerance: 1e-11,
        ..FlowOptions::default()
    };
    let grad = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap();
    assert!(grad.converged);
    let worst = newton
        .u
        .iter()
        .zip(&grad.u)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-8, "H²: u differs by {worst:.3e}");
}

#[test]
fn bad_inputs_are_refused_with_a_sentence() {
    let s = generate::torus(2.0, 1.0, 12).unwrap();
    let mut l = s.edge_lengths();
    l[5] = -1.0;
    let e = ricci_flow(&s.mesh, &l, &FlowOptions::default(), &mut NoProgress).unwrap_err();
    assert!(e.to_string().contains("edge 5"), "{e}");
    let mut l = s.edge_lengths();
    l[0] *= 100.0;
    let e = ricci_flow(&s.mesh, &l, &FlowOptions::default(), &mut NoProgress).unwrap_err();
    assert!(e.to_string().contains("triangle inequality"), "{e}");
    let o = FlowOptions {
        target: TargetSpec::Cones(vec![(1_000_000, 1.0)]),
        ..FlowOptions::default()
    };
    let e = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap_err();
    assert!(e.to_string().contains("vertex 1000000"), "{e}");
    let o = FlowOptions {
        target: TargetSpec::FreeBoundary,
        ..FlowOptions::default()
    };
    let e = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap_err();
    assert!(e.to_string().contains("closed"), "{e}");
    // Spec parsing.
    assert_eq!(
        "cone:3=-2pi,7=pi/2".parse::<TargetSpec>().unwrap(),
        TargetSpec::Cones(vec![(3, -2.0 * PI), (7, PI / 2.0)])
    );
    assert!("cone:3".parse::<TargetSpec>().is_err());
    assert!("sideways".parse::<TargetSpec>().is_err());
}

/// A target that vertex scaling can only reach with faces violating the triangle inequality
/// (the curvature of a metric where the two ends of one edge have grown so much that the edge
/// is longer than the other two sides of both its faces: angles 0, 0, π) is not reported as
/// converged, even when the extended angles match it.
#[test]
fn a_target_reached_only_with_degenerate_faces_is_not_converged() {
    let s = flow_support::torus(2.0, 1.0, 24, 12);
    let m = &s.mesh;
    let [a, b] = m.edge_vertices(0);
    let u: Vec<f64> = (0..m.n_vertices() as u32)
        .map(|x| if x == a || x == b { 3.0 } else { 0.0 })
        .collect();
    let lengths: Vec<f64> = (0..m.n_edges() as u32)
        .map(|e| {
            let [p, q] = m.edge_vertices(e);
            let (x, y) = (s.positions[p as usize], s.positions[q as usize]);
            let l = ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt();
            l * (0.5 * (u[p as usize] + u[q as usize])).exp()
        })
        .collect();
    // Both faces of edge 0 are degenerate: the vertex opposite it has angle π there.
    let th = metric::corner_angles(m, Geometry::Euclidean, &lengths);
    let h = m.edge_halfedge(0);
    for h in [h, m.he_twin(h)] {
        let c = m.opposite_corner(h) as usize;
        assert!((th[c] - PI).abs() < 1e-12, "corner {c}: {}", th[c]);
    }
    let k = metric::curvature(m, Geometry::Euclidean, &lengths);
    let r = run(
        &s,
        Geometry::Euclidean,
        Scheme::Yamabe,
        TargetSpec::PerVertex(k),
    );
    eprintln!(
        "max |K − K̄| {:.2e} after {} steps, {} degenerate faces, notes {:?}",
        r.max_curvature_error, r.iterations, r.degenerate_faces, r.notes
    );
    // The extended angles do reach the target; the faces are what is wrong.
    assert!(r.max_curvature_error <= 1e-10);
    assert!(r.degenerate_faces > 0);
    assert!(!r.converged);
    assert!(r.notes.iter().any(|n| n.contains("triangle inequality")));
}
