//! The E² free-boundary conformal flow run on the double of the surface
//! (`ricci::flow::double::flow_on_double`; issue 15, the disk whose boundary faces were split
//! off-centre). Checked: convergence with no degenerate face where the flow on the surface
//! itself stalls; σ-symmetry of the solution (not imposed by the solver: it follows from
//! uniqueness); `u = 0` at the held boundary vertices; Gauss–Bonnet on the half; agreement with
//! the surface's own flow where no boundary edge flips; `u = 0` for a surface that is already
//! flat (the closed form).

use ricci::flow::double::double_triangulation;
use ricci::flow::double::flow_on_double;
use ricci::flow::target::resolve;
use ricci::flow::{ricci_flow, FlowOptions, TargetSpec};
use ricci::mesh::{double_cover, generate, topology, Surface};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Geometry, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

/// The bumpy disk of issue 15 (`ricci::mesh::generate::bumpy_split_disk`), 120 faces split
/// off-centre, boundary faces too unless `interior_only`.
fn bumpy_disk(interior_only: bool) -> Surface {
    generate::bumpy_split_disk(120, 7, 0.75, !interior_only).unwrap()
}

/// The checks every solution must pass; returns the flow.
fn checked_double_flow(name: &str, s: &Surface) -> ricci::flow::double::DoubleFlow {
    let m = &s.mesh;
    let target = resolve(m, Geometry::Euclidean, &TargetSpec::FreeBoundary).unwrap();
    let r = flow_on_double(
        m,
        &s.edge_lengths(),
        Geometry::Euclidean,
        &target,
        1e-10,
        &mut NoProgress,
    )
    .unwrap();
    eprintln!(
        "{name}: converged {} in {} iterations, max |K − K̄| {:.2e}, {} isometric + {} Ptolemy \
         flips, {} boundary edges flipped, asymmetry {:.1e}",
        r.converged,
        r.iterations,
        r.max_error,
        r.initial_flips,
        r.flips,
        r.boundary_edges_flipped,
        r.asymmetry
    );
    assert!(r.converged, "{name}: {:?}", r.notes);
    assert!(r.max_error <= 1e-10, "{name}");
    assert_eq!(r.degenerate_faces, 0, "{name}");
    // σ-symmetric (uniqueness), boundary held at 0, interior flat.
    assert!(r.asymmetry <= 1e-9, "{name}: asymmetry {}", r.asymmetry);
    let mut total = 0.0;
    for v in 0..m.n_vertices() as u32 {
        let k = r.curvature[v as usize];
        total += k;
        if m.is_boundary_vertex(v) {
            assert_eq!(r.u[v as usize], 0.0, "{name}: boundary vertex {v}");
        } else {
            assert!(k.abs() <= 1e-10, "{name}: K = {k} at interior vertex {v}");
        }
    }
    // Gauss–Bonnet of the half: Σ K = 2π χ(M) (interior K = 0: the boundary's turning angles).
    let chi = topology(m).euler_characteristic() as f64;
    assert!(
        (total - 2.0 * PI * chi).abs() <= 1e-9,
        "{name}: Σ K = {total}, χ = {chi}"
    );
    r
}

/// Issue 15: the disk whose boundary faces were split off-centre too. On the surface the flow
/// stalls (boundary edges cannot flip); on the double it converges, and boundary edges flip.
#[test]
fn split_boundary_disk_converges_on_the_double() {
    let s = bumpy_disk(false);
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Conformal,
        target: TargetSpec::FreeBoundary,
        tolerance: 1e-10,
        ..FlowOptions::default()
    };
    match ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress) {
        Ok(r) => eprintln!(
            "on the surface: converged {}, max |K − K̄| {:.2e}, {} degenerate faces, notes {:?}",
            r.converged, r.max_curvature_error, r.degenerate_faces, r.notes
        ),
        Err(e) => eprintln!("on the surface: {e}"),
    }
    let r = checked_double_flow("split-boundary disk", &s);
    assert!(
        r.boundary_edges_flipped > 0,
        "the case lost its point: no boundary edge flips on the double"
    );
}

/// Where the surface's own flow is valid (interior faces split only) and no boundary edge of
/// the double flips, the two flows solve the same problem: the same `u`.
#[test]
fn double_agrees_with_the_surface_flow_when_no_boundary_edge_flips() {
    let s = bumpy_disk(true);
    let r = checked_double_flow("interior-split disk", &s);
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Conformal,
        target: TargetSpec::FreeBoundary,
        tolerance: 1e-12,
        ..FlowOptions::default()
    };
    let f = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap();
    assert!(f.converged, "{:?}", f.notes);
    assert_eq!(
        r.boundary_edges_flipped, 0,
        "precondition: no boundary edge flips here"
    );
    let d =
        r.u.iter()
            .zip(&f.u)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
    assert!(d <= 1e-8, "u differs by {d}");
}

/// A flat disk (z = 0) with off-centre splits everywhere: its input metric is already the
/// flat metric with the boundary held, so `u = 0` (closed form) although boundary edges of
/// the double are flipped by the isometric Delaunay flips.
#[test]
fn flat_disk_on_the_double_keeps_its_metric() {
    let d = generate::disk(12).unwrap();
    let s = generate::split_off_centre(&d, 80, 3, 0.8, true).unwrap();
    assert!(s.positions.iter().all(|p| p[2] == 0.0));
    let r = checked_double_flow("flat disk", &s);
    let umax = r.u_double.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(umax <= 1e-9, "max |u| = {umax}");
}

/// The double built as a Δ-complex (`double_triangulation`) is `mesh::double_cover`'s mesh
/// face by face, with every edge's coordinate that of the surface edge it copies.
#[test]
fn double_triangulation_matches_the_double_cover() {
    let s = bumpy_disk(false);
    let l = s.edge_lengths();
    let (tri, sigma, origin) = double_triangulation(&s.mesh, Geometry::Euclidean, &l).unwrap();
    let (d, sigma2) = double_cover(&s.mesh).unwrap();
    assert_eq!(sigma, sigma2);
    assert_eq!(tri.n_faces(), d.n_faces());
    assert_eq!(tri.n_edges(), d.n_edges());
    for f in 0..d.n_faces() as u32 {
        assert_eq!(tri.face(f), d.face(f), "face {f}");
    }
    for e in 0..tri.n_edges() as u32 {
        let [a, b] = tri.edge_vertices(e);
        let o = origin[e as usize];
        let mut got = [a, b].map(|v| v.min(sigma[v as usize]));
        let mut want = s.mesh.edge_vertices(o);
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want, "edge {e}");
        assert_eq!(tri.lambda[e as usize], 2.0 * l[o as usize].ln(), "edge {e}");
    }
}

/// A pair of pants whose interior edges join boundary vertices (the double is a Δ-complex
/// with two edges between them; `double_cover` refuses it): the flow on the double converges.
#[test]
fn pants_with_chords_converge_on_the_double() {
    let s = generate::pair_of_pants(24).unwrap();
    assert!(double_cover(&s.mesh).is_err());
    let r = checked_double_flow("pants", &s);
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Conformal,
        target: TargetSpec::FreeBoundary,
        tolerance: 1e-12,
        ..FlowOptions::default()
    };
    let f = ricci_flow(&s.mesh, &s.edge_lengths(), &o, &mut NoProgress).unwrap();
    if r.boundary_edges_flipped == 0 && f.converged {
        let d =
            r.u.iter()
                .zip(&f.u)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f64, f64::max);
        eprintln!("pants: max |u_double − u_surface| = {d:.2e}");
    }
}

/// The next step's premise (docs/notes/wave2-s7-dbl7.md): the faces of the double's final
/// Delaunay triangulation that meet the surface — a vertex in its interior, which includes the
/// rung faces `(x, σx, y)` whose edge `x σx` crosses the boundary — form a topological disk
/// (χ = 1, one boundary loop) whose metric is flat (the cones sit at the boundary vertices, on
/// its boundary): laid out in the plane, every edge has its length and no face is flipped.
#[test]
fn faces_meeting_the_surface_form_a_flat_disk() {
    use ricci::layout::place::layout;
    use ricci::mesh::Mesh;
    use ricci::metric::Euclidean;
    for (count, seed) in [(120, 7), (200, 3), (300, 11)] {
        let s = generate::bumpy_split_disk(count, seed, 0.75, true).unwrap();
        let name = format!("disk {count}/{seed}");
        let r = checked_double_flow(&name, &s);
        assert!(r.boundary_edges_flipped > 0, "{name}");
        let nv = s.mesh.n_vertices();
        let sm = r
            .triangulation
            .to_simplicial(Geometry::Euclidean, &r.u_double)
            .unwrap();
        let inside = |v: u32| v != u32::MAX && (v as usize) < nv && r.sigma[v as usize] != v;
        let mut id = vec![u32::MAX; sm.mesh.n_vertices()];
        let mut back = Vec::new();
        let mut faces = Vec::new();
        for f in 0..sm.mesh.n_faces() as u32 {
            let t = sm.mesh.face(f);
            if !t.iter().any(|&v| inside(sm.vertex_origin[v as usize])) {
                continue;
            }
            faces.push(t.map(|v| {
                if id[v as usize] == u32::MAX {
                    id[v as usize] = back.len() as u32;
                    back.push(v);
                }
                id[v as usize]
            }));
        }
        let region = Mesh::from_triangles(back.len(), faces).unwrap();
        let t = topology(&region);
        assert_eq!(t.components.len(), 1, "{name}");
        assert_eq!(t.euler_characteristic(), 1, "{name}");
        assert_eq!(t.boundary_loops(), 1, "{name}");
        // Some faces of the region are rung faces: two of their corners are x and σx.
        let rungs = region
            .faces()
            .iter()
            .filter(|t| {
                let o = t.map(|v| sm.vertex_origin[back[v as usize] as usize]);
                (0..3).any(|k| {
                    let (a, b) = (o[k], o[(k + 1) % 3]);
                    a != u32::MAX && b != u32::MAX && a != b && r.sigma[a as usize] == b
                })
            })
            .count();
        assert!(rungs > 0, "{name}: no rung face");
        let lengths: Vec<f64> = (0..region.n_edges() as u32)
            .map(|e| {
                let [a, b] = region.edge_vertices(e).map(|v| back[v as usize]);
                let h = sm.mesh.halfedge_between(a, b).unwrap();
                sm.lengths[sm.mesh.he_edge(h) as usize]
            })
            .collect();
        let l = layout::<Euclidean>(
            &region,
            &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, lengths.to_vec()),
            None,
        )
        .unwrap();
        eprintln!(
            "{name}: region {} faces ({rungs} rung faces), {} flipped, {} degenerate, length error {:.1e}",
            region.n_faces(),
            l.flipped_faces.len(),
            l.degenerate_faces.len(),
            l.max_length_error
        );
        assert!(l.flipped_faces.is_empty(), "{name}");
        assert!(l.degenerate_faces.is_empty(), "{name}");
        assert!(l.max_length_error <= 1e-12, "{name}");
    }
}
