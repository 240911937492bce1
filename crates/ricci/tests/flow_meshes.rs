//! The convergence list of issue 3 on the real meshes of `$RICCI_MESHES` (skipped with a note
//! when the folder is missing), and the conformality of the hemisphere's flattening.
//!
//! Bar: max |K − K̄| ≤ 1e-10, Gauss–Bonnet residual ≤ 1e-9, ≤ 30 Newton steps, default
//! (Thurston) scheme. Where Thurston's packing cannot reach a target the test says so and
//! asserts the refusal (with its reason) and, where one exists, convergence with another scheme:
//! * rocker-arm (E² uniform): a valence-3 vertex whose Thurston angles φ are near π/2 cannot be
//!   flat (Chow–Luo); tangential packing converges;
//! * face (E² round-boundary): 82 boundary "ears" (boundary vertices with one face) cannot be
//!   straightened by any scheme without changing the connectivity (refused / stuck here);
//! * beetle (H² geodesic-boundary): 10 ears and, for Thurston, boundary vertices with two faces
//!   and φ = π/2; refused as it is, and converges (Thurston, 6 Newton steps) once every boundary
//!   vertex has three faces (`metric::refine::widen_boundary`, metric-preserving splits).
//! * face (E² round-boundary) still fails after widening its boundary alone: interior one-rings
//!   next to its thin boundary triangles (angles down to 4.6°) then violate Chow–Luo for
//!   Thurston, and vertex scaling's convex energy has its minimum at a "metric" with degenerate
//!   faces (no discrete conformal metric on that triangulation). Widening plus adaptive
//!   bisection of the degenerate faces (`ricci::flow::ricci_flow_refined`) makes Thurston
//!   (11 Newton steps), tangential, inversive distance and vertex scaling converge:
//!   `face_round_boundary_after_adaptive_refinement`.
//!
//! Round boundaries are checked to be circles in an independent layout
//! (`round_boundaries_are_circles`, and the face test).

#![allow(clippy::needless_range_loop)]

mod flow_support;

use ricci::flow::{ricci_flow, separated_vertices, FlowOptions, FlowResult, TargetSpec};
use ricci::mesh::Surface;
use ricci::metric::{self, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;
use std::path::Path;

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Uniform,
    Cones,
    SingleCone,
    FreeBoundary,
    RoundBoundary,
    GeodesicBoundary,
}

fn spec(s: &Surface, kind: Kind) -> TargetSpec {
    let chi = metric::euler_characteristic(&s.mesh);
    match kind {
        Kind::Uniform => TargetSpec::Uniform,
        Kind::Cones => {
            let v = separated_vertices(&s.mesh, (-chi) as usize, 6);
            TargetSpec::Cones(v.iter().map(|&v| (v, -2.0 * PI)).collect())
        }
        Kind::SingleCone => {
            // A vertex of valence 6: a cone of 2πχ there violates Chow–Luo.
            let v = separated_vertices(&s.mesh, 1, 6)[0];
            assert_eq!(s.mesh.valence(v), 6);
            TargetSpec::SingleCone(Some(v))
        }
        Kind::FreeBoundary => TargetSpec::FreeBoundary,
        Kind::RoundBoundary => TargetSpec::RoundBoundary,
        Kind::GeodesicBoundary => TargetSpec::GeodesicBoundary,
    }
}

fn flow(s: &Surface, g: Geometry, sc: Scheme, t: TargetSpec) -> ricci::Result<FlowResult> {
    let o = FlowOptions {
        geometry: g,
        scheme: sc,
        target: t,
        ..FlowOptions::default()
    };
    ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress)
}

fn meets_bar(s: &Surface, r: &FlowResult) -> Result<(), String> {
    if !(r.converged && r.max_curvature_error <= 1e-10) {
        return Err(format!(
            "not converged: max |K − K̄| = {:.2e} after {} steps ({:?})",
            r.max_curvature_error, r.iterations, r.notes
        ));
    }
    if r.iterations > 30 {
        return Err(format!("{} Newton steps", r.iterations));
    }
    if r.gauss_bonnet_error > 1e-9 {
        return Err(format!(
            "Gauss–Bonnet residual {:.2e}",
            r.gauss_bonnet_error
        ));
    }
    let gb = metric::gauss_bonnet_residual(&s.mesh, r.geometry, &r.lengths);
    if gb > 1e-9 {
        return Err(format!("recomputed Gauss–Bonnet residual {gb:.2e}"));
    }
    Ok(())
}

/// What the list expects of Thurston's scheme on one case.
enum Expect {
    Converge,
    /// Thurston refuses with a message containing the text; the alternative schemes converge.
    Refused(&'static str, &'static [Scheme]),
    /// Every scheme refuses with a message containing the text.
    RefusedAll(&'static str),
    /// Thurston refuses (first text); the other schemes run but cannot converge and say why
    /// in their notes (second text).
    RefusedOrStuck(&'static str, &'static str),
}

#[test]
fn convergence_list_of_issue_3() {
    let Some(dir) = flow_support::meshes_dir() else {
        return;
    };
    use Expect::*;
    use Geometry::{Euclidean as E2, Hyperbolic as H2, Spherical as S2};
    use Kind::*;
    let high_genus = [
        "eight.off",
        "3holes.off",
        "genus3.off",
        "fertility.off",
        "cup_input_simple_10000.off",
        "botijo.off",
    ];
    let mut cases: Vec<(&str, Geometry, Kind, Expect)> = vec![
        ("torus.off", E2, Uniform, Converge),
        ("knot.obj", E2, Uniform, Converge),
        ("bob_tri.obj", E2, Uniform, Converge),
        ("kitten.nf20k.off", E2, Uniform, Converge),
        (
            "rocker-arm.off",
            E2,
            Uniform,
            Refused(
                "Chow–Luo",
                &[Scheme::Tangential, Scheme::Inversive, Scheme::Yamabe],
            ),
        ),
    ];
    for m in high_genus {
        cases.push((m, H2, Uniform, Converge));
        cases.push((m, E2, Cones, Converge));
        cases.push((m, E2, SingleCone, RefusedAll("Chow–Luo")));
    }
    for m in ["face.off", "camelhead.off", "hemisphere.obj"] {
        cases.push((m, E2, FreeBoundary, Converge));
    }
    cases.push((
        "face.off",
        E2,
        RoundBoundary,
        RefusedOrStuck("an ear", "ears"),
    ));
    cases.push(("camelhead.off", E2, RoundBoundary, Converge));
    cases.push(("hemisphere.obj", E2, RoundBoundary, Converge));
    cases.push(("eight.open.off", H2, GeodesicBoundary, Converge));
    cases.push(("beetle.off", H2, GeodesicBoundary, RefusedAll("Chow–Luo")));
    for m in ["sphere.off", "spot.obj", "maxplanck.nf25k.off"] {
        cases.push((m, S2, Uniform, Converge));
    }
    let mut failures = Vec::new();
    let mut cache: Option<(String, Surface)> = None;
    eprintln!("mesh                        faces  geometry    target             scheme      steps  max|K−K̄|  GB       seconds route");
    for (file, g, kind, expect) in cases {
        if cache.as_ref().map(|c| c.0 != file).unwrap_or(true) {
            cache = Some((file.to_string(), flow_support::read_mesh(&dir.join(file))));
        }
        let s = &cache.as_ref().unwrap().1;
        let t = spec(s, kind);
        let label = match &t {
            TargetSpec::Cones(c) => format!("{} cones −2π", c.len()),
            other => other.to_string(),
        };
        let report = |sc: Scheme, r: &ricci::Result<FlowResult>| match r {
            Ok(r) => eprintln!(
                "{file:27} {:6} {g:11} {label:18} {sc:10} {:5}  {:.2e}  {:.1e}  {:.3}   {}",
                s.mesh.n_faces(),
                r.iterations,
                r.max_curvature_error,
                r.gauss_bonnet_error,
                r.seconds,
                r.route
            ),
            Err(e) => {
                let msg = e.to_string();
                eprintln!(
                    "{file:27} {:6} {g:11} {label:18} {sc:10} refused: {}",
                    s.mesh.n_faces(),
                    &msg[..msg.len().min(110)]
                )
            }
        };
        let r = flow(s, g, Scheme::Thurston, t.clone());
        report(Scheme::Thurston, &r);
        match (expect, r) {
            (Converge, Ok(r)) => {
                if let Err(e) = meets_bar(s, &r) {
                    failures.push(format!("{file} {g} {label}: {e}"));
                }
            }
            (Converge, Err(e)) => failures.push(format!("{file} {g} {label}: refused: {e}")),
            (Refused(why, alternatives), r) => {
                match r {
                    Err(e) if e.to_string().contains(why) => {}
                    other => failures.push(format!(
                        "{file} {g} {label}: expected a '{why}' refusal with Thurston, got {:?}",
                        other.map(|r| r.max_curvature_error)
                    )),
                }
                for &sc in alternatives {
                    let r = flow(s, g, sc, t.clone());
                    report(sc, &r);
                    match r {
                        Ok(r) => {
                            if let Err(e) = meets_bar(s, &r) {
                                failures.push(format!("{file} {g} {label} {sc}: {e}"));
                            }
                        }
                        Err(e) => failures.push(format!("{file} {g} {label} {sc}: {e}")),
                    }
                }
            }
            (RefusedOrStuck(why, note), r) => {
                if !matches!(&r, Err(e) if e.to_string().contains(why)) {
                    failures.push(format!("{file} {g} {label}: expected a '{why}' refusal"));
                }
                for sc in [Scheme::Tangential, Scheme::Inversive, Scheme::Yamabe] {
                    let r = flow(s, g, sc, t.clone());
                    report(sc, &r);
                    match r {
                        Ok(r) if !r.converged && r.notes.iter().any(|n| n.contains(note)) => {}
                        other => failures.push(format!(
                            "{file} {g} {label} {sc}: expected non-convergence explained by \
                             '{note}', got {:?}",
                            other.map(|r| (r.converged, r.notes))
                        )),
                    }
                }
            }
            (RefusedAll(why), r) => {
                let mut all = vec![(Scheme::Thurston, r)];
                if kind != SingleCone {
                    for sc in [Scheme::Tangential, Scheme::Inversive, Scheme::Yamabe] {
                        let r = flow(s, g, sc, t.clone());
                        report(sc, &r);
                        all.push((sc, r));
                    }
                }
                for (sc, r) in all {
                    match r {
                        Err(e) if e.to_string().contains(why) || sc != Scheme::Thurston => {}
                        other => failures.push(format!(
                            "{file} {g} {label} {sc}: expected a '{why}' refusal, got {:?}",
                            other.map(|r| r.max_curvature_error)
                        )),
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "failures:\n{}", failures.join("\n"));
}

#[test]
fn hemisphere_maps_conformally() {
    let Some(dir) = flow_support::meshes_dir() else {
        return;
    };
    let s = flow_support::read_mesh(&dir.join("hemisphere.obj"));
    let a0 = metric::corner_angles(&s.mesh, Geometry::Euclidean, &s.edge_lengths());
    for sc in [Scheme::Thurston, Scheme::Inversive, Scheme::Yamabe] {
        for t in [TargetSpec::FreeBoundary, TargetSpec::RoundBoundary] {
            let r = flow(&s, Geometry::Euclidean, sc, t.clone()).unwrap();
            meets_bar(&s, &r).unwrap();
            let a1 = metric::corner_angles(&s.mesh, Geometry::Euclidean, &r.lengths);
            let ratio: Vec<f64> = a1.iter().zip(&a0).map(|(x, y)| x / y).collect();
            let n = ratio.len() as f64;
            let within =
                |e: f64| ratio.iter().filter(|&&q| (q - 1.0).abs() <= e).count() as f64 / n;
            let mean = ratio.iter().map(|q| (q - 1.0).abs()).sum::<f64>() / n;
            let worst = ratio.iter().map(|q| (q - 1.0).abs()).fold(0.0, f64::max);
            eprintln!(
                "hemisphere {sc:10} {t:15}: angle ratio within 1%: {:5.1}%, within 5%: {:5.1}%, \
                 mean |ratio − 1| {mean:.2e}, max {worst:.2e}",
                100.0 * within(0.01),
                100.0 * within(0.05)
            );
            // Concentrated at 1 (paper 001 Fig. 7). Measured: inversive and Yamabe 100% within
            // 5%, mean 1.1e-2 (the O(h) change of triangle shapes under a varying conformal
            // factor); Thurston 66% within 5%, mean 4.0e-2 (its clamped, mostly tangent
            // circles only approximate the input's conformal structure).
            if sc == Scheme::Thurston {
                assert!(within(0.05) > 0.6 && mean < 0.05, "{sc} {t}");
            } else {
                assert!(within(0.05) > 0.999 && mean < 0.015, "{sc} {t}");
            }
        }
    }
    // Closed form on the same connectivity: vertices moved exactly onto the unit hemisphere
    // (boundary onto the equator); vertex scaling with u = 0 on the boundary must give the
    // stereographic projection, u = −log(1 + z).
    let c = s
        .positions
        .iter()
        .fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
    let nc = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let pole = c.map(|x| x / nc);
    let mut exact = s.clone();
    for (v, p) in exact.positions.iter_mut().enumerate() {
        let mut q = *p;
        if s.mesh.is_boundary_vertex(v as u32) {
            let d = q[0] * pole[0] + q[1] * pole[1] + q[2] * pole[2];
            q = [q[0] - d * pole[0], q[1] - d * pole[1], q[2] - d * pole[2]];
        }
        let m = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        *p = q.map(|x| x / m);
    }
    let r = flow(
        &exact,
        Geometry::Euclidean,
        Scheme::Yamabe,
        TargetSpec::FreeBoundary,
    )
    .unwrap();
    meets_bar(&exact, &r).unwrap();
    let worst = exact
        .positions
        .iter()
        .enumerate()
        .map(|(v, p)| {
            let z = p[0] * pole[0] + p[1] * pole[1] + p[2] * pole[2];
            (r.u[v] + (1.0 + z).ln()).abs()
        })
        .fold(0.0, f64::max);
    eprintln!("hemisphere.obj on the exact sphere: |u + log(1 + z)| ≤ {worst:.2e}");
    assert!(worst < 1e-9);
    let _ = Path::new(".");
}

/// Boundary vertices with one face ("ears") or two faces and φ = π/2 make beetle's geodesic
/// boundary unreachable (refused above). Metric-preserving splits of the edges opposite them
/// (`widen_boundary`, at least 3 faces per boundary vertex) keep the input metric — the
/// curvature of every input vertex is unchanged, new vertices are flat — and then Thurston's
/// scheme meets the bar of issue 3.
#[test]
fn beetle_converges_after_widening_the_boundary() {
    let Some(dir) = flow_support::meshes_dir() else {
        return;
    };
    let s = flow_support::read_mesh(&dir.join("beetle.off"));
    let l0 = s.edge_lengths();
    let r = ricci::metric::refine::widen_boundary(
        &s.mesh,
        &l0,
        Geometry::Euclidean,
        Some(&s.positions),
        3,
    )
    .unwrap();
    assert!(r.splits() > 0);
    for v in r.mesh.boundary_loops().into_iter().flatten() {
        assert!(r.mesh.vertex_faces(v).count() >= 3, "boundary vertex {v}");
    }
    // The same metric: curvature of the input vertices kept, new ones flat (interior, 2π).
    let k0 = metric::curvature(&s.mesh, Geometry::Euclidean, &l0);
    let k1 = metric::curvature(&r.mesh, Geometry::Euclidean, &r.lengths);
    let worst_old = (0..s.mesh.n_vertices())
        .map(|v| (k0[v] - k1[v]).abs())
        .fold(0.0, f64::max);
    let worst_new = k1[s.mesh.n_vertices()..]
        .iter()
        .map(|k| k.abs())
        .fold(0.0, f64::max);
    assert!(
        worst_old < 1e-9 && worst_new < 1e-9,
        "{worst_old:e} {worst_new:e}"
    );
    let refined = Surface {
        mesh: r.mesh.clone(),
        positions: r.positions.clone().unwrap(),
        uvs: None,
    };
    let f = ricci_flow(
        &r.mesh,
        &r.lengths,
        &FlowOptions {
            geometry: Geometry::Hyperbolic,
            target: TargetSpec::GeodesicBoundary,
            ..FlowOptions::default()
        },
        &mut NoProgress,
    )
    .unwrap();
    eprintln!(
        "beetle widened ({} splits): {} steps, max |K − K̄| {:.1e}",
        r.splits(),
        f.iterations,
        f.max_curvature_error
    );
    meets_bar(&refined, &f).unwrap();
}

/// The round boundaries of the convergence list are circles: laid out independently, the
/// boundary vertices of camelhead and hemisphere (Thurston) lie on one circle.
#[test]
fn round_boundaries_are_circles() {
    let Some(dir) = flow_support::meshes_dir() else {
        return;
    };
    for m in ["camelhead.off", "hemisphere.obj"] {
        let s = flow_support::read_mesh(&dir.join(m));
        let r = flow(
            &s,
            Geometry::Euclidean,
            Scheme::Thurston,
            TargetSpec::RoundBoundary,
        )
        .unwrap();
        meets_bar(&s, &r).unwrap();
        let spread = flow_support::boundary_circle_spread(&s.mesh, &r.lengths);
        eprintln!("{m} round-boundary (Thurston): boundary radius spread {spread:.2e}");
        assert!(spread <= 1e-8, "{m}: radius spread {spread:e}");
    }
}

/// face.off (a scanned disk whose boundary zig-zags: 114 of its 359 boundary vertices turn by
/// more than 1 rad, 82 are ears) to a round disk. On its own triangulation no scheme can:
/// vertex scaling's convex energy has its minimum at a "metric" with 77 faces violating the
/// triangle inequality, and Thurston is refused by Chow–Luo (checked above). Metric-preserving
/// refinement makes the discrete conformal metric exist: boundary widening (every boundary
/// vertex ≥ 3 faces), then adaptive longest-edge bisection of the faces where the flow's
/// metric degenerates (`ricci::flow::ricci_flow_refined`; while Thurston is refused, a
/// vertex-scaling probe finds the faces). Asserted for the default scheme (Thurston) and for
/// vertex scaling: the bar of issue 3 on the refined mesh, the laid-out boundary is a circle,
/// the refinement kept the input vertices (ids, positions, curvature of the input metric) and
/// made every new vertex flat, and no face of the final metric is degenerate.
#[test]
fn face_round_boundary_after_adaptive_refinement() {
    let Some(dir) = flow_support::meshes_dir() else {
        return;
    };
    let s = flow_support::read_mesh(&dir.join("face.off"));
    let l0 = s.edge_lengths();
    for scheme in [Scheme::Thurston, Scheme::Yamabe] {
        let widened = ricci::metric::refine::widen_boundary(
            &s.mesh,
            &l0,
            Geometry::Euclidean,
            Some(&s.positions),
            3,
        )
        .unwrap();
        let options = FlowOptions {
            scheme,
            target: TargetSpec::RoundBoundary,
            ..FlowOptions::default()
        };
        let (refined, r) =
            ricci::flow::ricci_flow_refined(widened, &options, 40, &mut NoProgress).unwrap();
        eprintln!(
            "face.off round-boundary {scheme}: {} → {} faces, {} Newton steps, max |K − K̄| \
             {:.2e}, GB {:.1e}, {:.2} s; {:?}",
            s.mesh.n_faces(),
            refined.mesh.n_faces(),
            r.iterations,
            r.max_curvature_error,
            r.gauss_bonnet_error,
            r.seconds,
            r.notes
        );
        check_refined_face(&s, &refined, &r);
    }
}

/// The assertions of `face_round_boundary_after_adaptive_refinement` for one flow.
fn check_refined_face(s: &Surface, refined: &ricci::metric::refine::Refined, r: &FlowResult) {
    let l0 = s.edge_lengths();
    let n0 = s.mesh.n_vertices();
    let surf = Surface {
        mesh: refined.mesh.clone(),
        positions: refined.positions.clone().unwrap(),
        uvs: None,
    };
    meets_bar(&surf, r).unwrap();
    assert_eq!(r.degenerate_faces, 0);
    assert!(ricci::flow::adaptive::under_resolved_faces(
        &refined.mesh,
        Geometry::Euclidean,
        &r.lengths
    )
    .is_empty());
    // The boundary is round.
    let spread = flow_support::boundary_circle_spread(&refined.mesh, &r.lengths);
    eprintln!("face.off: boundary radius spread {spread:.2e}");
    assert!(spread <= 1e-8, "radius spread {spread:e}");
    // The refinement kept the input: ids and positions of the input vertices, boundary
    // vertices on the boundary, new vertices on input edges (at their interpolated position).
    let p = refined.positions.as_ref().unwrap();
    assert_eq!(refined.original_vertices, n0);
    assert_eq!(&p[..n0], &s.positions[..]);
    for v in 0..n0 as u32 {
        assert_eq!(
            s.mesh.is_boundary_vertex(v),
            refined.mesh.is_boundary_vertex(v),
            "vertex {v}"
        );
    }
    for (k, sv) in refined.new_vertices.iter().enumerate() {
        let q = p[n0 + k];
        let (a, b) = (p[sv.a as usize], p[sv.b as usize]);
        let lerp = [0, 1, 2].map(|i| (1.0 - sv.t) * a[i] + sv.t * b[i]);
        assert!((0..3).all(|i| (q[i] - lerp[i]).abs() <= 1e-12 * (1.0 + lerp[i].abs())));
    }
    // The same metric: curvature of the input vertices unchanged, new vertices flat.
    let k0 = metric::curvature(&s.mesh, Geometry::Euclidean, &l0);
    let k1 = metric::curvature(&refined.mesh, Geometry::Euclidean, &refined.lengths);
    let worst_old = (0..n0).map(|v| (k0[v] - k1[v]).abs()).fold(0.0, f64::max);
    let worst_new = k1[n0..].iter().map(|k| k.abs()).fold(0.0, f64::max);
    assert!(
        worst_old < 1e-9 && worst_new < 1e-9,
        "{worst_old:e} {worst_new:e}"
    );
    let a0 = metric::total_area(&s.mesh, Geometry::Euclidean, &l0);
    let a1 = metric::total_area(&refined.mesh, Geometry::Euclidean, &refined.lengths);
    assert!((a0 - a1).abs() <= 1e-10 * a0);
}
