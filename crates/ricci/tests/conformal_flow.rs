//! Discrete conformal equivalence (vertex scaling with intrinsic Delaunay / Ptolemy flips,
//! `ricci::flow::conformal`): derivatives by finite differences after flips, convexity and the
//! closed-form Euclidean energy of Bobenko–Pinkall–Springborn, independence of the starting
//! triangulation, and the issue's real meshes (`$RICCI_MESHES`).

#![allow(clippy::needless_range_loop)]

use ricci::flow::conformal::{evaluate, hessian_triplets, ConformalState};
use ricci::flow::{ricci_flow, separated_vertices, FlowOptions, FlowResult, TargetSpec};
use ricci::mesh::{generate, Mesh, Surface};
use ricci::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{self, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

struct Rng(u64);
impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn genus2() -> Surface {
    generate::genus(2, 12).unwrap()
}

/// The Delaunay triangulation of `s`'s metric in `geometry` (lengths scaled by `scale`).
fn delaunay(s: &Surface, geometry: Geometry, scale: f64) -> IntrinsicTriangulation {
    let l: Vec<f64> = s.edge_lengths().iter().map(|x| x * scale).collect();
    let mut t = IntrinsicTriangulation::from_mesh(&s.mesh, geometry, &l).unwrap();
    assert!(t.make_delaunay_isometric(geometry, 1_000_000).delaunay);
    t
}

fn mean_edge(s: &Surface) -> f64 {
    let l = s.edge_lengths();
    l.iter().sum::<f64>() / l.len() as f64
}

fn eval(
    t: &IntrinsicTriangulation,
    g: Geometry,
    u: &[f64],
) -> (IntrinsicTriangulation, ConformalState) {
    let mut t = t.clone();
    let mut st = ConformalState::default();
    assert!(evaluate(&mut t, g, u, 10_000_000, &mut st));
    (t, st)
}

/// Curvature and Hessian by central differences at a `u` where flips happened.
fn check_derivatives(geometry: Geometry, scale: f64) {
    let s = genus2();
    let t0 = delaunay(&s, geometry, scale);
    let n = t0.n_vertices;
    let mut rng = Rng::new(17);
    let u: Vec<f64> = (0..n).map(|_| 0.8 * (rng.next() - 0.5)).collect();
    let (t, st) = eval(&t0, geometry, &u);
    assert!(
        t.flip_log.len() > t0.flip_log.len(),
        "no flips at the test point"
    );
    let h = hessian_triplets(&t, &st);
    let mut dense = vec![vec![0.0; n]; n];
    for (i, j, v) in h {
        dense[i as usize][j as usize] += v;
    }
    let eps = 1e-6;
    let mut worst = 0.0f64;
    let mut scale_h = 0.0f64;
    for j in (0..n).step_by(7) {
        let mut up = u.clone();
        let mut um = u.clone();
        up[j] += eps;
        um[j] -= eps;
        let (_, sp) = eval(&t, geometry, &up);
        let (_, sm) = eval(&t, geometry, &um);
        for i in 0..n {
            let fd = (sp.curvature[i] - sm.curvature[i]) / (2.0 * eps);
            worst = worst.max((fd - dense[i][j]).abs());
            scale_h = scale_h.max(dense[i][j].abs());
            assert!(
                (dense[i][j] - dense[j][i]).abs() <= 1e-10 * (1.0 + dense[i][j].abs()),
                "Hessian not symmetric at ({i}, {j})"
            );
        }
    }
    assert!(
        worst <= 1e-6 * scale_h.max(1.0),
        "{geometry:?}: FD mismatch {worst:e} (scale {scale_h:e})"
    );
}

#[test]
fn curvature_and_hessian_match_finite_differences_after_flips_e2() {
    check_derivatives(Geometry::Euclidean, 1.0);
}

#[test]
fn curvature_and_hessian_match_finite_differences_after_flips_h2() {
    let s = genus2();
    check_derivatives(Geometry::Hyperbolic, 0.3 / mean_edge(&s));
}

/// Lobachevsky's function Л(x) = −∫₀ˣ log|2 sin t| dt = ½ Cl₂(2x), by the Bernoulli series of
/// Clausen's function on (−π, π].
fn lobachevsky(x: f64) -> f64 {
    let mut th = (2.0 * x).rem_euclid(2.0 * PI);
    if th > PI {
        th -= 2.0 * PI;
    }
    if th == 0.0 {
        return 0.0;
    }
    // Cl₂(θ) = θ − θ log|θ| + Σ_{n≥1} |B_2n| θ^{2n+1} / (2n (2n+1)!).
    let b = [
        1.0 / 6.0,
        1.0 / 30.0,
        1.0 / 42.0,
        1.0 / 30.0,
        5.0 / 66.0,
        691.0 / 2730.0,
        7.0 / 6.0,
        3617.0 / 510.0,
        43867.0 / 798.0,
        174611.0 / 330.0,
        854513.0 / 138.0,
        236364091.0 / 2730.0,
        8553103.0 / 6.0,
        23749461029.0 / 870.0,
        8615841276005.0 / 14322.0,
        7709321041217.0 / 510.0,
        2577687858367.0 / 6.0,
    ];
    let mut s = th - th * th.abs().ln();
    let mut fact = 1.0; // (2n+1)!
    let mut pow = th;
    for (k, bk) in b.iter().enumerate() {
        let n = (k + 1) as f64;
        fact *= (2.0 * n) * (2.0 * n + 1.0);
        pow *= th * th;
        s += bk * pow / (2.0 * n * fact);
    }
    0.5 * s
}

/// The Euclidean energy of Bobenko–Pinkall–Springborn (2015, eq. 4.4 up to sign and constant):
/// `E(u) = Σ_faces [2F(λ̃) − (π/2)(λ̃₁+λ̃₂+λ̃₃)] + Σ_v Θ_v u_v`, `F = ½Σ θ λ̃ + Σ Л(θ)` with θ
/// opposite λ̃ and `Θ_v = 2π − K̄_v` (π − K̄_v on the boundary); its gradient is `K − K̄`.
fn bps_energy(t: &IntrinsicTriangulation, u: &[f64], target: &[f64]) -> f64 {
    let mut e = 0.0;
    for f in 0..t.n_faces() as u32 {
        let mut lam = [0.0; 3];
        let mut l = [0.0; 3];
        for m in 0..3 {
            let h = 3 * f + (m as u32 + 1) % 3;
            lam[m] = t.lambda[t.edge[h as usize] as usize]
                + u[t.origin[h as usize] as usize]
                + u[t.tip(h) as usize];
            l[m] = length_of_lambda(Geometry::Euclidean, lam[m]);
        }
        let th = [
            Geometry::Euclidean.angle(l[0], l[1], l[2]),
            Geometry::Euclidean.angle(l[1], l[2], l[0]),
            Geometry::Euclidean.angle(l[2], l[0], l[1]),
        ];
        for m in 0..3 {
            e += th[m] * lam[m] + 2.0 * lobachevsky(th[m]) - 0.5 * PI * lam[m];
        }
    }
    for v in 0..t.n_vertices {
        let base = if t.boundary_vertex[v] { PI } else { 2.0 * PI };
        e += (base - target[v]) * u[v];
    }
    e
}

#[test]
fn lobachevsky_matches_quadrature() {
    for &x in &[0.1, 0.5, 1.0, 1.4, 2.0, 2.9] {
        // −∫₀ˣ log(2 sin t) dt by composite Simpson on [δ, x] plus the series near 0.
        let d: f64 = 1e-3;
        // −∫₀^δ log(2 sin t) dt with log(2 sin t) = log 2t − t²/6 + O(t⁴).
        let near = -(d * (2.0 * d).ln() - d - d * d * d / 18.0);
        let n = 20000;
        let h = (x - d) / n as f64;
        let f = |t: f64| -(2.0 * t.sin()).abs().ln();
        let mut s = f(d) + f(x);
        for k in 1..n {
            s += if k % 2 == 1 { 4.0 } else { 2.0 } * f(d + k as f64 * h);
        }
        let q = near + s * h / 3.0;
        assert!(
            (lobachevsky(x) - q).abs() < 1e-8,
            "Л({x}) = {} vs {q}",
            lobachevsky(x)
        );
    }
}

#[test]
fn euclidean_energy_gradient_is_curvature_and_convex_across_flips() {
    let s = genus2();
    let t0 = delaunay(&s, Geometry::Euclidean, 1.0);
    let n = t0.n_vertices;
    let chi = metric::euler_characteristic(&s.mesh) as f64;
    // A Gauss–Bonnet target: 2πχ spread over every vertex.
    let target = vec![2.0 * PI * chi / n as f64; n];
    let mut rng = Rng::new(5);
    let energy = |u: &[f64]| {
        let (t, _) = eval(&t0, Geometry::Euclidean, u);
        bps_energy(&t, u, &target)
    };
    for _ in 0..3 {
        let u: Vec<f64> = (0..n).map(|_| 0.8 * (rng.next() - 0.5)).collect();
        let d: Vec<f64> = (0..n).map(|_| rng.next() - 0.5).collect();
        let (t, st) = eval(&t0, Geometry::Euclidean, &u);
        assert!(t.flip_log.len() > t0.flip_log.len());
        // Directional derivative of the closed form vs (K − K̄)·d.
        let g: f64 = (0..n).map(|i| (st.curvature[i] - target[i]) * d[i]).sum();
        let eps = 1e-5;
        let up: Vec<f64> = (0..n).map(|i| u[i] + eps * d[i]).collect();
        let um: Vec<f64> = (0..n).map(|i| u[i] - eps * d[i]).collect();
        let fd = (energy(&up) - energy(&um)) / (2.0 * eps);
        assert!(
            (fd - g).abs() <= 1e-6 * (1.0 + g.abs()),
            "dE = {fd} vs (K − K̄)·d = {g}"
        );
        // Convexity along the line through u with direction d, long enough to cross flips.
        let ts: Vec<f64> = (0..=40).map(|k| -1.0 + 0.05 * k as f64).collect();
        let es: Vec<f64> = ts
            .iter()
            .map(|&t| energy(&(0..n).map(|i| u[i] + t * d[i]).collect::<Vec<_>>()))
            .collect();
        for k in 1..es.len() - 1 {
            let second = es[k + 1] - 2.0 * es[k] + es[k - 1];
            assert!(
                second >= -1e-9 * (1.0 + es[k].abs()),
                "not convex at t = {}: {second}",
                ts[k]
            );
        }
    }
}

#[test]
fn hyperbolic_energy_is_convex_along_lines() {
    // Convexity ⟺ the directional derivative g(t) = (K(u + t d) − K̄)·d increases with t.
    let s = genus2();
    let t0 = delaunay(&s, Geometry::Hyperbolic, 0.3 / mean_edge(&s));
    let n = t0.n_vertices;
    let mut rng = Rng::new(9);
    for _ in 0..3 {
        let u: Vec<f64> = (0..n).map(|_| 0.8 * (rng.next() - 0.5)).collect();
        let d: Vec<f64> = (0..n).map(|_| rng.next() - 0.5).collect();
        let mut last = f64::NEG_INFINITY;
        let mut flips = 0;
        for k in 0..=40 {
            let t = -1.0 + 0.05 * k as f64;
            let p: Vec<f64> = (0..n).map(|i| u[i] + t * d[i]).collect();
            let (tri, st) = eval(&t0, Geometry::Hyperbolic, &p);
            flips = flips.max(tri.flip_log.len() - t0.flip_log.len());
            let g: f64 = (0..n).map(|i| st.curvature[i] * d[i]).sum();
            assert!(g >= last - 1e-9, "g decreased at t = {t}: {g} < {last}");
            last = g;
        }
        assert!(flips > 0);
    }
}

fn conformal(s: &Surface, g: Geometry, t: TargetSpec) -> FlowResult {
    conformal_lengths(&s.mesh, &s.edge_lengths(), g, t)
}

fn conformal_lengths(mesh: &Mesh, l: &[f64], g: Geometry, t: TargetSpec) -> FlowResult {
    let o = FlowOptions {
        geometry: g,
        scheme: Scheme::Conformal,
        target: t,
        ..FlowOptions::default()
    };
    ricci_flow(mesh, l, &o, &mut NoProgress).unwrap()
}

/// A converged result: tolerance, Gauss–Bonnet on the simplicial mesh, no degenerate face.
fn check_result(name: &str, r: &FlowResult) {
    assert!(
        r.converged && r.max_curvature_error <= 1e-10,
        "{name}: max |K − K̄| = {:e} after {} iterations, notes {:?}",
        r.max_curvature_error,
        r.iterations,
        r.notes
    );
    assert_eq!(r.degenerate_faces, 0, "{name}");
    assert!(
        r.gauss_bonnet_error < 1e-8,
        "{name}: GB {:e}",
        r.gauss_bonnet_error
    );
    let tri = r.triangulation.as_ref().unwrap();
    let sm = &tri.simplicial;
    let gb = metric::gauss_bonnet_residual(&sm.mesh, r.geometry, &r.lengths);
    assert!(gb < 1e-8, "{name}: simplicial Gauss–Bonnet {gb:e}");
    // Curvature on the simplicial mesh: the solver's at input vertices, 0 at split vertices.
    let k = metric::curvature(&sm.mesh, r.geometry, &r.lengths);
    for v in 0..k.len() {
        let want = if v < r.curvature.len() {
            r.curvature[v]
        } else {
            0.0
        };
        assert!(
            (k[v] - want).abs() < 1e-9,
            "{name}: vertex {v}: {} vs {want}",
            k[v]
        );
    }
}

#[test]
fn genus2_cones_and_single_cone() {
    let s = genus2();
    let chi = metric::euler_characteristic(&s.mesh);
    let cones = separated_vertices(&s.mesh, (-chi) as usize, 5);
    let r = conformal(
        &s,
        Geometry::Euclidean,
        TargetSpec::Cones(cones.iter().map(|&v| (v, -2.0 * PI)).collect()),
    );
    check_result("genus-2 cones", &r);
    let r = conformal(
        &s,
        Geometry::Euclidean,
        TargetSpec::SingleCone(Some(cones[0])),
    );
    check_result("genus-2 single cone", &r);
    let r = conformal(&s, Geometry::Hyperbolic, TargetSpec::Uniform);
    check_result("genus-2 H²", &r);
}

/// Random isometric flips of convex quads that keep the triangulation simplicial.
fn retriangulate(s: &Surface, seed: u64, count: usize) -> (Mesh, Vec<f64>) {
    let mut t =
        IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Euclidean, &s.edge_lengths()).unwrap();
    let mut rng = Rng::new(seed);
    let mut done = 0;
    let mut tries = 0;
    while done < count && tries < 100 * count {
        tries += 1;
        let e = (rng.next() * t.n_edges() as f64) as u32;
        if !t.is_flippable(e) {
            continue;
        }
        let h = t.edge_he[e as usize];
        let tw = t.twin[h as usize];
        let l =
            |x: u32| length_of_lambda(Geometry::Euclidean, t.lambda[t.edge[x as usize] as usize]);
        let ang = |a: u32, b: u32, c: u32| Geometry::Euclidean.angle(l(a), l(b), l(c));
        let nx = IntrinsicTriangulation::next;
        let pv = IntrinsicTriangulation::prev;
        // Angles at origin(h) and tip(h) in both faces must sum below π (convex quad).
        let at_i = ang(nx(h), h, pv(h)) + ang(pv(tw), tw, nx(tw));
        let at_j = ang(pv(h), h, nx(h)) + ang(nx(tw), tw, pv(tw));
        if at_i >= PI - 0.1 || at_j >= PI - 0.1 {
            continue;
        }
        let k = t.origin[pv(h) as usize];
        let m = t.origin[pv(tw) as usize];
        let exists = (0..t.n_edges() as u32).any(|f| {
            let [a, b] = t.edge_vertices(f);
            (a == k && b == m) || (a == m && b == k)
        });
        if k == m || exists {
            continue;
        }
        t.flip_isometric(e, Geometry::Euclidean);
        done += 1;
    }
    assert!(done >= count / 2);
    let sm = t.to_simplicial(Geometry::Euclidean, &[]).unwrap();
    assert_eq!(sm.splits, 0);
    (sm.mesh, sm.lengths)
}

#[test]
fn result_does_not_depend_on_the_starting_triangulation() {
    // A torus of revolution and the same polyhedral surface retriangulated by random
    // isometric flips: the flat metrics agree (u per vertex up to a constant, and the sorted
    // edge lengths of the final Delaunay triangulations).
    let s = ricci::mesh::generate::torus(1.0, 0.4, 12).unwrap();
    let (mesh2, l2) = retriangulate(&s, 3, s.mesh.n_edges() / 4);
    let a = conformal(&s, Geometry::Euclidean, TargetSpec::Uniform);
    let b = conformal_lengths(&mesh2, &l2, Geometry::Euclidean, TargetSpec::Uniform);
    check_result("torus", &a);
    check_result("retriangulated torus", &b);
    let n = a.u.len();
    let ma = a.u.iter().sum::<f64>() / n as f64;
    let mb = b.u.iter().sum::<f64>() / n as f64;
    let du = (0..n)
        .map(|i| ((a.u[i] - ma) - (b.u[i] - mb)).abs())
        .fold(0.0, f64::max);
    assert!(du < 1e-8, "u differs by {du:e}");
    let sorted = |r: &FlowResult| {
        let t = &r.triangulation.as_ref().unwrap().triangulation;
        let mut l = t.lengths(Geometry::Euclidean, &[]);
        l.sort_by(f64::total_cmp);
        l
    };
    let (la, lb) = (sorted(&a), sorted(&b));
    let dl = la
        .iter()
        .zip(&lb)
        .map(|(x, y)| (x - y).abs() / y)
        .fold(0.0, f64::max);
    assert!(dl < 1e-8, "final Delaunay lengths differ by {dl:e}");
}

mod ricci_meshes;

fn mesh_dir() -> Option<std::path::PathBuf> {
    let d = ricci_meshes::ricci_meshes()?;
    d.is_dir().then_some(d)
}

fn read(name: &str) -> Option<Surface> {
    let d = mesh_dir()?;
    Some(ricci::mesh::io::read_surface(&d.join(name)).unwrap().0)
}

/// The issue's list: every case converges to max |K − K̄| ≤ 1e-10 with no degenerate face,
/// Gauss–Bonnet holds on the simplicial mesh and the round boundaries are round.
#[test]
fn issue_meshes_converge() {
    if mesh_dir().is_none() {
        eprintln!("RICCI_MESHES not set: skipping");
        return;
    }
    use Geometry::*;
    let cases = [
        ("kitten.nf20k.off", Euclidean, TargetSpec::Uniform),
        ("rocker-arm.off", Euclidean, TargetSpec::Uniform),
        ("eight.off", Hyperbolic, TargetSpec::Uniform),
        ("3holes.off", Hyperbolic, TargetSpec::Uniform),
        ("seahorse2_100K.off", Hyperbolic, TargetSpec::Uniform),
        ("camelhead.off", Euclidean, TargetSpec::FreeBoundary),
        ("camelhead.off", Euclidean, TargetSpec::RoundBoundary),
        ("face.off", Euclidean, TargetSpec::RoundBoundary),
        ("beetle.off", Hyperbolic, TargetSpec::GeodesicBoundary),
        ("bunny.off", Euclidean, TargetSpec::FreeBoundary),
    ];
    for (file, g, t) in cases {
        let s = read(file).unwrap();
        let name = format!("{file} {g:?} {t:?}");
        let r = conformal(&s, g, t.clone());
        check_result(&name, &r);
        if t == TargetSpec::FreeBoundary {
            // Boundary lengths are kept: u = 0 on the boundary.
            for v in 0..s.mesh.n_vertices() as u32 {
                if s.mesh.is_boundary_vertex(v) {
                    assert_eq!(r.u[v as usize], 0.0, "{name}: u at boundary vertex {v}");
                }
            }
        }
        if t == TargetSpec::RoundBoundary {
            // Quadratic convergence needs the exact Jacobian H − ∂K̄/∂u (chord steps alone
            // took 26 (camelhead) and 28 (face.off) steps).
            assert!(r.iterations <= 15, "{name}: {} iterations", r.iterations);
            // Every boundary loop's vertices lie on a circle: for each loop the radius from
            // the final boundary lengths and targets agrees with the turning of every vertex
            // (K̄ = (α_a + α_b)/2 with α = 2 asin(l / 2R)).
            let tri = &r.triangulation.as_ref().unwrap().triangulation;
            for lp in s.mesh.boundary_loop_halfedges() {
                let edges: Vec<u32> = lp.iter().map(|&h| s.mesh.he_edge(h)).collect();
                let l: Vec<f64> = edges
                    .iter()
                    .map(|&e| length_of_lambda(Geometry::Euclidean, tri.lambda[e as usize]))
                    .collect();
                let total: f64 = lp
                    .iter()
                    .map(|&h| r.curvature[s.mesh.he_origin(h) as usize])
                    .sum();
                let radius = ricci::flow::target::circle_radius(&l, total.abs());
                let n = l.len();
                for k in 0..n {
                    let v = s.mesh.he_origin(lp[(k + 1) % n]) as usize;
                    let a = |x: f64| 2.0 * (x / (2.0 * radius)).min(1.0).asin();
                    let want = total.signum() * 0.5 * (a(l[k]) + a(l[(k + 1) % n]));
                    assert!(
                        (r.curvature[v] - want).abs() < 1e-9,
                        "{name}: boundary vertex {v}: K = {} but the circle needs {want}",
                        r.curvature[v]
                    );
                }
            }
        }
    }
}

fn lattice_normalized(r: &FlowResult, count: usize) -> Vec<f64> {
    use ricci::analysis::spectrum::lattice_spectrum;
    use ricci::layout::deck_group;
    use ricci::layout::pipeline::cut_disk;
    use ricci::layout::place::layout;
    use ricci::metric::Euclidean;
    let sm = &r.triangulation.as_ref().unwrap().simplicial;
    let disk = cut_disk(
        &sm.mesh,
        &IntrinsicMetric::new(Geometry::Euclidean, r.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    let l = layout::<Euclidean>(&disk.mesh, &disk.metric, None).unwrap();
    assert!(l.flipped_faces.is_empty());
    let g = deck_group::<Euclidean>(&l, &disk.polygon).unwrap();
    let gens = g.named_generators();
    let sp = lattice_spectrum(gens[0].1.t, gens[1].1.t, count).unwrap();
    sp.iter().map(|x| x / sp[0]).collect()
}

/// Conformal moduli from the intrinsic triangulation. kitten: normalized lattice lengths
/// 1, 2, 2.1790 (the issue's harmonic 1-forms reference), ± 0.3 %. torus.off (R = 1,
/// r = 0.25, 1200 vertices): the smooth torus is a rectangle r : √(R² − r²), lengths 1, 2, 3,
/// √15 = 3.8730; this coarse polyhedral torus gives 3.8888 (+0.41 %) with every scheme that
/// keeps its metric (vertex scaling without flips gives the same 3.88876: all its grid quads
/// are intrinsically cocircular isosceles trapezoids, so Ptolemy flips are isometric there),
/// hence 0.5 % against the closed form and 1e-8 against vertex scaling.
#[test]
fn spectra_on_the_intrinsic_triangulation() {
    if mesh_dir().is_none() {
        eprintln!("RICCI_MESHES not set: skipping");
        return;
    }
    let s = read("kitten.nf20k.off").unwrap();
    let r = conformal(&s, Geometry::Euclidean, TargetSpec::Uniform);
    check_result("kitten", &r);
    let sp = lattice_normalized(&r, 4);
    assert!((sp[2] / 2.1790 - 1.0).abs() < 3e-3, "kitten: {sp:?}");
    let s = read("torus.off").unwrap();
    let r = conformal(&s, Geometry::Euclidean, TargetSpec::Uniform);
    check_result("torus.off", &r);
    let sp = lattice_normalized(&r, 4);
    assert!((sp[3] / 15f64.sqrt() - 1.0).abs() < 5e-3, "torus: {sp:?}");
    // Vertex scaling on the input triangulation, through the other solver.
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Yamabe,
        target: TargetSpec::Uniform,
        tolerance: 1e-11,
        ..FlowOptions::default()
    };
    let y = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap();
    assert!(y.converged);
    let disk = ricci::layout::pipeline::cut_disk(
        &s.mesh,
        &IntrinsicMetric::new(Geometry::Euclidean, y.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    let l =
        ricci::layout::place::layout::<ricci::metric::Euclidean>(&disk.mesh, &disk.metric, None)
            .unwrap();
    let g = ricci::layout::deck_group::<ricci::metric::Euclidean>(&l, &disk.polygon).unwrap();
    let gens = g.named_generators();
    let spy = ricci::analysis::spectrum::lattice_spectrum(gens[0].1.t, gens[1].1.t, 4).unwrap();
    assert!(
        (sp[3] - spy[3] / spy[0]).abs() < 1e-8,
        "{sp:?} vs vertex scaling {spy:?}"
    );
}

/// `to_simplicial` on Δ-complexes with self-loops and multi-edges: the split vertices are flat,
/// the input vertices keep their curvature, in E² and H².
#[test]
fn to_simplicial_splits_loops_and_multi_edges() {
    for (geometry, scale) in [(Geometry::Euclidean, 1.0), (Geometry::Hyperbolic, 0.5)] {
        let s = ricci::mesh::generate::torus(1.0, 0.4, 12).unwrap();
        let s = if geometry == Geometry::Hyperbolic {
            genus2()
        } else {
            s
        };
        let t0 = delaunay(&s, geometry, scale / mean_edge(&s));
        let n = t0.n_vertices;
        // Every vertex but one pushed far away: the Delaunay triangulation joins the remaining
        // one to itself around the handles (self-loops) and to the others by several edges.
        let mut u = vec![
            if geometry == Geometry::Euclidean {
                12.0
            } else {
                6.0
            };
            n
        ];
        u[0] = 0.0;
        let (t, st) = eval(&t0, geometry, &u);
        let bad = (0..t.n_edges() as u32)
            .filter(|&e| {
                let [a, b] = t.edge_vertices(e);
                a == b
            })
            .count();
        let sm = t.to_simplicial(geometry, &u).unwrap();
        assert!(
            sm.splits > 0,
            "{geometry:?}: no splits needed ({bad} loops)"
        );
        let k = metric::curvature(&sm.mesh, geometry, &sm.lengths);
        for v in 0..sm.mesh.n_vertices() {
            let want = if v < n { st.curvature[v] } else { 0.0 };
            assert!(
                (k[v] - want).abs() < 1e-9,
                "{geometry:?}: vertex {v}: {} vs {want}",
                k[v]
            );
            assert_eq!(sm.vertex_origin[v], if v < n { v as u32 } else { u32::MAX });
        }
        let deg0 = (0..t.n_edges() as u32)
            .filter(|&e| t.edge_vertices(e).contains(&0))
            .count();
        eprintln!(
            "{geometry:?}: {bad} loops, {} splits, {} flips, {deg0} edges at vertex 0",
            sm.splits,
            t.flip_log.len() - t0.flip_log.len()
        );
    }
}

/// The contract with input-edge tracking: replaying `flip_log` on the input triangulation
/// reproduces the final connectivity (same half-edge arrays, edge ids and end points).
#[test]
fn flip_log_replays_to_the_final_triangulation() {
    let s = genus2();
    let chi = metric::euler_characteristic(&s.mesh);
    let cones = separated_vertices(&s.mesh, (-chi) as usize, 5);
    let r = conformal(
        &s,
        Geometry::Euclidean,
        TargetSpec::Cones(cones.iter().map(|&v| (v, -2.0 * PI)).collect()),
    );
    check_result("genus-2 cones", &r);
    let fin = &r.triangulation.as_ref().unwrap().triangulation;
    // A long log (92 flips since the line search stopped re-evaluating trial points, which
    // flipped edges back and forth; 100+ before).
    assert!(fin.flip_log.len() > 50, "flip log {}", fin.flip_log.len());
    let mut t =
        IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Euclidean, &s.edge_lengths()).unwrap();
    for &e in &fin.flip_log {
        assert!(t.flip(e), "edge {e} of the log cannot be flipped on replay");
    }
    assert_eq!(t.origin, fin.origin);
    assert_eq!(t.twin, fin.twin);
    assert_eq!(t.edge, fin.edge);
}
