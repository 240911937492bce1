//! Genus 1: the modulus τ of the holomorphic 1-form (`ricci::analysis::forms`, period of the
//! form normalized on `a`) against two independent sources — the translation lattice of the
//! flat metric's deck group (conformal flow → cut → layout → deck group, the chain of
//! `ricci spectrum`) and the closed form of a torus of revolution (`√(R² − r²)/r`, a
//! rectangle) — and its independence of the base vertex of the cut.

mod ricci_meshes;

use ricci::analysis::forms::{holomorphic_forms, FormsOptions, FormsTriangulation};
use ricci::analysis::spectrum::torus_modulus;
use ricci::cut::CutOptions;
use ricci::layout::pipeline::{cut_disk, uniformization_metric};
use ricci::layout::{deck_group, layout};
use ricci::mesh::generate::{irregular_torus, torus};
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Scheme};
use ricci::progress::NoProgress;

/// τ from the flat metric's deck group (reduced to the fundamental domain).
fn deck_modulus(s: &Surface) -> (f64, f64) {
    let f = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Euclidean,
        Scheme::Conformal,
        1e-11,
        &mut NoProgress,
    )
    .unwrap();
    assert!(f.converged);
    let work = &f.triangulation.as_ref().unwrap().simplicial.mesh;
    let d = cut_disk(
        work,
        &IntrinsicMetric::new(Geometry::Euclidean, f.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    let l = layout::<Euclidean>(&d.mesh, &d.metric, None).unwrap();
    let g = deck_group::<Euclidean>(&l, &d.polygon).unwrap();
    let gens = g.named_generators();
    torus_modulus(gens[0].1.t, gens[1].1.t).unwrap()
}

/// τ from the holomorphic 1-form (reduced), and the report's star defect.
fn forms_modulus(s: &Surface, triangulation: FormsTriangulation, base: Option<u32>) -> (f64, f64) {
    let opts = FormsOptions {
        triangulation,
        cut: CutOptions {
            base,
            ..Default::default()
        },
        ..Default::default()
    };
    let h = holomorphic_forms(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Some(&s.positions),
        &opts,
        &mut NoProgress,
    )
    .unwrap();
    assert!(h.report.harmonic_residual < 1e-9, "{:?}", h.report);
    assert!(h.report.closedness < 1e-12, "{:?}", h.report);
    assert!(
        h.period_matrix.im[0][0] > 0.0,
        "Im τ = {} must be positive (a-cycle, b-cycle positively oriented)",
        h.period_matrix.im[0][0]
    );
    h.modulus().unwrap()
}

fn rel(a: (f64, f64), b: (f64, f64)) -> f64 {
    ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt() / (b.0 * b.0 + b.1 * b.1).sqrt()
}

/// Forms on the intrinsic Delaunay triangulation of the input metric vs the deck group of the
/// flat metric: two discretizations, agreeing to `tol`. On the flat metric's own
/// triangulation the form is exactly `dz`: agreement to rounding.
fn check(name: &str, s: &Surface, tol: f64) -> (f64, f64) {
    let deck = deck_modulus(s);
    let del = forms_modulus(s, FormsTriangulation::Delaunay, None);
    let flat = forms_modulus(s, FormsTriangulation::Flat, None);
    let (e_del, e_flat) = (rel(del, deck), rel(flat, deck));
    eprintln!(
        "{name}: deck τ = {:.6} + {:.6}i, forms (Delaunay) {:.6} + {:.6}i ({e_del:.1e}), forms (flat) {e_flat:.1e}",
        deck.0, deck.1, del.0, del.1
    );
    assert!(
        e_del <= tol,
        "{name}: τ from the 1-form {del:?} vs the deck group {deck:?}: {e_del:e}"
    );
    assert!(
        e_flat <= 1e-9,
        "{name}: on the flat metric the 1-form is dz: {flat:?} vs {deck:?}"
    );
    del
}

#[test]
fn generated_tori_match_the_deck_group_and_the_closed_form() {
    for (name, s, big, small) in [
        (
            "torus(1, 0.4, 64)",
            torus(1.0, 0.4, 64).unwrap(),
            1.0f64,
            0.4f64,
        ),
        (
            "irregular torus(1, 0.25)",
            irregular_torus(1.0, 0.25, 4000, 5).unwrap(),
            1.0,
            0.25,
        ),
        (
            "irregular torus(2, 1)",
            irregular_torus(2.0, 1.0, 4000, 7).unwrap(),
            2.0,
            1.0,
        ),
    ] {
        let (re, im) = check(name, &s, 1e-3);
        let want = (big * big - small * small).sqrt() / small;
        let got = if want >= 1.0 { im } else { 1.0 / im };
        eprintln!("  closed form {want:.6}: {:.1e}", (got - want).abs() / want);
        assert!(re.abs() < 3e-3, "{name}: a rectangle, Re τ = {re}");
        assert!(
            ((got - want) / want).abs() <= 3e-3,
            "{name}: modulus {got} vs closed form {want}"
        );
    }
}

#[test]
fn base_vertex_does_not_change_the_modulus() {
    let s = irregular_torus(1.0, 0.3, 3000, 3).unwrap();
    let a = forms_modulus(&s, FormsTriangulation::Delaunay, Some(0));
    let b = forms_modulus(&s, FormsTriangulation::Delaunay, Some(1777));
    // The two cuts' bases differ by an element of SL(2, Z); torus_modulus undoes it.
    assert!(rel(a, b) < 1e-3, "{a:?} vs {b:?}");
}

#[test]
fn shared_tori_match_the_deck_group() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    for m in [
        "torus.off",
        "bob_tri.obj",
        "kitten.nf20k.off",
        "rocker-arm.off",
    ] {
        let (s, _) = ricci::mesh::io::read_surface(&dir.join(m)).unwrap();
        check(m, &s, 1e-3);
    }
}
