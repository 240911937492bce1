//! Layouts and deck groups of surfaces with exact metrics (`ricci::layout::synthetic`):
//! positions are recovered up to one isometry, deck generators match the closed forms, the
//! group relation holds, and layouts from different seed faces agree.

use num_complex::Complex64 as C;
use ricci::layout::isometry::{poincare_to_klein, Isometry, Mobius, RigidMotion, Rotation};
use ricci::layout::place::{align, layout, Space};
use ricci::layout::synthetic::{flat_torus, regular_polygon_surface, Gluing, SyntheticSurface};
use ricci::layout::{deck_group, Layout};
use ricci::mesh::Mesh;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Hyperbolic, Spherical};

fn seeds(m: &Mesh) -> [Option<u32>; 3] {
    let nf = m.n_faces() as u32;
    [None, Some(nf / 7), Some(nf - 1)]
}

/// Lay out from three seed faces; all agree with the exact positions up to one isometry.
fn check_layouts<S: Space<Point = C>>(s: &SyntheticSurface, tol: f64) -> Layout<C> {
    let mut first = None;
    for seed in seeds(&s.cut) {
        let l = layout::<S>(
            &s.cut,
            &IntrinsicMetric::new(S::KIND, s.cut_lengths.to_vec()),
            seed,
        )
        .unwrap();
        assert!(
            l.flipped_faces.is_empty(),
            "{} flipped",
            l.flipped_faces.len()
        );
        assert!(l.degenerate_faces.is_empty());
        assert!(
            l.max_length_error < tol,
            "length error {}",
            l.max_length_error
        );
        let (_, dev) = align::<S>(&s.positions, &l.positions).unwrap();
        assert!(dev < tol, "seed {seed:?}: deviation from exact {dev}");
        match &first {
            None => first = Some(l),
            Some(f) => {
                let (_, d) = align::<S>(&f.positions, &l.positions).unwrap();
                assert!(d < tol, "layouts from different seeds differ by {d}");
            }
        }
    }
    first.unwrap()
}

#[test]
fn flat_torus_deck_group_is_the_lattice() {
    let (w1, w2) = (C::new(2.0, 0.3), C::new(0.7, 1.4));
    let s = flat_torus(w1, w2, 12, 9, 0.25, 42).unwrap();
    assert_eq!(s.closed.n_vertices(), 12 * 9);
    let l = check_layouts::<Euclidean>(&s, 1e-12);
    let g = deck_group::<Euclidean>(&l, &s.polygon).unwrap();
    assert!(g.relation_error.unwrap() < 1e-12);
    assert!(g.max_edge_spread < 1e-12 && g.max_vertex_error < 1e-12);
    // In the frame of the exact positions the generators are the translations ω₁, ω₂.
    let (iso, _) = align::<Euclidean>(&s.positions, &l.positions).unwrap();
    let want = [w1, w2];
    for (k, (name, d)) in g.named_generators().into_iter().enumerate() {
        let e = iso.compose(&d).compose(&iso.inverse());
        assert!(
            e.distance(&RigidMotion::translation(want[k])) < 1e-12,
            "{name}: {e:?}"
        );
    }
}

fn corner_positions(s: &SyntheticSurface) -> Vec<C> {
    s.polygon
        .sides
        .iter()
        .map(|x| s.positions[x.vertices[0] as usize])
        .collect()
}

#[test]
fn bolza_side_pairings_translate_by_twice_the_inradius() {
    // Regular octagon with angles π/4, opposite sides glued: every side pairing is the
    // translation between opposite sides, of length 2 r with cosh r = cot(π/8) = 1 + √2.
    let s = regular_polygon_surface(Geometry::Hyperbolic, 2, Gluing::Opposite, 6).unwrap();
    assert_eq!(
        s.closed.n_vertices() as i64 - s.closed.n_edges() as i64 + s.closed.n_faces() as i64,
        -2
    );
    let l = check_layouts::<Hyperbolic>(&s, 1e-10);
    let g = deck_group::<Hyperbolic>(&l, &s.polygon).unwrap();
    let want = 2.0 * (1.0 + 2f64.sqrt()).acosh();
    for p in &g.pairings {
        assert!((p.map.translation_length() - want).abs() < 1e-10);
        assert!(p.edge_spread < 1e-10, "spread {}", p.edge_spread);
    }
    assert!(g.relation_error.unwrap() < 1e-10, "{:?}", g.relation_error);
}

#[test]
fn canonical_hyperbolic_polygons_match_exact_side_pairings_and_relation() {
    for genus in [2, 3] {
        let s = regular_polygon_surface(Geometry::Hyperbolic, genus, Gluing::Canonical, 5).unwrap();
        let chi =
            s.closed.n_vertices() as i64 - s.closed.n_edges() as i64 + s.closed.n_faces() as i64;
        assert_eq!(chi, 2 - 2 * genus as i64);
        let l = check_layouts::<Hyperbolic>(&s, 1e-10);
        let g = deck_group::<Hyperbolic>(&l, &s.polygon).unwrap();
        let rel = g.relation_error.unwrap();
        assert!(rel < 1e-10, "genus {genus}: relation error {rel}");
        // Side pairings against the exact ones from the polygon's corners: P_{m+1} ↦ P_s,
        // P_m ↦ P_{s+1}.
        let (iso, _) = align::<Hyperbolic>(&s.positions, &l.positions).unwrap();
        let c = corner_positions(&s);
        let n = c.len();
        for p in &g.pairings {
            let (k, m) = (p.side, p.partner);
            let exact = Mobius::from_pairs(c[(m + 1) % n], c[m], c[k], c[(k + 1) % n]);
            let got = iso.compose(&p.map).compose(&iso.inverse());
            assert!(
                got.distance(&exact) < 1e-9,
                "side {k}: {got:?} vs {exact:?}"
            );
        }
        // Deck generators D(x) move the base corner P_0 along the side labelled x.
        for (s_idx, side) in s.polygon.sides.iter().enumerate() {
            if side.inverse {
                continue;
            }
            let d = g.generators[side.letter.unwrap()].unwrap();
            let q = g.corner_maps[s_idx].unwrap();
            let p0 = l.positions[s.polygon.sides[0].vertices[0] as usize];
            let a = l.positions[side.vertices[0] as usize];
            let b = l.positions[*side.vertices.last().unwrap() as usize];
            assert!((q.apply(p0) - a).norm() < 1e-9);
            assert!((q.compose(&d).apply(p0) - b).norm() < 1e-9);
        }
        // Real projective structure: the Klein matrices act like the Möbius maps.
        for (_, d) in g.named_generators() {
            let k = d.klein_matrix();
            let z = C::new(0.1, -0.2);
            let kz = poincare_to_klein(z);
            let r: Vec<f64> = (0..3)
                .map(|i| k[i][0] * kz.re + k[i][1] * kz.im + k[i][2])
                .collect();
            assert!(
                (C::new(r[0] / r[2], r[1] / r[2]) - poincare_to_klein(d.apply(z))).norm() < 1e-9
            );
        }
    }
}

#[test]
fn flat_octagon_with_one_cone_has_rigid_motion_generators() {
    // The regular Euclidean octagon glued canonically: a flat metric with a cone of angle 6π.
    let s = regular_polygon_surface(Geometry::Euclidean, 2, Gluing::Canonical, 4).unwrap();
    let l = check_layouts::<Euclidean>(&s, 1e-12);
    let g = deck_group::<Euclidean>(&l, &s.polygon).unwrap();
    assert!(g.relation_error.unwrap() < 1e-12);
    // Side s+2 (direction 2π(s+2)/8 + 5π/8) is carried onto side s (direction 2πs/8 + 5π/8)
    // reversed: a rotation by −π/2 − π ≡ π/2.
    for p in &g.pairings {
        assert!((p.map.rot - C::new(0.0, 1.0)).norm() < 1e-12, "{:?}", p.map);
    }
}

/// The library's icosphere (unit sphere, `levels` 4-to-1 subdivisions) as connectivity and
/// positions.
fn icosphere(levels: u32) -> (Mesh, Vec<[f64; 3]>) {
    let s = ricci::mesh::generate::icosphere(levels).unwrap();
    (s.mesh, s.positions)
}

#[test]
fn closed_genus_zero_surface_goes_onto_the_sphere() {
    let (m, p) = icosphere(3);
    let lengths: Vec<f64> = (0..m.n_edges() as u32)
        .map(|e| {
            let [a, b] = m.edge_vertices(e);
            let (x, y) = (p[a as usize], p[b as usize]);
            let d = [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
            2.0 * (0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()).asin()
        })
        .collect();
    for seed in seeds(&m) {
        let l = layout::<Spherical>(
            &m,
            &IntrinsicMetric::new(ricci::metric::Geometry::Spherical, lengths.to_vec()),
            seed,
        )
        .unwrap();
        assert!(l.flipped_faces.is_empty());
        assert!(l.max_length_error < 1e-12, "{}", l.max_length_error);
        let (r, dev) = align::<Spherical>(&p, &l.positions).unwrap();
        assert!(dev < 1e-12, "{dev}");
        assert!(r.compose(&r.inverse()).distance(&Rotation::identity()) < 1e-12);
    }
    // The plane and the disk refuse a closed surface.
    assert!(layout::<Euclidean>(
        &m,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, lengths.to_vec()),
        None
    )
    .is_err());
}

#[test]
fn errors_name_the_problem() {
    let s = flat_torus(C::new(1.0, 0.0), C::new(0.0, 1.0), 4, 4, 0.0, 1).unwrap();
    let e = layout::<Euclidean>(
        &s.closed,
        &IntrinsicMetric::new(
            ricci::metric::Geometry::Euclidean,
            s.closed_lengths.to_vec(),
        ),
        None,
    )
    .unwrap_err();
    assert!(e.to_string().contains("genus 1"), "{e}");
    let mut bad = s.cut_lengths.clone();
    bad[3] = f64::NAN;
    let e = layout::<Euclidean>(
        &s.cut,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, bad.to_vec()),
        None,
    )
    .unwrap_err();
    assert!(e.to_string().contains("edge 3"), "{e}");
    let e = layout::<Euclidean>(
        &s.cut,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, s.cut_lengths.to_vec()),
        Some(10_000),
    )
    .unwrap_err();
    assert!(e.to_string().contains("seed face 10000"), "{e}");
}

#[test]
fn universal_cover_tiles_carry_words_that_evaluate_to_their_maps() {
    use ricci::layout::cover::{tiles_by_radius, tiles_by_words};
    let s = regular_polygon_surface(Geometry::Hyperbolic, 2, Gluing::Canonical, 3).unwrap();
    let l = layout::<Hyperbolic>(
        &s.cut,
        &IntrinsicMetric::new(ricci::metric::Geometry::Hyperbolic, s.cut_lengths.to_vec()),
        None,
    )
    .unwrap();
    let g = deck_group::<Hyperbolic>(&l, &s.polygon).unwrap();
    let base = l.positions[s.cut.face(ricci::layout::place::central_face(&s.cut))[0] as usize];
    let tiles = tiles_by_radius::<Hyperbolic>(&g, &s.polygon, base, 6.0, 5000).unwrap();
    assert!(tiles.len() > 50);
    for t in &tiles {
        let w = g.word(&t.word).unwrap();
        assert!(w.distance(&t.map) < 1e-8, "{:?}", t.word);
    }
    // The copies across the 8 sides of F are among the tiles.
    for side in 0..8 {
        let sm = g.side_map(side).unwrap();
        assert!(tiles.iter().any(|t| t.map.distance(&sm) < 1e-9));
    }
    // Distinct tiles have distinct base images; words of length ≤ 2: 1 + 8 + 8·7.
    let w = tiles_by_words(&g, 2, 1000).unwrap();
    assert_eq!(w.len(), 1 + 8 + 56);
}

/// A long thin hyperbolic strip (two rows of vertices at signed distance ±0.05 from a geodesic,
/// Fermi coordinates, 300 steps of 0.1: length 30) with its exact metric,
/// `sinh²(d/2) = cosh w₁ cosh w₂ sinh²(Δt/2) + sinh²(Δw/2)`. Laid out from either end it
/// reaches hyperbolic distance ~30 from the centre of the disk, where double-precision
/// coordinates resolve only ~1e-16·e^30 ≈ 1e-3: the layout must keep its accuracy through its
/// double-double positions (lengths, orientation and the alignment of the two layouts).
#[test]
fn hyperbolic_layout_keeps_its_accuracy_far_from_the_centre() {
    use ricci::layout::align_layouts;
    let (n, h, w0) = (300usize, 0.1f64, 0.05f64);
    let coord = |v: usize| -> (f64, f64) {
        let (i, row) = (v / 2, v % 2);
        (i as f64 * h, if row == 0 { -w0 } else { w0 })
    };
    let mut faces = Vec::new();
    for i in 0..n as u32 {
        let (a0, b0, a1, b1) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        faces.push([a0, a1, b0]);
        faces.push([a1, b1, b0]);
    }
    let mesh = Mesh::from_triangles(2 * (n + 1), faces).unwrap();
    let lengths: Vec<f64> = (0..mesh.n_edges() as u32)
        .map(|e| {
            let [p, q] = mesh.edge_vertices(e);
            let ((t1, w1), (t2, w2)) = (coord(p as usize), coord(q as usize));
            let s2 = w1.cosh() * w2.cosh() * (0.5 * (t2 - t1)).sinh().powi(2)
                + (0.5 * (w2 - w1)).sinh().powi(2);
            2.0 * s2.sqrt().asinh()
        })
        .collect();
    let nf = mesh.n_faces() as u32;
    let from_start = layout::<Hyperbolic>(
        &mesh,
        &IntrinsicMetric::new(ricci::metric::Geometry::Hyperbolic, lengths.to_vec()),
        Some(0),
    )
    .unwrap();
    let from_end = layout::<Hyperbolic>(
        &mesh,
        &IntrinsicMetric::new(ricci::metric::Geometry::Hyperbolic, lengths.to_vec()),
        Some(nf - 1),
    )
    .unwrap();
    for l in [&from_start, &from_end] {
        assert!(l.max_radius > 29.0, "radius {}", l.max_radius);
        assert!(l.flipped_faces.is_empty() && l.degenerate_faces.is_empty());
        assert!(l.max_length_error < 1e-12, "{:e}", l.max_length_error);
        assert_eq!(l.positions_lo.len(), l.positions.len());
        // The premise: the rounded coordinates alone cannot carry this accuracy.
        let rounded = (0..mesh.n_edges() as u32)
            .map(|e| {
                let [p, q] = mesh.edge_vertices(e);
                let d = Hyperbolic::distance(l.positions[p as usize], l.positions[q as usize]);
                (d - lengths[e as usize]).abs()
            })
            .fold(0.0, f64::max);
        assert!(
            rounded > 1e-6,
            "double-precision coordinates err by {rounded:e}"
        );
    }
    let (_, dev) = align_layouts::<Hyperbolic>(&from_start, &from_end).unwrap();
    assert!(
        dev < 1e-10,
        "the two layouts differ by {dev:e} after one isometry"
    );
}
