//! Intrinsic refinement preserves the metric: every old corner angle is the sum of its new
//! pieces, old vertices keep their curvature, new vertices are flat, and the area is unchanged
//! — in E², H² and S², with random metrics (seeded).

use ricci::mesh::Mesh;
use ricci::metric::refine::{Refined, Refiner};
use ricci::metric::Geometry;
use std::f64::consts::PI;

/// Small deterministic generator (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A torus grid with a random metric: lengths from random positions of a flat grid of
/// spacing `h`, perturbed by ±`jitter` of a cell (always valid triangles for small jitter).
fn torus_with_metric(n: u32, m: u32, h: f64, jitter: f64, rng: &mut Rng) -> (Mesh, Vec<f64>) {
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..m {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let mesh = Mesh::from_triangles((n * m) as usize, f).unwrap();
    // Periodic jittered planar positions give consistent lengths on the torus.
    let off: Vec<[f64; 2]> = (0..n * m)
        .map(|_| [jitter * (rng.next() - 0.5), jitter * (rng.next() - 0.5)])
        .collect();
    let lengths = (0..mesh.n_edges() as u32)
        .map(|e| {
            let h0 = mesh.edge_halfedge(e);
            let (a, b) = (mesh.he_origin(h0), mesh.he_tip(h0));
            let (ia, ja) = (a / m, a % m);
            let (ib, jb) = (b / m, b % m);
            // Unwrap the periodic difference.
            let di = ((ib as i64 - ia as i64 + n as i64 + 1) % n as i64) - 1;
            let dj = ((jb as i64 - ja as i64 + m as i64 + 1) % m as i64) - 1;
            let dx = di as f64 + off[b as usize][0] - off[a as usize][0];
            let dy = dj as f64 + off[b as usize][1] - off[a as usize][1];
            h * (dx * dx + dy * dy).sqrt()
        })
        .collect();
    (mesh, lengths)
}

fn corner_angles(g: Geometry, mesh: &Mesh, lengths: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; mesh.n_corners()];
    for f in 0..mesh.n_faces() as u32 {
        let l = |i: u32| lengths[mesh.he_edge(3 * f + i) as usize];
        for i in 0..3u32 {
            // Corner i: opposite half-edge 3f+(i+1)%3, adjacent 3f+i and 3f+(i+2)%3.
            out[(3 * f + i) as usize] = g.angle(l((i + 1) % 3), l(i), l((i + 2) % 3));
        }
    }
    out
}

fn angle_sums(mesh: &Mesh, angles: &[f64]) -> Vec<f64> {
    let mut s = vec![0.0; mesh.n_vertices()];
    for c in 0..mesh.n_corners() as u32 {
        s[mesh.corner_vertex(c) as usize] += angles[c as usize];
    }
    s
}

fn area(g: Geometry, mesh: &Mesh, lengths: &[f64]) -> f64 {
    (0..mesh.n_faces() as u32)
        .map(|f| {
            let e = mesh.face_edges_opposite(f);
            g.area(
                lengths[e[0] as usize],
                lengths[e[1] as usize],
                lengths[e[2] as usize],
            )
        })
        .sum()
}

fn check(g: Geometry, mesh: &Mesh, lengths: &[f64], r: &Refined) {
    let a0 = corner_angles(g, mesh, lengths);
    let a1 = corner_angles(g, &r.mesh, &r.lengths);
    // Every original corner = sum of the refined corners at the same vertex in the same
    // original face.
    let mut sum = vec![0.0; mesh.n_corners()];
    for c in 0..r.mesh.n_corners() as u32 {
        let v = r.mesh.corner_vertex(c);
        if (v as usize) < mesh.n_vertices() {
            let f0 = r.face_origin[(c / 3) as usize];
            let i = mesh
                .face(f0)
                .iter()
                .position(|&w| w == v)
                .expect("vertex of the origin face");
            sum[(3 * f0 as usize) + i] += a1[c as usize];
        }
    }
    for c in 0..mesh.n_corners() {
        assert!(
            (sum[c] - a0[c]).abs() < 1e-12,
            "{g:?}: corner {c}: {} vs {}",
            sum[c],
            a0[c]
        );
    }
    let s0 = angle_sums(mesh, &a0);
    let s1 = angle_sums(&r.mesh, &a1);
    for v in 0..mesh.n_vertices() {
        assert!(
            (s0[v] - s1[v]).abs() < 1e-12,
            "{g:?}: curvature of vertex {v} changed"
        );
    }
    #[allow(clippy::needless_range_loop)]
    for v in mesh.n_vertices()..r.mesh.n_vertices() {
        let flat = if r.mesh.is_boundary_vertex(v as u32) {
            PI
        } else {
            2.0 * PI
        };
        assert!(
            (s1[v] - flat).abs() < 1e-12,
            "{g:?}: new vertex {v} is not flat: {}",
            s1[v]
        );
    }
    let (ar0, ar1) = (area(g, mesh, lengths), area(g, &r.mesh, &r.lengths));
    assert!(
        (ar0 - ar1).abs() < 1e-11 * ar0.max(1.0),
        "{g:?}: area {ar0} vs {ar1}"
    );
    // Provenance: every new vertex lies on an edge between older vertices.
    for (k, p) in r.new_vertices.iter().enumerate() {
        let v = (r.original_vertices + k) as u32;
        assert!(p.a < v && p.b < v && p.t > 0.0 && p.t < 1.0);
    }
}

#[test]
fn refinement_preserves_random_metrics_in_all_three_geometries() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for (g, h) in [
        (Geometry::Euclidean, 1.0),
        (Geometry::Hyperbolic, 0.7),
        (Geometry::Spherical, 0.05),
    ] {
        for trial in 0..3 {
            let (mesh, lengths) = torus_with_metric(9, 8, h, 0.5, &mut rng);
            let x = (trial * 17) as u32 % mesh.n_vertices() as u32;
            let mut r = Refiner::new(&mesh, &lengths, g, None).unwrap();
            r.raise_valence(x, 24).unwrap();
            let theta = r.cone_angle(x);
            r.grade_around(x, 24, 4.0 * h, 20_000).unwrap();
            let refined = r.finish().unwrap();
            assert!(refined.mesh.valence(x) >= 24);
            assert!(refined.splits() > 18, "grading did something");
            // The cone angle at x is unchanged too.
            let a1 = corner_angles(g, &refined.mesh, &refined.lengths);
            let s1 = angle_sums(&refined.mesh, &a1);
            assert!((s1[x as usize] - theta).abs() < 1e-12);
            check(g, &mesh, &lengths, &refined);
        }
    }
}

#[test]
fn boundary_edges_split_and_positions_interpolate() {
    // A fan around vertex 0 with one boundary: splitting its link (boundary edges) works.
    let faces: Vec<[u32; 3]> = (1..7)
        .map(|i| [0, i, if i == 6 { 1 } else { i + 1 }])
        .collect();
    let mesh = Mesh::from_triangles(7, faces).unwrap();
    let pos: Vec<[f64; 3]> = std::iter::once([0.0, 0.0, 0.0])
        .chain((0..6).map(|k| {
            let t = k as f64 * PI / 3.0;
            [t.cos(), t.sin(), 0.0]
        }))
        .collect();
    let lengths: Vec<f64> = (0..mesh.n_edges() as u32)
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            let (p, q) = (pos[a as usize], pos[b as usize]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
        })
        .collect();
    let r = ricci::metric::refine::raise_valence(
        &mesh,
        &lengths,
        Geometry::Euclidean,
        Some(&pos),
        0,
        15,
    )
    .unwrap();
    assert_eq!(r.mesh.valence(0), 15);
    check(Geometry::Euclidean, &mesh, &lengths, &r);
    // Positions are consistent with the lengths (the embedding is planar and exact here).
    let p = r.positions.as_ref().unwrap();
    for e in 0..r.mesh.n_edges() as u32 {
        let [a, b] = r.mesh.edge_vertices(e);
        let d = ((p[a as usize][0] - p[b as usize][0]).powi(2)
            + (p[a as usize][1] - p[b as usize][1]).powi(2))
        .sqrt();
        assert!((d - r.lengths[e as usize]).abs() < 1e-12);
    }
    // Refusing a boundary base vertex.
    let e = ricci::metric::refine::raise_valence(&mesh, &lengths, Geometry::Euclidean, None, 1, 8)
        .unwrap_err();
    assert!(e.to_string().contains("boundary"), "{e}");
}

#[test]
fn double_double_split_lengths_satisfy_the_cosine_laws() {
    // `split_side_dd` (Stewart's theorem) against the cosine law at `a`, which the triangles
    // (a, b, c) and (a, m, c) share, evaluated independently in double-double: E²
    // `cos A = (p² + ab² − q²)/(2 p ab)`, H² `cos A = (cosh p cosh ab − cosh q)/(sinh p sinh ab)`.
    use ricci::metric::refine::split_side_dd;
    use ricci::numeric::dd::Dd;
    let mut rng = Rng(0x5eed_dd14);
    for g in [Geometry::Euclidean, Geometry::Hyperbolic] {
        let mut worst = 0.0f64;
        for k in 0..200 {
            // Scales from 1e-3 (cosh near 1) to 1.
            let s = 10f64.powf(-3.0 * rng.next());
            let (ab, p) = (s * (0.5 + rng.next()), s * (0.5 + rng.next()));
            let q = s * (0.5 + rng.next());
            if !(q < ab + p && ab < p + q && p < ab + q) {
                continue;
            }
            let t = if k % 2 == 0 {
                0.5
            } else {
                0.1 + 0.8 * rng.next()
            };
            let (ab, p, q) = (Dd::new(ab), Dd::new(p), Dd::new(q));
            let x = ab * Dd::new(t);
            let y = ab - x;
            let mc = split_side_dd(g, p, q, x, y);
            let cos_a = |side: Dd, base: Dd, opp: Dd| match g {
                Geometry::Euclidean => {
                    (side.sqr() + base.sqr() - opp.sqr()) / (Dd::new(2.0) * side * base)
                }
                _ => (side.cosh() * base.cosh() - opp.cosh()) / (side.sinh() * base.sinh()),
            };
            let (c1, c2) = (cos_a(p, ab, q), cos_a(p, x, mc));
            worst = worst.max((c1 - c2).abs().f64());
        }
        assert!(worst < 1e-20, "{g}: cosine laws differ by {worst:e}");
    }
}

#[test]
fn low_parts_are_carried_through_splits() {
    let mut rng = Rng(42);
    let (mesh, lengths) = torus_with_metric(6, 7, 0.3, 0.1, &mut rng);
    let lo = vec![0.0; lengths.len()];
    let mut r = Refiner::new_with_low_parts(&mesh, &lengths, Some(&lo), Geometry::Hyperbolic, None)
        .unwrap();
    r.raise_valence(0, 12).unwrap();
    let done = r.finish().unwrap();
    let dlo = done.lengths_lo.as_ref().expect("low parts kept");
    assert_eq!(dlo.len(), done.lengths.len());
    // The split edges' leading parts agree with the double-precision splits to rounding.
    let plain =
        ricci::metric::refine::raise_valence(&mesh, &lengths, Geometry::Hyperbolic, None, 0, 12)
            .unwrap();
    for (a, b) in plain.lengths.iter().zip(&done.lengths) {
        assert!((a - b).abs() <= 1e-14 * b, "{a} vs {b}");
    }
    assert!(
        Refiner::new_with_low_parts(&mesh, &lengths, Some(&lo), Geometry::Spherical, None).is_err()
    );
}
