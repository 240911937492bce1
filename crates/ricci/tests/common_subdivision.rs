//! The common subdivision of an input mesh and its intrinsic triangulation after Ptolemy flips:
//! validity as a mesh of the input surface, normal coordinates, the crossing point of a cyclic
//! quad's diagonals, and UV maps by projective interpolation (flat grids mapped by a Möbius
//! transformation, where every quantity has an independent closed form).

mod ricci_meshes;
use ricci::mesh::{generate, Mesh, Surface};
use ricci::metric::common_subdivision::{layout_euclidean, CommonSubdivision};
use ricci::metric::intrinsic::{lambda_of_length, IntrinsicTriangulation};
use ricci::metric::Geometry;
use std::collections::HashMap;

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
    fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn tri_area(p: [f64; 3], q: [f64; 3], r: [f64; 3]) -> f64 {
    0.5 * norm(cross(sub3(q, p), sub3(r, p)))
}

/// `count` random flips of flippable interior edges.
fn random_flips(tri: &mut IntrinsicTriangulation, rng: &mut Lcg, count: usize) {
    let mut done = 0;
    let mut tries = 0;
    while done < count && tries < 100 * count {
        tries += 1;
        let e = rng.below(tri.n_edges()) as u32;
        if tri.flip(e) {
            done += 1;
        }
    }
}

/// Everything that makes the common subdivision a mesh of the input surface.
fn check_valid(surface: &Surface, sub: &CommonSubdivision) {
    let mesh = &surface.mesh;
    let pos = sub.positions(mesh, &surface.positions).unwrap();
    assert_eq!(sub.report.order_violations, 0);
    // Area per input face and in total.
    let mut area = vec![0.0; mesh.n_faces()];
    for (t, tr) in sub.triangles.iter().enumerate() {
        area[sub.input_face[t] as usize] += tri_area(
            pos[tr[0] as usize],
            pos[tr[1] as usize],
            pos[tr[2] as usize],
        );
        // Each corner's input barycentric coordinates reproduce its position.
        let fv = mesh.face(sub.input_face[t]);
        for i in 0..3 {
            let b = sub.input_barycentric[3 * t + i];
            let p = [0, 1, 2].map(|k| {
                (0..3)
                    .map(|m| b[m] * surface.positions[fv[m] as usize][k])
                    .sum::<f64>()
            });
            assert!(norm(sub3(p, pos[tr[i] as usize])) < 1e-12 * surface.diagonal());
        }
    }
    let mut total_in = 0.0;
    let mut total_sub = 0.0;
    for f in 0..mesh.n_faces() as u32 {
        let [a, b, c] = mesh.face(f);
        let a0 = tri_area(
            surface.positions[a as usize],
            surface.positions[b as usize],
            surface.positions[c as usize],
        );
        assert!(
            (area[f as usize] - a0).abs() <= 1e-12 * a0.max(1e-300) * 10.0,
            "input face {f}: area {a0} vs subdivision {}",
            area[f as usize]
        );
        total_in += a0;
        total_sub += area[f as usize];
    }
    assert!(
        (total_in - total_sub).abs() <= 1e-12 * total_in,
        "{total_in} vs {total_sub}"
    );
    // Every input vertex is a vertex of the subdivision.
    let mut used = vec![false; sub.n_vertices()];
    for tr in &sub.triangles {
        for &v in tr {
            used[v as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "a subdivision vertex is unused");
    // Crossings lie on their input edges, strictly inside, in rank order.
    let mut by_edge: HashMap<u32, Vec<(u32, f64, u32)>> = HashMap::new();
    for (c, cr) in sub.crossings.iter().enumerate() {
        let [a, b] = mesh.edge_vertices(cr.input_edge);
        let (pa, pb) = (surface.positions[a as usize], surface.positions[b as usize]);
        let p = pos[sub.n_input_vertices + c];
        let l = norm(sub3(pb, pa));
        let off = norm(cross(sub3(p, pa), sub3(pb, pa))) / l;
        assert!(off <= 1e-12 * l, "crossing {c} is {off} off its input edge");
        assert!(cr.input_t > 0.0 && cr.input_t < 1.0);
        by_edge.entry(cr.input_edge).or_default().push((
            cr.input_rank,
            cr.input_t,
            (sub.n_input_vertices + c) as u32,
        ));
    }
    // Subdivision edges: every input edge is exactly the chain v0 → crossings → v1.
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for tr in &sub.triangles {
        for i in 0..3 {
            let (a, b) = (tr[i], tr[(i + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    for e0 in 0..mesh.n_edges() as u32 {
        let [a, b] = mesh.edge_vertices(e0);
        let mut chain = by_edge.remove(&e0).unwrap_or_default();
        chain.sort_by_key(|c| c.0);
        for (k, c) in chain.iter().enumerate() {
            assert_eq!(c.0 as usize, k + 1);
            if k > 0 {
                assert!(
                    c.1 > chain[k - 1].1,
                    "input edge {e0}: crossings out of order"
                );
            }
        }
        let mut verts = vec![a];
        verts.extend(chain.iter().map(|c| c.2));
        verts.push(b);
        let want = if mesh.is_boundary_edge(e0) { 1 } else { 2 };
        for w in verts.windows(2) {
            let key = (w[0].min(w[1]), w[0].max(w[1]));
            assert_eq!(
                edges.get(&key).copied(),
                Some(want),
                "input edge {e0}: piece {:?} is not a subdivision edge used {want} times",
                w
            );
        }
    }
    // Euler characteristic and manifoldness.
    let m = Mesh::from_triangles(sub.n_vertices(), sub.triangles.clone())
        .expect("the common subdivision is a manifold mesh");
    let chi_in = mesh.n_vertices() as i64 - mesh.n_edges() as i64 + mesh.n_faces() as i64;
    let chi = m.n_vertices() as i64 - m.n_edges() as i64 + m.n_faces() as i64;
    assert_eq!(chi, chi_in);
    assert_eq!(m.has_boundary(), mesh.has_boundary());
}

fn lengths_for(surface: &Surface) -> Vec<f64> {
    surface.edge_lengths()
}

#[test]
fn no_flips_gives_the_input_mesh() {
    let s = generate::disk(12).unwrap();
    let sub = CommonSubdivision::new(&s.mesh, Geometry::Euclidean, &lengths_for(&s), &[]).unwrap();
    assert_eq!(sub.crossings.len(), 0);
    assert!(sub.normal.iter().all(|&n| n == -1));
    let mut want: Vec<[u32; 3]> = s.mesh.faces().iter().map(|&f| canon(f)).collect();
    let mut got: Vec<[u32; 3]> = sub.triangles.iter().map(|&f| canon(f)).collect();
    want.sort();
    got.sort();
    assert_eq!(want, got);
    check_valid(&s, &sub);
}

fn canon(f: [u32; 3]) -> [u32; 3] {
    let i = (0..3).min_by_key(|&i| f[i]).unwrap();
    [f[i], f[(i + 1) % 3], f[(i + 2) % 3]]
}

/// Random flips, in E² and H² coordinates, on a disk and a torus.
#[test]
fn random_flips_give_a_valid_subdivision() {
    let disk = generate::disk(14).unwrap();
    let torus = generate::torus(1.0, 0.4, 10).unwrap();
    for (name, s) in [("disk", &disk), ("torus", &torus)] {
        for geometry in [Geometry::Euclidean, Geometry::Hyperbolic] {
            let mut rng = Lcg(7 + name.len() as u64);
            let lengths = lengths_for(s);
            // H² coordinates need lengths that are hyperbolic triangles: scale down.
            let scale = if geometry == Geometry::Hyperbolic {
                0.5 / s.diagonal()
            } else {
                1.0
            };
            let lengths: Vec<f64> = lengths.iter().map(|l| l * scale).collect();
            let mut tri = IntrinsicTriangulation::from_mesh(&s.mesh, geometry, &lengths).unwrap();
            random_flips(&mut tri, &mut rng, 3 * s.mesh.n_edges());
            let sub = CommonSubdivision::new(&s.mesh, geometry, &lengths, &tri.flip_log).unwrap();
            // The replay reproduces the flipped triangulation.
            assert_eq!(sub.triangulation.origin, tri.origin);
            assert_eq!(sub.triangulation.twin, tri.twin);
            assert!(
                sub.crossings.len() > s.mesh.n_edges(),
                "{name}: too few crossings"
            );
            check_valid(s, &sub);
            // Flipping back in reverse order restores the input: no crossings at all.
            let mut log = tri.flip_log.clone();
            let forward = log.clone();
            log.extend(forward.iter().rev());
            let back = CommonSubdivision::new(&s.mesh, geometry, &lengths, &log).unwrap();
            assert_eq!(back.crossings.len(), 0, "{name} {geometry:?}");
            assert!(back.normal.iter().all(|&n| n == -1));
            check_valid(s, &back);
        }
    }
}

/// Delaunay flips after a random conformal scaling: each face of the layout is positive, so
/// is every triangle of the subdivision.
#[test]
fn delaunay_after_random_scaling_has_no_flipped_triangle() {
    let s = generate::disk(20).unwrap();
    let lengths = lengths_for(&s);
    let mut rng = Lcg(99);
    // Boundary edges never flip, so the scaling is 0 on the boundary (free-boundary style).
    let u: Vec<f64> = (0..s.mesh.n_vertices() as u32)
        .map(|v| {
            if s.mesh.is_boundary_vertex(v) {
                0.0
            } else {
                3.0 * (rng.next() - 0.5)
            }
        })
        .collect();
    let mut tri =
        IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Euclidean, &lengths).unwrap();
    let rep = tri.make_delaunay(&u, 100_000);
    assert!(rep.delaunay && rep.flips > 20, "{} flips", rep.flips);
    let sub =
        CommonSubdivision::new(&s.mesh, Geometry::Euclidean, &lengths, &tri.flip_log).unwrap();
    check_valid(&s, &sub);
    let layout = layout_euclidean(&sub.triangulation, &u).unwrap();
    let uv = sub.uv(Geometry::Euclidean, &u, &layout).unwrap();
    assert_eq!(sub.flipped_triangles(Geometry::Euclidean, &uv), 0);
    // The scale factors are recovered from the final coordinates.
    let fin: Vec<f64> = (0..tri.n_edges() as u32)
        .map(|e| tri.scaled_lambda(e, &u))
        .collect();
    let (u2, res) = sub.scale_factors(&fin).unwrap();
    assert!(res < 1e-12);
    for (a, b) in u.iter().zip(&u2) {
        assert!((a - b).abs() < 1e-12);
    }
}

fn intersect(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> [f64; 2] {
    // p + t (q − p) = r + w (s − r)
    let d = (q[0] - p[0]) * (s[1] - r[1]) - (q[1] - p[1]) * (s[0] - r[0]);
    let t = ((r[0] - p[0]) * (s[1] - r[1]) - (r[1] - p[1]) * (s[0] - r[0])) / d;
    [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
}

/// One flip of a cyclic quad: one crossing, at the intersection of the diagonals (Ptolemy flip
/// = geometric flip on a cyclic quad), on the input and in the layout of `T`.
#[test]
fn cyclic_quad_crossing_is_the_diagonals_intersection() {
    let ang = [0.3f64, 1.9, 3.0, 4.4];
    let z: Vec<[f64; 2]> = ang
        .iter()
        .map(|a| [2.0 * a.cos() + 0.7, 2.0 * a.sin() - 0.2])
        .collect();
    let s = Surface::new(
        z.iter().map(|p| [p[0], p[1], 0.0]).collect(),
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let lengths = lengths_for(&s);
    let mut tri =
        IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Euclidean, &lengths).unwrap();
    let diag = (0..s.mesh.n_edges() as u32)
        .find(|&e| !s.mesh.is_boundary_edge(e))
        .unwrap();
    assert!(tri.flip(diag));
    // Ptolemy = the true other diagonal 1–3 on a cyclic quad.
    let l13 = ((z[1][0] - z[3][0]).powi(2) + (z[1][1] - z[3][1]).powi(2)).sqrt();
    assert!((tri.lambda[diag as usize] - lambda_of_length(Geometry::Euclidean, l13)).abs() < 1e-13);
    let sub =
        CommonSubdivision::new(&s.mesh, Geometry::Euclidean, &lengths, &tri.flip_log).unwrap();
    assert_eq!(sub.normal[diag as usize], 1);
    assert_eq!(sub.crossings.len(), 1);
    check_valid(&s, &sub);
    let x = intersect(z[0], z[2], z[1], z[3]);
    let pos = sub.positions(&s.mesh, &s.positions).unwrap();
    let p = pos[4];
    assert!(
        (p[0] - x[0]).abs() < 1e-13 && (p[1] - x[1]).abs() < 1e-13,
        "{p:?} vs {x:?}"
    );
    // The layout of T is congruent to the quad; the crossing's UV is the diagonals' crossing
    // in that layout.
    let layout = layout_euclidean(&sub.triangulation, &[]).unwrap();
    let uv = sub.uv(Geometry::Euclidean, &[], &layout).unwrap();
    let (vuv, gap) = sub.vertex_uv(&uv, 1e-12);
    let vuv = vuv.unwrap_or_else(|| panic!("layout has a seam of {gap}"));
    let y = intersect(vuv[0], vuv[2], vuv[1], vuv[3]);
    assert!((vuv[4][0] - y[0]).abs() < 1e-12 && (vuv[4][1] - y[1]).abs() < 1e-12);
    assert_eq!(sub.flipped_triangles(Geometry::Euclidean, &uv), 0);
}

/// A flat square grid with random diagonals; flip a random set of the diagonals (every square
/// is cyclic, so T is the same flat metric) and scale by a Möbius map `M` (`u = log|M'|`), so
/// `T` at `u` is laid out exactly by `M(z)`. The crossings are the squares' centres on the input
/// and the intersections of the image diagonals in the UV map; the UV map is continuous and
/// has no flipped triangle.
#[test]
fn flat_grid_with_mobius_scaling_maps_crossings_to_image_diagonals() {
    let n = 8usize;
    let mut rng = Lcg(5);
    let mut pos = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            pos.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if rng.next() < 0.5 {
                faces.push([a, b, c]);
                faces.push([a, c, d]);
            } else {
                faces.push([a, b, d]);
                faces.push([b, c, d]);
            }
        }
    }
    let s = Surface::new(pos.clone(), faces).unwrap();
    let lengths = lengths_for(&s);
    let mut tri =
        IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Euclidean, &lengths).unwrap();
    // The diagonals are the interior edges of length √2/n.
    let mut flipped = Vec::new();
    for e in 0..s.mesh.n_edges() as u32 {
        if !s.mesh.is_boundary_edge(e) && lengths[e as usize] > 1.2 / n as f64 && rng.next() < 0.6 {
            assert!(tri.flip(e));
            flipped.push(e);
        }
    }
    // M(z) = (z + 0.3) / (0.4 z̄₀ ... ): a Möbius map with its pole outside the square.
    let (a, b, c, d) = (
        num(1.0, 0.2),
        num(0.3, -0.1),
        num(0.25, 0.35),
        num(1.0, 0.0),
    );
    let m = |p: [f64; 3]| {
        let z = num(p[0], p[1]);
        let w = div(add(mul(a, z), b), add(mul(c, z), d));
        [w.0, w.1]
    };
    // |M'(z)| = |ad − bc| / |cz + d|².
    let det = sub2(mul(a, d), mul(b, c));
    let u: Vec<f64> = pos
        .iter()
        .map(|p| {
            let q = add(mul(c, num(p[0], p[1])), d);
            (abs(det) / (q.0 * q.0 + q.1 * q.1)).ln()
        })
        .collect();
    let sub =
        CommonSubdivision::new(&s.mesh, Geometry::Euclidean, &lengths, &tri.flip_log).unwrap();
    assert_eq!(sub.crossings.len(), flipped.len());
    check_valid(&s, &sub);
    // Input side: the crossing is the square's centre.
    let p3 = sub.positions(&s.mesh, &s.positions).unwrap();
    for (k, cr) in sub.crossings.iter().enumerate() {
        let [v0, v1] = s.mesh.edge_vertices(cr.input_edge);
        let mid = [0, 1].map(|i| 0.5 * (pos[v0 as usize][i] + pos[v1 as usize][i]));
        let p = p3[sub.n_input_vertices + k];
        assert!((p[0] - mid[0]).abs() < 1e-14 && (p[1] - mid[1]).abs() < 1e-14);
    }
    // Layout of T at u: congruent to M(grid).
    let layout = layout_euclidean(&sub.triangulation, &u).unwrap();
    let uv = sub.uv(Geometry::Euclidean, &u, &layout).unwrap();
    assert_eq!(sub.flipped_triangles(Geometry::Euclidean, &uv), 0);
    let (vuv, gap) = sub.vertex_uv(&uv, 1e-12);
    let vuv = vuv.unwrap_or_else(|| panic!("UV map is discontinuous by {gap}"));
    // Align: the layout is M(z) up to a rigid motion fixed by vertices 0 and 1.
    let mz: Vec<[f64; 2]> = pos.iter().map(|&p| m(p)).collect();
    let rigid = rigid_from(vuv[0], vuv[1], mz[0], mz[1]);
    for v in 0..pos.len() {
        let q = rigid(vuv[v]);
        assert!(
            (q[0] - mz[v][0]).abs() < 1e-12 && (q[1] - mz[v][1]).abs() < 1e-12,
            "vertex {v}"
        );
    }
    for (k, cr) in sub.crossings.iter().enumerate() {
        let [c0, c1] = sub.triangulation.edge_vertices(cr.t_edge);
        let [a0, a1] = s.mesh.edge_vertices(cr.input_edge);
        let want = intersect(
            mz[a0 as usize],
            mz[a1 as usize],
            mz[c0 as usize],
            mz[c1 as usize],
        );
        let got = rigid(vuv[sub.n_input_vertices + k]);
        assert!(
            (got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12,
            "crossing {k}: {got:?} vs {want:?}"
        );
    }
}

type C = (f64, f64);
fn num(x: f64, y: f64) -> C {
    (x, y)
}
fn add(a: C, b: C) -> C {
    (a.0 + b.0, a.1 + b.1)
}
fn sub2(a: C, b: C) -> C {
    (a.0 - b.0, a.1 - b.1)
}
fn mul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
fn div(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}
fn abs(a: C) -> f64 {
    a.0.hypot(a.1)
}

/// The rigid motion taking p0 → q0 and the direction p0→p1 to q0→q1.
fn rigid_from(
    p0: [f64; 2],
    p1: [f64; 2],
    q0: [f64; 2],
    q1: [f64; 2],
) -> impl Fn([f64; 2]) -> [f64; 2] {
    let a0 = (p1[1] - p0[1]).atan2(p1[0] - p0[0]);
    let a1 = (q1[1] - q0[1]).atan2(q1[0] - q0[0]);
    let (s, c) = (a1 - a0).sin_cos();
    move |p: [f64; 2]| {
        let (x, y) = (p[0] - p0[0], p[1] - p0[1]);
        [q0[0] + c * x - s * y, q0[1] + s * x + c * y]
    }
}

/// Many random flips on a torus with 9 vertices: the triangulation becomes a Δ-complex with
/// self-loops and multi-edges, input edges cross one edge of T several times; the common
/// subdivision stays a valid mesh of the input.
#[test]
fn delta_complex_with_loops_and_repeated_crossings() {
    let n = 3usize;
    let mut pos = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b) = (
                2.0 * std::f64::consts::PI * i as f64 / n as f64,
                2.0 * std::f64::consts::PI * (j as f64 + 0.3 * i as f64) / n as f64,
            );
            pos.push([
                (2.0 + b.cos()) * a.cos(),
                (2.0 + b.cos()) * a.sin(),
                b.sin(),
            ]);
        }
    }
    let id = |i: usize, j: usize| ((j % n) * n + (i % n)) as u32;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let s = Surface::new(pos, faces).unwrap();
    let lengths = lengths_for(&s);
    for geometry in [Geometry::Euclidean, Geometry::Hyperbolic] {
        let mut rng = Lcg(2024);
        let lengths: Vec<f64> = if geometry == Geometry::Hyperbolic {
            lengths.iter().map(|l| 0.3 * l).collect()
        } else {
            lengths.clone()
        };
        let mut tri = IntrinsicTriangulation::from_mesh(&s.mesh, geometry, &lengths).unwrap();
        random_flips(&mut tri, &mut rng, 40);
        let loops = (0..tri.n_edges() as u32)
            .filter(|&e| {
                let [a, b] = tri.edge_vertices(e);
                a == b
            })
            .count();
        let mut pairs: Vec<(u32, u32)> = (0..tri.n_edges() as u32)
            .map(|e| {
                let [a, b] = tri.edge_vertices(e);
                (a.min(b), a.max(b))
            })
            .collect();
        pairs.sort();
        let multi = pairs.windows(2).filter(|w| w[0] == w[1]).count();
        assert!(loops > 0 && multi > 0, "loops {loops}, multi-edges {multi}");
        let sub = CommonSubdivision::new(&s.mesh, geometry, &lengths, &tri.flip_log).unwrap();
        // Some input edge crosses some edge of T at least twice.
        let mut seen: HashMap<(u32, u32), u32> = HashMap::new();
        for c in &sub.crossings {
            *seen.entry((c.input_edge, c.t_edge)).or_default() += 1;
        }
        assert!(seen.values().any(|&k| k >= 2));
        check_valid(&s, &sub);
        // Flipping back restores the input.
        let mut log = tri.flip_log.clone();
        log.extend(tri.flip_log.iter().rev());
        let back = CommonSubdivision::new(&s.mesh, geometry, &lengths, &log).unwrap();
        assert_eq!(back.crossings.len(), 0);
    }
}

/// The conformal flow's result on real meshes (`$RICCI_MESHES`): face (free boundary, E²,
/// a flat disk: the UV map must be continuous) and kitten (genus 1, flat torus, laid out face
/// by face): a valid common subdivision and no flipped triangle.
#[test]
fn conformal_flow_on_real_meshes_has_no_flipped_triangle() {
    use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
    use ricci::metric::Scheme;
    use ricci::progress::NoProgress;
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES unset: skipping the real meshes");
        return;
    };
    for (file, target, disk) in [
        ("face.off", TargetSpec::FreeBoundary, true),
        ("kitten.nf20k.off", TargetSpec::Uniform, false),
    ] {
        let (s, _) = ricci::mesh::io::read_surface(&dir.join(file)).unwrap();
        let o = FlowOptions {
            geometry: Geometry::Euclidean,
            scheme: Scheme::Conformal,
            target,
            ..FlowOptions::default()
        };
        let lengths = s.edge_lengths();
        let r = ricci_flow(&s.mesh, &lengths, &o, &mut NoProgress).unwrap();
        assert!(r.converged, "{file}: {:?}", r.notes);
        let it = r.triangulation.as_ref().unwrap();
        let scaled: Vec<f64> = lengths.iter().map(|l| l * r.input_scale).collect();
        let sub = CommonSubdivision::from_triangulation(
            &s.mesh,
            Geometry::Euclidean,
            &scaled,
            &it.triangulation,
            &r.u,
        )
        .unwrap();
        check_valid(&s, &sub);
        let layout = layout_euclidean(&sub.triangulation, &r.u).unwrap();
        let uv = sub.uv(Geometry::Euclidean, &r.u, &layout).unwrap();
        let flipped = sub.flipped_triangles(Geometry::Euclidean, &uv);
        let (_, gap) = sub.vertex_uv(&uv, 0.0);
        eprintln!(
            "{file}: {} flips, {} crossings, {} triangles, {flipped} flipped, seam gap {gap:.2e}",
            it.triangulation.flip_log.len(),
            sub.crossings.len(),
            sub.triangles.len()
        );
        assert_eq!(flipped, 0, "{file}");
        if disk {
            // A flat disk lays out without seams (up to the solver's tolerance).
            let size = layout
                .iter()
                .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
            assert!(
                gap < 1e-6 * size,
                "{file}: seam gap {gap} in a flat disk of size {size}"
            );
            // The uv.obj surface: one UV per vertex, the input's area.
            let out = sub
                .uv_surface(&s.mesh, &s.positions, &uv, 1e-9 * size)
                .unwrap();
            assert_eq!(out.mesh.n_vertices(), sub.n_vertices());
            let area = |m: &Mesh, p: &[[f64; 3]]| -> f64 {
                m.faces()
                    .iter()
                    .map(|f| tri_area(p[f[0] as usize], p[f[1] as usize], p[f[2] as usize]))
                    .sum()
            };
            let (a0, a1) = (area(&s.mesh, &s.positions), area(&out.mesh, &out.positions));
            assert!((a0 - a1).abs() <= 1e-12 * a0);
            let mut obj = Vec::new();
            ricci::mesh::io::write_obj(&mut obj, &out).unwrap();
            let text = String::from_utf8(obj).unwrap();
            assert_eq!(
                text.lines().filter(|l| l.starts_with("vt ")).count(),
                out.mesh.n_vertices()
            );
        }
    }
}

/// H²: the conformal flow of a genus-2 surface to constant curvature −1, laid out face by face
/// in the Poincaré disk: a valid subdivision, no flipped triangle (Klein model), and the
/// `uv.obj` surface keeps the input's area and Euler characteristic once seams are glued.
#[test]
fn hyperbolic_genus_two_has_no_flipped_triangle() {
    use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
    use ricci::metric::common_subdivision::layout_hyperbolic;
    use ricci::metric::Scheme;
    use ricci::progress::NoProgress;
    let s = generate::genus(2, 12).unwrap();
    let o = FlowOptions {
        geometry: Geometry::Hyperbolic,
        scheme: Scheme::Conformal,
        target: TargetSpec::Uniform,
        ..FlowOptions::default()
    };
    let lengths = s.edge_lengths();
    let r = ricci_flow(&s.mesh, &lengths, &o, &mut NoProgress).unwrap();
    assert!(r.converged, "{:?}", r.notes);
    let it = r.triangulation.as_ref().unwrap();
    let scaled: Vec<f64> = lengths.iter().map(|l| l * r.input_scale).collect();
    let sub = CommonSubdivision::from_triangulation(
        &s.mesh,
        Geometry::Hyperbolic,
        &scaled,
        &it.triangulation,
        &r.u,
    )
    .unwrap();
    check_valid(&s, &sub);
    assert!(!sub.crossings.is_empty());
    let layout = layout_hyperbolic(&sub.triangulation, &r.u).unwrap();
    // The layout is isometric: Poincaré distances of the corners are the final lengths.
    let t = &sub.triangulation;
    for h in 0..t.n_halfedges() as u32 {
        let (z, w) = (
            layout[h as usize],
            layout[IntrinsicTriangulation::next(h) as usize],
        );
        let num = (z[0] - w[0]).hypot(z[1] - w[1]);
        // |1 − z̄ w|
        let re = 1.0 - (z[0] * w[0] + z[1] * w[1]);
        let im = -(z[0] * w[1] - z[1] * w[0]);
        let d = 2.0 * (num / re.hypot(im)).atanh();
        let want = 2.0
            * (0.5 * t.scaled_lambda(t.edge[h as usize], &r.u))
                .exp()
                .asinh();
        assert!(
            (d - want).abs() < 1e-9 * want.max(1.0),
            "half-edge {h}: {d} vs {want}"
        );
    }
    let uv = sub.uv(Geometry::Hyperbolic, &r.u, &layout).unwrap();
    assert!(uv.iter().all(|z| z[0].hypot(z[1]) < 1.0));
    assert_eq!(sub.flipped_triangles(Geometry::Hyperbolic, &uv), 0);
    let out = sub.uv_surface(&s.mesh, &s.positions, &uv, 1e-9).unwrap();
    assert!(out.mesh.n_vertices() >= sub.n_vertices());
    assert_eq!(out.mesh.n_faces(), sub.triangles.len());
}

fn poincare_distance(z: [f64; 2], w: [f64; 2]) -> f64 {
    let num = (z[0] - w[0]).hypot(z[1] - w[1]);
    let re = 1.0 - (z[0] * w[0] + z[1] * w[1]);
    let im = -(z[0] * w[1] - z[1] * w[0]);
    2.0 * (num / re.hypot(im)).atanh()
}
fn klein(z: [f64; 2]) -> [f64; 2] {
    let s = 2.0 / (1.0 + z[0] * z[0] + z[1] * z[1]);
    [s * z[0], s * z[1]]
}

/// H²: a quad inscribed in a hyperbolic circle (Ptolemy for sinh(l/2) = geometric flip); the
/// crossing's UV in the Poincaré layout of the flipped quad is the intersection of the two
/// geodesic diagonals (straight lines in the Klein model).
#[test]
fn hyperbolic_cyclic_quad_crossing_is_the_geodesic_diagonals_intersection() {
    use ricci::metric::common_subdivision::layout_hyperbolic;
    let ang = [0.2f64, 1.7, 3.1, 4.6];
    let z: Vec<[f64; 2]> = ang.iter().map(|a| [0.6 * a.cos(), 0.6 * a.sin()]).collect();
    let s = Surface::new(
        z.iter().map(|p| [p[0], p[1], 0.0]).collect(),
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let hyp: Vec<f64> = (0..s.mesh.n_edges() as u32)
        .map(|e| {
            let [a, b] = s.mesh.edge_vertices(e);
            poincare_distance(z[a as usize], z[b as usize])
        })
        .collect();
    let mut tri = IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Hyperbolic, &hyp).unwrap();
    let diag = (0..s.mesh.n_edges() as u32)
        .find(|&e| !s.mesh.is_boundary_edge(e))
        .unwrap();
    assert!(tri.flip(diag));
    let l13 = poincare_distance(z[1], z[3]);
    assert!(
        (tri.lambda[diag as usize] - lambda_of_length(Geometry::Hyperbolic, l13)).abs() < 1e-12
    );
    let sub = CommonSubdivision::new(&s.mesh, Geometry::Hyperbolic, &hyp, &tri.flip_log).unwrap();
    assert_eq!(sub.crossings.len(), 1);
    check_valid(&s, &sub);
    let layout = layout_hyperbolic(&sub.triangulation, &[]).unwrap();
    let uv = sub.uv(Geometry::Hyperbolic, &[], &layout).unwrap();
    let (vuv, gap) = sub.vertex_uv(&uv, 1e-12);
    let vuv = vuv.unwrap_or_else(|| panic!("seam {gap}"));
    let k: Vec<[f64; 2]> = vuv.iter().map(|&w| klein(w)).collect();
    let x = intersect(k[0], k[2], k[1], k[3]);
    assert!(
        (k[4][0] - x[0]).abs() < 1e-12 && (k[4][1] - x[1]).abs() < 1e-12,
        "{:?} vs {x:?}",
        k[4]
    );
    assert_eq!(sub.flipped_triangles(Geometry::Hyperbolic, &uv), 0);
}

/// Without `$RICCI_MESHES`: a jittered disk lifted to a bumpy height field, flattened by the
/// conformal flow with free boundary (E²): the layout is a flat disk, so the UV map on the
/// common subdivision is seamless, and no triangle is flipped.
#[test]
fn free_boundary_flattening_of_a_bumpy_disk_is_seamless_without_flips() {
    use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
    use ricci::metric::Scheme;
    use ricci::progress::NoProgress;
    let d = generate::disk(24).unwrap();
    let mut rng = Lcg(31);
    let pos: Vec<[f64; 3]> = d
        .positions
        .iter()
        .enumerate()
        .map(|(v, p)| {
            let (mut x, mut y) = (p[0], p[1]);
            if !d.mesh.is_boundary_vertex(v as u32) {
                x += 0.02 * (rng.next() - 0.5);
                y += 0.02 * (rng.next() - 0.5);
            }
            [x, y, 0.6 * (3.0 * x).sin() * (2.0 * y).cos() + 0.8 * x * x]
        })
        .collect();
    let s = Surface::new(pos, d.mesh.faces().to_vec()).unwrap();
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Conformal,
        target: TargetSpec::FreeBoundary,
        ..FlowOptions::default()
    };
    let lengths = s.edge_lengths();
    let r = ricci_flow(&s.mesh, &lengths, &o, &mut NoProgress).unwrap();
    assert!(r.converged, "{:?}", r.notes);
    let it = r.triangulation.as_ref().unwrap();
    let scaled: Vec<f64> = lengths.iter().map(|l| l * r.input_scale).collect();
    let sub = CommonSubdivision::from_triangulation(
        &s.mesh,
        Geometry::Euclidean,
        &scaled,
        &it.triangulation,
        &r.u,
    )
    .unwrap();
    assert!(sub.crossings.len() > 5, "{} crossings", sub.crossings.len());
    check_valid(&s, &sub);
    let layout = layout_euclidean(&sub.triangulation, &r.u).unwrap();
    let uv = sub.uv(Geometry::Euclidean, &r.u, &layout).unwrap();
    assert_eq!(sub.flipped_triangles(Geometry::Euclidean, &uv), 0);
    let (vuv, gap) = sub.vertex_uv(&uv, 1e-8);
    assert!(vuv.is_some(), "seam gap {gap}");
}
