//! Manifold splines over the affine atlas (issue 7, paper 000 §4 Step 5 and §5): the degree-3
//! spline is C² across every interior edge and evaluates the same in every chart of a face.
//!
//! The single cone grades the faces around it down by orders of magnitude (to 1e-7 of the
//! central chart on 3holes.off); stored in the central chart, such a face's corners are
//! accurate to only ~1e-9 of the face, and the spline built there jumped by 1e-3 (3holes.off,
//! order 2, relative). The atlas now gives every face whose home chart is too large for it a
//! local chart ([`ricci::atlas::LOCAL_CHART_CONDITIONING`]); these tests check the
//! consequence from the metric (side lengths in the home charts relative to each face), the
//! continuity of the spline, the same against `LocalCharts` on the same metric, and chart
//! independence.
//!
//! Real-mesh tests read `RICCI_MESHES` and skip with a note when it is unset.

use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts, LOCAL_CHART_CONDITIONING};
use ricci::mesh::io::read_surface;
use ricci::mesh::Surface;
use ricci::progress::NoProgress;
use ricci::spline::dms::{KnotOptions, Workspace};
use ricci::spline::fit::fair;
use ricci::spline::manifold::{rotate_partials, LocalCharts, ManifoldSpace};
use ricci::spline::simplex::n_partials;
use ricci::spline::surface::continuity;

mod ricci_meshes;
use ricci_meshes::ricci_meshes;

fn load(name: &str) -> Option<Surface> {
    let Some(dir) = ricci_meshes() else {
        eprintln!("note: RICCI_MESHES is not set; skipping {name}");
        return None;
    };
    Some(read_surface(&dir.join(name)).expect(name).0)
}

/// Largest |(side in the chart) − (metric length)| / (the face's shortest side) over the
/// neighbourhood (faces sharing a vertex, not at a cone) of every active face in its home
/// chart: how accurately the charts the bases live in store each face, relative to the face.
fn home_chart_accuracy(atlas: &AffineAtlas) -> f64 {
    let mesh = atlas.mesh();
    let l = atlas.lengths();
    let sing = atlas.singular_vertices();
    let at_cone = |g: u32| mesh.face(g).iter().any(|v| sing.contains(v));
    let mut worst: f64 = 0.0;
    for f in 0..mesh.n_faces() as u32 {
        let Some(h) = atlas.home_chart(f) else {
            assert!(at_cone(f), "face {f} has no home chart");
            continue;
        };
        for v in mesh.face(f) {
            for g in mesh.vertex_faces(v) {
                if at_cone(g) {
                    continue;
                }
                let c = atlas
                    .face_coords(h, g)
                    .unwrap_or_else(|| panic!("face {g} missing in home chart {h} of {f}"));
                let hs = mesh.face_halfedges(g);
                let side: Vec<f64> = hs.iter().map(|&e| l[mesh.he_edge(e) as usize]).collect();
                let short = side.iter().copied().fold(f64::INFINITY, f64::min);
                for i in 0..3 {
                    let (a, b) = (c[i], c[(i + 1) % 3]);
                    let d = (a[0] - b[0]).hypot(a[1] - b[1]);
                    worst = worst.max((d - side[i]).abs() / short);
                }
            }
        }
    }
    worst
}

/// `(values, partials)`: the largest difference between evaluating at the same point of a
/// face in its home chart and in each other chart containing it (partials rotated back),
/// values relative to `diag`, partials of order 1..=2 relative to the largest partial of that
/// order at the point; `well` restricts to charts no larger than
/// [`LOCAL_CHART_CONDITIONING`] of the face.
fn chart_independence<A: FlatCharts + Sync>(
    atlas: &AffineAtlas,
    space: &ManifoldSpace<'_, A>,
    control: &[f64],
    stride: usize,
    diag: f64,
) -> ([f64; 2], [f64; 2], usize) {
    let order = 2;
    let np = n_partials(order);
    let mut ws = Workspace::default();
    let (mut val, mut par) = ([0.0f64; 2], [0.0f64; 2]);
    let mut compared = 0;
    for f in (0..atlas.mesh().n_faces() as u32).step_by(stride) {
        if !space.is_active(f) {
            continue;
        }
        let c0 = space.canonical_chart(f);
        for b in [
            [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
            [0.7, 0.2, 0.1],
            [0.05, 0.15, 0.8],
        ] {
            let mut base = vec![0.0; np * 3];
            space
                .evaluate(control, 3, f, b, order, &mut ws, &mut base)
                .unwrap();
            for c in atlas.charts_of_face(f) {
                if c == c0 {
                    continue;
                }
                let well = atlas.conditioning(c, f) <= LOCAL_CHART_CONDITIONING;
                let x = atlas.face_coords(c, f).unwrap();
                let u = [
                    b[0] * x[0][0] + b[1] * x[1][0] + b[2] * x[2][0],
                    b[0] * x[0][1] + b[1] * x[1][1] + b[2] * x[2][1],
                ];
                let mut out = vec![0.0; np * 3];
                space
                    .evaluate_in_chart(control, 3, c, f, u, order, &mut ws, &mut out)
                    .unwrap();
                let (m, _) = atlas.transition(c0, c, f).unwrap();
                for d in 0..3 {
                    let mut col: Vec<f64> = (0..np).map(|k| out[k * 3 + d]).collect();
                    rotate_partials(order, m.rot, &mut col);
                    for k in 0..np {
                        out[k * 3 + d] = col[k];
                    }
                }
                let mut v: f64 = 0.0;
                for d in 0..3 {
                    v = v.max((out[d] - base[d]).abs() / diag);
                }
                let mut p: f64 = 0.0;
                for k in 1..=order {
                    let idx = n_partials(k) - k - 1..n_partials(k);
                    let scale = base[idx.start * 3..idx.end * 3]
                        .iter()
                        .fold(1e-300, |a: f64, x| a.max(x.abs()));
                    for i in idx {
                        for d in 0..3 {
                            p = p.max((out[i * 3 + d] - base[i * 3 + d]).abs() / scale);
                        }
                    }
                }
                val[0] = val[0].max(v);
                par[0] = par[0].max(p);
                if well {
                    val[1] = val[1].max(v);
                    par[1] = par[1].max(p);
                }
                compared += 1;
            }
        }
    }
    (val, par, compared)
}

fn sci(x: &[f64]) -> String {
    x.iter()
        .map(|v| format!("{v:.1e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn check(s: &Surface, name: &str, stride: usize) {
    let atlas = AffineAtlas::build(s, &AtlasOptions::default(), &mut NoProgress).unwrap();
    let r = &atlas.report;
    assert_eq!(atlas.singular_vertices().len(), 1, "{name}: one cone");
    assert_eq!(r.faces_without_home, 0, "{name}");
    assert_eq!(r.flipped_faces, 0, "{name}");
    // The cone's graded neighbourhood needs local charts (the central chart is up to 10⁵
    // (eight.off) – 10⁷ (3holes.off) of those faces across), and afterwards every home chart
    // stores every face the basis is evaluated on to ~1e-13 of the face.
    assert!(r.local_charts > 0, "{name}: no local charts");
    // The cause: the central chart (the layout of the cut disk) alone is this many times
    // larger than the cone's smallest faces (measured 4.8e3 genus2:16, 2.6e5 eight.off,
    // 6.2e7 3holes.off, where its bases jumped by 9.2e-4 at order 2).
    let central = (0..atlas.mesh().n_faces() as u32)
        .filter(|&f| atlas.home_chart(f).is_some())
        .map(|f| atlas.conditioning(0, f))
        .fold(0.0, f64::max);
    assert!(central > LOCAL_CHART_CONDITIONING, "{name}: {central:.2e}");
    assert!(
        r.max_home_conditioning <= LOCAL_CHART_CONDITIONING,
        "{name}: {r:?}"
    );
    let acc = home_chart_accuracy(&atlas);
    eprintln!(
        "{name}: {} charts ({} local), central chart conditioning {central:.1e}, home \
         conditioning {:.1e}, home-chart sides to {acc:.1e} of the face, transitions {:.1e} \
         ({:.1e} of the face)",
        atlas.n_charts(),
        r.local_charts,
        r.max_home_conditioning,
        r.max_transition_error,
        r.max_relative_transition_error
    );
    // Measured 2.1e-13 (genus2:16), 1.2e-12 (eight.off), 1.4e-12 (3holes.off); the central
    // chart alone stores the smallest faces to 1.1e-8 of themselves (3holes.off, transition
    // residual relative to the face).
    assert!(acc <= 1e-11, "{name}: home charts store faces to {acc:.2e}");

    let space = ManifoldSpace::new(&atlas, 3, &KnotOptions::default()).unwrap();
    let (control, fairing) = fair(&space, &space.subdivision_control_points(), 3, 1).unwrap();
    assert!(fairing.converged, "{name}: {fairing:?}");
    let cont = continuity(&space, &control, &[], 1e-8).unwrap();
    // The same metric, knots and control points over `LocalCharts` (one development per
    // face's neighbourhood, independent of the atlas): the level the recurrence reaches.
    let local = LocalCharts::new(
        atlas.mesh().clone(),
        ricci::metric::IntrinsicMetric::euclidean(atlas.lengths().to_vec()),
        atlas.positions().to_vec(),
        atlas.singular_vertices().to_vec(),
        None,
    )
    .unwrap();
    let space2 = ManifoldSpace::new(&local, 3, &KnotOptions::default()).unwrap();
    let cont2 = continuity(&space2, &control, &[], 1e-8).unwrap();
    eprintln!(
        "{name}: relative jumps over the atlas {}, over LocalCharts {} ({} edges between \
         different home charts)",
        sci(&cont.relative_jumps),
        sci(&cont2.relative_jumps),
        cont.chart_boundary_edges
    );
    // Measured (double-double recurrence) ≤ 9.8e-12 over the atlas, ≤ 8.3e-11 over
    // `LocalCharts`; the planar bound is 1e-8.
    for k in 0..3 {
        let bound = 1e-9f64.max(1.5 * cont2.relative_jumps[k]);
        assert!(
            cont.relative_jumps[k] <= bound,
            "{name}: order-{k} jump {:.2e} over the atlas (LocalCharts {:.2e})",
            cont.relative_jumps[k],
            cont2.relative_jumps[k]
        );
    }
    // Not C³: the measurement can fail.
    assert!(cont.relative_jumps[3] > 1e-4, "{name}: {cont:?}");

    let (val, par, compared) = chart_independence(&atlas, &space, &control, stride, s.diagonal());
    eprintln!(
        "{name}: chart independence ({compared} comparisons): values {:.1e} of the diagonal, \
         partials {:.1e} of the partial ({:.1e} / {:.1e} in charts within the conditioning bound)",
        val[0], par[0], val[1], par[1]
    );
    assert!(compared > 0);
    assert!(val[0] <= 1e-10, "{name}: values differ by {:.2e}", val[0]);
    // Charts within the bound: the 1e-10 (spline_manifold.rs `ISSUE`); measured
    // 3.5e-12 (genus2:16), 3.3e-13 (eight.off), 5.5e-13 (3holes.off).
    assert!(
        par[1] <= 1e-10,
        "{name}: partials differ by {:.2e} between well-conditioned charts",
        par[1]
    );
    // Any chart, including the central chart at the cone's smallest faces (stored there to
    // 1.1e-8 of the face on 3holes.off, so the point itself is known only to that): measured
    // 6.9e-12 / 2.8e-10 / 2.4e-8.
    assert!(par[0] <= 1e-6, "{name}: partials differ by {:.2e}", par[0]);
}

#[test]
fn generated_genus2_is_c2_over_the_atlas() {
    check(
        &ricci::mesh::generate::genus(2, 16).unwrap(),
        "genus2:16",
        1,
    );
}

#[test]
fn eight_is_c2_over_the_atlas() {
    let Some(s) = load("eight.off") else { return };
    check(&s, "eight.off", 3);
}

#[test]
fn three_holes_is_c2_over_the_atlas() {
    let Some(s) = load("3holes.off") else { return };
    check(&s, "3holes.off", 7);
}
