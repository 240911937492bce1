//! Planar DMS triangular B-splines (issue 7, task dms): partition of unity, polynomial
//! reproduction, C^{n−1} continuity across domain edges, derivatives against finite
//! differences, fairing and fitting.

#![allow(clippy::needless_range_loop)]

use ricci::spline::dms::{DmsSpace, Domain, KnotOptions, Precision, Workspace};
use ricci::spline::poly::Polynomial;
use ricci::spline::simplex::{n_partials, Point};

/// Small deterministic generator (xorshift*).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A jittered m×m grid of the unit square, diagonals alternating (all parallel when
/// `jitter < 0`; the jitter amplitude is `|jitter|`).
fn grid_domain(m: usize, jitter: f64, seed: u64) -> Domain {
    let mut rng = Rng(seed);
    let mut pts = Vec::new();
    for j in 0..=m {
        for i in 0..=m {
            let (mut x, mut y) = (i as f64 / m as f64, j as f64 / m as f64);
            if i > 0 && i < m && j > 0 && j < m {
                x += jitter.abs() / m as f64 * (rng.next() - 0.5);
                y += jitter.abs() / m as f64 * (rng.next() - 0.5);
            }
            pts.push([x, y]);
        }
    }
    let id = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    let mut tris = Vec::new();
    for j in 0..m {
        for i in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 || jitter < 0.0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    Domain::new(pts, tris).unwrap()
}

/// An L-shaped domain (with a reflex boundary vertex): the 2×2 square minus its top-right
/// quarter, triangulated from a jittered grid.
fn l_domain(m: usize, seed: u64) -> Domain {
    let g = grid_domain(2 * m, 0.3, seed);
    let pts = g.points().to_vec();
    let tris: Vec<[u32; 3]> = g
        .triangles()
        .iter()
        .copied()
        .filter(|t| {
            let c = [
                (pts[t[0] as usize][0] + pts[t[1] as usize][0] + pts[t[2] as usize][0]) / 3.0,
                (pts[t[0] as usize][1] + pts[t[1] as usize][1] + pts[t[2] as usize][1]) / 3.0,
            ];
            !(c[0] > 0.5 && c[1] > 0.5)
        })
        .collect();
    // Drop unused vertices.
    let mut map = vec![u32::MAX; pts.len()];
    let mut np = Vec::new();
    let mut nt = Vec::new();
    for t in &tris {
        let mut u = [0u32; 3];
        for k in 0..3 {
            let v = t[k] as usize;
            if map[v] == u32::MAX {
                map[v] = np.len() as u32;
                np.push(pts[v]);
            }
            u[k] = map[v];
        }
        nt.push(u);
    }
    Domain::new(np, nt).unwrap()
}

/// A disk: a centre of valence 7 and two rings, irregular.
fn disk_domain() -> Domain {
    let mut pts = vec![[0.0, 0.0]];
    let rings = [(7usize, 0.45), (14, 1.0)];
    for (k, r) in rings {
        for i in 0..k {
            let a = 2.0 * std::f64::consts::PI * (i as f64 + 0.3 * (k as f64).sin()) / k as f64;
            pts.push([r * a.cos(), r * a.sin()]);
        }
    }
    let mut tris = Vec::new();
    for i in 0..7u32 {
        tris.push([0, 1 + i, 1 + (i + 1) % 7]);
    }
    // Inner ring vertex i sits between outer vertices 2i and 2i+1.
    for i in 0..7u32 {
        let a = 1 + i;
        let b = 1 + (i + 1) % 7;
        let o0 = 8 + 2 * i;
        let o1 = 8 + (2 * i + 1) % 14;
        let o2 = 8 + (2 * i + 2) % 14;
        tris.push([a, o0, o1]);
        tris.push([a, o1, b]);
        tris.push([b, o1, o2]);
    }
    Domain::new(pts, tris).unwrap()
}

/// A fan of 24 thin triangles (15° at the centre) with a ring of triangles around it.
fn thin_fan_domain() -> Domain {
    let k = 24u32;
    let mut pts = vec![[0.0, 0.0]];
    for i in 0..k {
        let a = 2.0 * std::f64::consts::PI * i as f64 / k as f64;
        pts.push([a.cos(), a.sin()]);
    }
    for i in 0..k {
        let a = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / k as f64;
        pts.push([1.15 * a.cos(), 1.15 * a.sin()]);
    }
    let mut tris = Vec::new();
    for i in 0..k {
        tris.push([0, 1 + i, 1 + (i + 1) % k]);
        tris.push([1 + i, 1 + k + i, 1 + (i + 1) % k]);
    }
    Domain::new(pts, tris).unwrap()
}

fn domains() -> Vec<(&'static str, Domain)> {
    vec![
        ("grid", grid_domain(4, 0.5, 7)),
        ("L", l_domain(2, 3)),
        ("disk", disk_domain()),
        ("thin fan", thin_fan_domain()),
    ]
}

/// Sample points: (face, point) inside faces, on edges and at vertices.
fn samples(d: &Domain, count: usize, seed: u64) -> Vec<(u32, Point)> {
    let mut rng = Rng(seed);
    let nf = d.n_faces();
    let mut out = Vec::new();
    for k in 0..count {
        let f = ((rng.next() * nf as f64) as usize).min(nf - 1) as u32;
        let (mut a, mut b) = (rng.next(), rng.next());
        if a + b > 1.0 {
            a = 1.0 - a;
            b = 1.0 - b;
        }
        let bary = match k % 4 {
            0 | 1 => [1.0 - a - b, a, b],
            2 => [1.0 - a, a, 0.0], // on an edge
            _ => {
                let mut v = [0.0; 3];
                v[k % 3] = 1.0; // at a vertex
                v
            }
        };
        out.push((f, d.point_in_face(f, bary)));
    }
    out
}

#[test]
fn partition_of_unity_everywhere() {
    for (name, dom) in domains() {
        for n in 1..=5 {
            let space =
                DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
            let mut ws = Workspace::default();
            let np = n_partials(2);
            let (mut worst, mut worst_d): (f64, f64) = (0.0, 0.0);
            for (f, u) in samples(space.domain(), 800, 11 + n as u64) {
                let m = space.basis_at(f, u, 2, &mut ws).unwrap();
                let mut sum = [0.0; 6];
                let mut mag = [0.0; 6];
                for i in 0..m {
                    for k in 0..np {
                        sum[k] += ws.values[i * np + k];
                        mag[k] += ws.values[i * np + k].abs();
                    }
                }
                worst = worst.max((sum[0] - 1.0).abs());
                // Derivatives of Σ N vanish (up to order n − 1, where they are continuous,
                // and also beyond: Σ N is the constant 1 on the domain).
                for k in 1..np {
                    worst_d = worst_d.max(sum[k].abs() / mag[k].max(1.0));
                }
            }
            eprintln!(
                "{name} n={n}: max |Σ N − 1| = {worst:.2e}, max |∂ Σ N| / Σ |∂N| = {worst_d:.2e}, {:?}",
                space.report()
            );
            assert!(
                worst_d < 1e-9,
                "{name} n={n}: derivatives of Σ N = {worst_d:.2e}"
            );
            assert!(
                worst < 5e-11,
                "{name} n={n}: partition of unity off by {worst:.2e}"
            );
        }
    }
}

/// Every polynomial of degree ≤ n (each monomial, and random combinations) is reproduced by
/// its blossom control points, with all derivatives.
#[test]
fn polynomial_reproduction() {
    for (name, dom) in domains() {
        for n in 2..=5 {
            let space =
                DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
            let center = [0.3, 0.2];
            let mut polys = Vec::new();
            for tot in 0..=n {
                for b in 0..=tot {
                    polys.push(Polynomial::monomial(n, tot - b, b, center, 1.0));
                }
            }
            let mut rng = Rng(99 + n as u64);
            let coeffs: Vec<f64> = (0..n_partials(n)).map(|_| 2.0 * rng.next() - 1.0).collect();
            polys.push(Polynomial::from_coeffs(n, center, 1.0, coeffs));
            let pts = samples(space.domain(), 300, 3 + n as u64);
            let order = n;
            let np = n_partials(order);
            for precision in [Precision::Extended, Precision::Double] {
                let mut ws = Workspace::with_precision(precision);
                let mut worst = vec![0.0f64; order + 1];
                let mut worst_rel = vec![0.0f64; order + 1];
                for p in &polys {
                    let c = space.control_points_of_polynomial(p).unwrap();
                    for &(f, u) in &pts {
                        let m = space.basis_at(f, u, order, &mut ws).unwrap();
                        let want = p.partials(u, order);
                        for i in 0..np {
                            let (mut val, mut mag) = (0.0, 0.0);
                            for j in 0..m {
                                let t = c[ws.indices[j] as usize] * ws.values[j * np + i];
                                val += t;
                                mag += t.abs();
                            }
                            let k = (((8 * i + 1) as f64).sqrt() as usize - 1) / 2; // order of partial i
                            let err = (val - want[i]).abs();
                            worst[k] = worst[k].max(err);
                            worst_rel[k] = worst_rel[k].max(err / mag.max(1e-300));
                        }
                    }
                }
                let fmt = |v: &[f64]| v.iter().map(|e| format!("{e:.1e}")).collect::<Vec<_>>();
                eprintln!(
                "{name} n={n} {precision:?}: reproduction error by derivative order {:?}, relative to Σ|c ∂N| {:?}",
                fmt(&worst),
                fmt(&worst_rel)
            );
                assert!(
                    worst[0] < 1e-10,
                    "{name} n={n}: value error {:.2e}",
                    worst[0]
                );
                // Derivatives: the sum Σ c ∂N cancels (individual ∂^k N grow like ρ^-k, ρ the cloud
                // radius); the error is measured against the size of the terms. In double
                // precision the recurrence's rounding grows by about a decade per order (its
                // derivative coefficients are not damped by the choice of variant); in
                // double-double what is left is the rounding of the basis values to double and
                // of this sum (measured ≤ 8e-12 of the terms, thin fan n = 4).
                for k in 1..=order {
                    let tol = match precision {
                        Precision::Extended => 1e-10,
                        Precision::Double => 1e-9 * 10f64.powi(k as i32),
                    };
                    assert!(
                        worst_rel[k] < tol,
                        "{name} n={n} {precision:?}: order {k} error {:.2e} (relative {:.2e})",
                        worst[k],
                        worst_rel[k]
                    );
                }
            }
        }
    }
}

fn random_control(space: &DmsSpace, dim: usize, seed: u64) -> Vec<f64> {
    let mut rng = Rng(seed);
    (0..space.n_control_points() * dim)
        .map(|_| 2.0 * rng.next() - 1.0)
        .collect()
}

/// Largest |partial| of each total order over a set of evaluations.
fn order_of(i: usize) -> usize {
    (((8 * i + 1) as f64).sqrt() as usize - 1) / 2
}

/// C^{n−1} across every interior domain edge, with random control points: the partials up to
/// order n − 1 approached from the two faces agree; the order-n partials do jump (so the
/// one-sided evaluation is really one-sided).
#[test]
fn continuity_across_domain_edges() {
    for (name, dom) in [("grid", grid_domain(4, 0.5, 21)), ("disk", disk_domain())] {
        for n in 2..=5 {
            let space =
                DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
            let c = random_control(&space, 1, 5 + n as u64);
            let mesh = space.domain().mesh();
            let np = n_partials(n);
            let mut ws = Workspace::default();
            let (mut a, mut b) = (vec![0.0; np], vec![0.0; np]);
            let mut rng = Rng(77);
            let mut jumps = Vec::new(); // (order, |jump|)
            let mut scale = vec![0.0f64; n + 1];
            for e in 0..mesh.n_edges() as u32 {
                if mesh.is_boundary_edge(e) {
                    continue;
                }
                let h = mesh.edge_halfedge(e);
                let (f, g) = (mesh.he_face(h), mesh.he_face(mesh.he_twin(h)));
                let [p, q] = mesh
                    .edge_vertices(e)
                    .map(|v| space.domain().points()[v as usize]);
                for s in 0..3 {
                    let t = if s == 0 { 0.5 } else { rng.next() };
                    let u = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                    space.evaluate(&c, 1, f, u, n, &mut ws, &mut a).unwrap();
                    space.evaluate(&c, 1, g, u, n, &mut ws, &mut b).unwrap();
                    for i in 0..np {
                        let k = order_of(i);
                        scale[k] = scale[k].max(a[i].abs()).max(b[i].abs());
                        jumps.push((k, (a[i] - b[i]).abs()));
                    }
                }
            }
            let mut worst = vec![0.0f64; n + 1];
            for (k, j) in jumps {
                worst[k] = worst[k].max(j / scale[k]);
            }
            eprintln!(
                "{name} n={n}: relative jumps by order {:?}",
                worst.iter().map(|e| format!("{e:.1e}")).collect::<Vec<_>>()
            );
            for k in 0..n {
                assert!(
                    worst[k] <= 1e-8,
                    "{name} n={n}: order-{k} jump {:.2e}",
                    worst[k]
                );
            }
            assert!(
                worst[n] > 1e-3,
                "{name} n={n}: order-n partials do not jump ({:.2e})",
                worst[n]
            );
        }
    }
}

/// Partials of order k against central differences of the partials of order k − 1, for random
/// control points in R³, k = 1..n−1 (where they are continuous).
#[test]
fn derivatives_match_finite_differences() {
    let dom = grid_domain(3, 0.5, 4);
    for n in 2..=5 {
        let space = DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
        let dim = 3;
        let c = random_control(&space, dim, 40 + n as u64);
        let order = n - 1;
        let np = n_partials(order);
        let mut ws = Workspace::default();
        let mut out = vec![0.0; np * dim];
        let (mut op, mut om) = (vec![0.0; np * dim], vec![0.0; np * dim]);
        let h = 1e-6;
        let mut worst = 0.0f64;
        let mut scale = vec![0.0f64; order + 1];
        let pts: Vec<(u32, Point)> = samples(space.domain(), 200, 8)
            .into_iter()
            .enumerate()
            .filter(|(k, _)| k % 4 < 2)
            .map(|(_, s)| s)
            .collect();
        let mut errs = Vec::new();
        for &(f, u) in &pts {
            space
                .evaluate(&c, dim, f, u, order, &mut ws, &mut out)
                .unwrap();
            for i in 0..np {
                for d in 0..dim {
                    scale[order_of(i)] = scale[order_of(i)].max(out[i * dim + d].abs());
                }
            }
            for axis in 0..2 {
                let mut up = u;
                let mut um = u;
                up[axis] += h;
                um[axis] -= h;
                space
                    .evaluate(&c, dim, f, up, order, &mut ws, &mut op)
                    .unwrap();
                space
                    .evaluate(&c, dim, f, um, order, &mut ws, &mut om)
                    .unwrap();
                // d/dx of partial (a, b) is partial (a+1, b); d/dy is (a, b+1).
                for k in 0..order {
                    for b in 0..=k {
                        let a = k - b;
                        let from = k * (k + 1) / 2 + b;
                        let (a2, b2) = if axis == 0 { (a + 1, b) } else { (a, b + 1) };
                        let to = (k + 1) * (k + 2) / 2 + b2;
                        debug_assert_eq!(a2 + b2, k + 1);
                        for d in 0..dim {
                            let fd = (op[from * dim + d] - om[from * dim + d]) / (2.0 * h);
                            errs.push((k + 1, (fd - out[to * dim + d]).abs()));
                        }
                    }
                }
            }
        }
        for (k, e) in errs {
            worst = worst.max(e / scale[k]);
        }
        eprintln!("n={n}: worst finite-difference mismatch {worst:.1e} (relative to the largest partial of that order)");
        assert!(
            worst < 1e-4,
            "n={n}: derivatives disagree with finite differences ({worst:.2e})"
        );
    }
}

/// The basis of a triangle built from knots in another chart (rigid motion, as between charts
/// of an affine atlas, and a general affine map) gives the same values at the mapped point,
/// and derivatives that transform by the chain rule.
#[test]
fn triangle_basis_is_chart_independent() {
    use ricci::spline::dms::{KnotClouds, TriangleBasis};
    let dom = grid_domain(3, 0.5, 9);
    for n in [3, 5] {
        let clouds = KnotClouds::place(&dom, n, &KnotOptions::default()).unwrap();
        let f = 7u32;
        let tri = dom.triangles()[f as usize];
        let base = TriangleBasis::new(n, tri.map(|v| clouds.cloud(v))).unwrap();
        // x ↦ A x + t
        let maps = [
            (
                [[0.6f64.cos(), -0.6f64.sin()], [0.6f64.sin(), 0.6f64.cos()]],
                [3.0, -2.0],
            ),
            ([[1.3, 0.4], [-0.2, 0.8]], [-1.0, 5.0]),
        ];
        for (a, t) in maps {
            let map = |p: Point| {
                [
                    a[0][0] * p[0] + a[0][1] * p[1] + t[0],
                    a[1][0] * p[0] + a[1][1] * p[1] + t[1],
                ]
            };
            let lin = |p: Point| {
                [
                    a[0][0] * p[0] + a[0][1] * p[1],
                    a[1][0] * p[0] + a[1][1] * p[1],
                ]
            };
            let moved: Vec<Vec<Point>> = tri
                .iter()
                .map(|&v| clouds.cloud(v).iter().map(|&p| map(p)).collect())
                .collect();
            let other =
                TriangleBasis::new(n, [&moved[0][..], &moved[1][..], &moved[2][..]]).unwrap();
            let np = n_partials(1);
            let (mut x, mut y) = (vec![0.0; base.len() * np], vec![0.0; base.len() * np]);
            let mut work = Vec::new();
            let mut worst: f64 = 0.0;
            for (g, u) in samples(&dom, 200, 31) {
                if g != f {
                    continue;
                }
                let c = dom.centroid(f);
                let d = [c[0] - u[0], c[1] - u[1]];
                base.eval(u, d, 1, &mut work, &mut x);
                other.eval(map(u), lin(d), 1, &mut work, &mut y);
                for b in 0..base.len() {
                    worst = worst.max((x[b * np] - y[b * np]).abs());
                    // ∇_u N = Aᵀ ∇_x N
                    let gx = a[0][0] * y[b * np + 1] + a[1][0] * y[b * np + 2];
                    let gy = a[0][1] * y[b * np + 1] + a[1][1] * y[b * np + 2];
                    let s = x[b * np + 1].abs() + x[b * np + 2].abs() + 1.0;
                    worst = worst
                        .max((gx - x[b * np + 1]).abs() / s)
                        .max((gy - x[b * np + 2]).abs() / s);
                }
            }
            assert!(worst < 1e-11, "n={n}: chart dependence {worst:.2e}");
        }
    }
}

/// The B-patch blossom weights of a triangle reproduce the blossom of a polynomial from its
/// control points at arbitrary arguments (what the fairing constraints of Fig. 13 rely on).
#[test]
fn blossom_weights_reproduce_polynomial_blossoms() {
    let dom = disk_domain();
    for n in 2..=5 {
        let space = DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
        let mut rng = Rng(3 + n as u64);
        let coeffs: Vec<f64> = (0..n_partials(n)).map(|_| 2.0 * rng.next() - 1.0).collect();
        let p = Polynomial::from_coeffs(n, [0.1, -0.1], 1.0, coeffs);
        let c = space.control_points_of_polynomial(&p).unwrap();
        let nb = space.per_triangle();
        let mut w = vec![0.0; nb];
        for f in [0u32, 5, 11] {
            let args: Vec<Point> = (0..n)
                .map(|_| [2.0 * rng.next() - 1.0, 2.0 * rng.next() - 1.0])
                .collect();
            space.triangle(f).blossom_weights(&args, &mut w);
            let via: f64 = (0..nb).map(|b| w[b] * c[f as usize * nb + b]).sum();
            assert!(
                (via - p.blossom(&args)).abs() < 1e-11,
                "n={n} face {f}: {via} vs {}",
                p.blossom(&args)
            );
        }
    }
}

/// Bad input is refused with a sentence naming the culprit.
#[test]
fn refuses_inadmissible_input() {
    use ricci::spline::dms::KnotClouds;
    // A clockwise triangle.
    let e = Domain::new(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]], vec![[0, 1, 2]]).unwrap_err();
    assert!(e.to_string().contains("face 0"), "{e}");
    // Knots of a boundary vertex inside the domain.
    let dom = grid_domain(2, 0.0, 1);
    let n = 2;
    let mut knots = KnotClouds::place(&dom, n, &KnotOptions::default())
        .unwrap()
        .knots()
        .to_vec();
    let p0 = dom.points()[0];
    knots[1] = [p0[0] + 0.05, p0[1] + 0.05]; // into the square
    let e = DmsSpace::new(dom.clone(), KnotClouds::new(n, knots).unwrap()).unwrap_err();
    assert!(e.to_string().contains("boundary vertex 0"), "{e}");
    // Degree out of range, spread out of range.
    assert!(KnotClouds::place(&dom, 9, &KnotOptions::default()).is_err());
    assert!(KnotClouds::place(
        &dom,
        3,
        &KnotOptions {
            spread: 0.9,
            seed: 1
        }
    )
    .is_err());
}

/// Paper 000's fairing: constraints hold after it, the result is the closest feasible point
/// (c − c̃ is orthogonal to every feasible direction, e.g. towards polynomial control points),
/// r = 0 keeps the subdivision net (its edge control points are already shared), polynomial
/// control points are left alone, and larger r gives a fairer (lower thin-plate energy)
/// surface.
#[test]
fn fairing_satisfies_constraints_and_is_optimal() {
    use ricci::spline::fit::{constraint_residuals, fair, fairness_constraints, thin_plate_energy};
    let dom = grid_domain(4, 0.4, 12);
    for n in [3, 5] {
        let space = DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
        // A bumpy height field sampled at the domain vertices → subdivision control points.
        let pos: Vec<f64> = space
            .domain()
            .points()
            .iter()
            .flat_map(|p| [p[0], p[1], 0.2 * (7.0 * p[0]).sin() * (5.0 * p[1]).cos()])
            .collect();
        let c = space.subdivision_control_points(&pos, 3).unwrap();
        let scale = c.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let (c0, rep0) = fair(&space, &c, 3, 0).unwrap();
        assert!(rep0.converged, "{rep0:?}");
        assert!(
            rep0.rms_change < 1e-12 * scale,
            "r=0 changed the subdivision net: {rep0:?}"
        );
        let mut energies = vec![thin_plate_energy(&space, &c0, 3).unwrap()];
        let mut rng = Rng(5);
        for r in 1..n {
            let (x, rep) = fair(&space, &c, 3, r).unwrap();
            assert!(
                rep.converged && rep.max_constraint_residual < 1e-10,
                "n={n} r={r}: {rep:?}"
            );
            let cons = fairness_constraints(&space, r).unwrap();
            let res = constraint_residuals(&space, &cons, &x, 3);
            // Residual relative to the size of each constraint's terms.
            let mut worst = 0.0f64;
            for (i, con) in cons.iter().enumerate() {
                let norm = 1.0 + con.weights.iter().map(|w| w.abs()).sum::<f64>();
                for d in 0..3 {
                    worst = worst.max(res[i * 3 + d].abs() / (norm * scale));
                }
            }
            assert!(
                worst < 1e-10,
                "n={n} r={r}: constraint residual {worst:.2e}"
            );
            // Optimality: ⟨c − x, q − x⟩ = 0 for a feasible q (a polynomial's control points).
            let coeffs: Vec<f64> = (0..n_partials(n)).map(|_| rng.next() - 0.5).collect();
            let poly = Polynomial::from_coeffs(n, [0.5, 0.5], 1.0, coeffs);
            let q1 = space.control_points_of_polynomial(&poly).unwrap();
            let q: Vec<f64> = q1.iter().flat_map(|&v| [v, 0.5 * v, -v]).collect();
            let (mut dot, mut na, mut nb) = (0.0, 0.0, 0.0);
            for k in 0..x.len() {
                dot += (c[k] - x[k]) * (q[k] - x[k]);
                na += (c[k] - x[k]).powi(2);
                nb += (q[k] - x[k]).powi(2);
            }
            let cos = dot / (na * nb).sqrt();
            assert!(
                cos.abs() < 1e-8,
                "n={n} r={r}: not the closest feasible point (cos {cos:.2e})"
            );
            // Polynomial control points are feasible: the fairing leaves them in place.
            let (qq, _) = fair(&space, &q, 3, r).unwrap();
            let moved = qq
                .iter()
                .zip(&q)
                .fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
            assert!(moved < 1e-9, "n={n} r={r}: polynomial moved by {moved:.2e}");
            energies.push(thin_plate_energy(&space, &x, 3).unwrap());
            eprintln!("n={n} r={r}: {} constraints, rms change {:.3e}, residual {:.1e}, steps {}, energy {:.4e}", rep.constraints, rep.rms_change, rep.max_constraint_residual, rep.refinement_steps, energies[r]);
        }
        assert!(
            energies[n - 1] < energies[0],
            "n={n}: fairing did not lower the thin-plate energy {energies:?}"
        );
    }
}

/// The least-squares fit: exact data from a polynomial of degree ≤ n is reproduced when the
/// smoothing is negligible; with smoothing the objective drops below its initial value, the
/// normal equations are solved, and more smoothing trades error for energy.
#[test]
fn fit_reduces_objective_and_reproduces_polynomials() {
    use ricci::spline::fit::{fit, DataPoint, FitOptions};
    let dom = disk_domain();
    for n in [3, 5] {
        let space = DmsSpace::with_placed_knots(dom.clone(), n, &KnotOptions::default()).unwrap();
        let mut rng = Rng(17);
        let coeffs: Vec<f64> = (0..n_partials(n)).map(|_| rng.next() - 0.5).collect();
        let poly = Polynomial::from_coeffs(n, [0.0, 0.0], 1.0, coeffs);
        // Dense data: many points per face.
        let data: Vec<DataPoint> = samples(space.domain(), 40 * space.domain().n_faces(), 23)
            .into_iter()
            .map(|(f, u)| DataPoint {
                face: f,
                param: u,
                target: vec![poly.eval(u)],
            })
            .collect();
        let init = vec![0.0; space.n_control_points()];
        let (x, rep) = fit(
            &space,
            &data,
            &init,
            1,
            &FitOptions {
                smoothing: 0.0,
                ridge: 1e-12,
            },
        )
        .unwrap();
        eprintln!("n={n} exact: {rep:?}");
        assert!(
            rep.max_error < 1e-7,
            "n={n}: polynomial not reproduced by the fit: {rep:?}"
        );
        assert!(rep.relative_residual < 1e-8);
        let _ = x;
        // Noisy data with smoothing.
        let noisy: Vec<DataPoint> = data
            .iter()
            .map(|d| DataPoint {
                target: vec![d.target[0] + 0.05 * (rng.next() - 0.5)],
                ..d.clone()
            })
            .collect();
        let mut last_energy = f64::INFINITY;
        let mut last_err = 0.0;
        for s in [1e-4, 1e-2, 1.0] {
            let (_, rep) = fit(
                &space,
                &noisy,
                &init,
                1,
                &FitOptions {
                    smoothing: s,
                    ridge: 1e-9,
                },
            )
            .unwrap();
            eprintln!("n={n} smoothing {s}: {rep:?}");
            assert!(rep.objective_after < rep.objective_before);
            assert!(rep.relative_residual < 1e-8);
            assert!(
                rep.energy_after <= last_energy * (1.0 + 1e-9),
                "energy must fall as smoothing grows"
            );
            assert!(
                rep.rms_error >= last_err * (1.0 - 1e-9),
                "error must grow as smoothing grows"
            );
            last_energy = rep.energy_after;
            last_err = rep.rms_error;
        }
    }
}

/// Regression: on a 968-triangle grid the shifted factorisation of A Aᵀ must not spoil the
/// solve (a fixed shift of 1e-9 once left residuals of 4e-3).
#[test]
fn fairing_converges_on_a_larger_grid() {
    use ricci::spline::fit::fair;
    let dom = grid_domain(22, -0.4, 12);
    let space = DmsSpace::with_placed_knots(dom, 3, &KnotOptions::default()).unwrap();
    let pos: Vec<f64> = space
        .domain()
        .points()
        .iter()
        .flat_map(|p| [p[0], p[1], 0.1 * (6.0 * p[0]).sin()])
        .collect();
    let c = space.subdivision_control_points(&pos, 3).unwrap();
    let (_, rep) = fair(&space, &c, 3, 1).unwrap();
    assert!(
        rep.converged && rep.max_constraint_residual < 1e-10,
        "{rep:?}"
    );
}

/// The knot-quality measures of a triangle do not depend on where the triangle sits: a
/// triangle of size 1e-8 with clouds of 10⁻¹ of it, at the origin and moved to (0.7, −0.4)
/// (a tiny face in a unit-size chart), has the same relative `Δ_β` orientation and `Ω_I`
/// area, and the basis builds in both places (`Ω_I` used to come out empty far from the
/// origin, the shoelace formula cancelling in absolute coordinates).
#[test]
fn knot_quality_is_translation_invariant() {
    let h = 1e-8;
    let corners = [[0.0, 0.0], [h, 0.0], [0.3 * h, 0.8 * h]];
    let mut knots = Vec::new();
    for (m, c) in corners.iter().enumerate() {
        knots.push(*c);
        for k in 1..=3 {
            let a = 2.1 * k as f64 + m as f64;
            knots.push([c[0] + 0.1 * h * a.cos(), c[1] + 0.1 * h * a.sin()]);
        }
    }
    let (o0, w0) = ricci::spline::dms::patch_quality(3, &knots);
    assert!(o0 > 0.0 && w0 > 0.1, "{o0} {w0}");
    let moved: Vec<Point> = knots.iter().map(|p| [p[0] + 0.7, p[1] - 0.4]).collect();
    let (o1, w1) = ricci::spline::dms::patch_quality(3, &moved);
    assert!((o1 - o0).abs() < 1e-6 * o0, "orientation {o0} vs {o1}");
    assert!((w1 - w0).abs() < 1e-6 * w0, "Ω ratio {w0} vs {w1}");
    let clouds: Vec<&[Point]> = moved.chunks(4).collect();
    ricci::spline::dms::TriangleBasis::new(3, [clouds[0], clouds[1], clouds[2]]).unwrap();
}

/// The control net of a degree-`n` B-patch: `3n(n+1)/2` edges (n² sub-triangles of the net,
/// `n(n+1)/2` pointing up, each side shared or on the boundary: `(3n² + 3n)/2`), each joining
/// two multi-indices that differ by moving one unit between two coordinates, none twice.
#[test]
fn control_net_edges_join_neighbouring_multi_indices() {
    use ricci::spline::dms::{control_net_edges, multi_indices};
    for n in 1..=6 {
        let betas = multi_indices(n);
        let edges = control_net_edges(n);
        assert_eq!(edges.len(), 3 * n * (n + 1) / 2, "degree {n}");
        let mut seen = std::collections::HashSet::new();
        for &(k, j) in &edges {
            let (a, b) = (betas[k], betas[j]);
            let diff: Vec<i64> = (0..3).map(|i| a[i] as i64 - b[i] as i64).collect();
            let mut sorted = diff.clone();
            sorted.sort();
            assert_eq!(sorted, vec![-1, 0, 1], "degree {n}: {a:?} – {b:?}");
            assert!(
                seen.insert((k.min(j), k.max(j))),
                "degree {n}: edge {k}–{j} twice"
            );
        }
    }
}
