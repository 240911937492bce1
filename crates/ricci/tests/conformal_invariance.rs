//! The conformal scheme computes invariants of the *surface*, not of its triangulation
//! (issue 15, docs/DESIGN.md §5): a surface, its 1-to-4 midpoint subdivision and a copy with random
//! off-centre face splits give length spectra within 0.3 % of each other, and an irregular
//! torus of revolution (random points, Delaunay in the parameter square, slivers below 1°)
//! matches the closed form `√(R² − r²)/r` to 0.3 %. Plain vertex scaling degenerates on the
//! face splits (faces violating the triangle inequality), Thurston packing changes the
//! structure; the intrinsic Delaunay flips make it work.

mod ricci_meshes;

use ricci::analysis::spectrum::{fuchsian_spectrum, lattice_spectrum, torus_modulus};
use ricci::layout::pipeline::{
    cut_disk, cut_disk_polished, polish_uniformization, uniformization_metric,
};
use ricci::layout::{deck_group, layout, layout_dd};
use ricci::mesh::generate::{genus, irregular_torus, midpoint_subdivision, random_face_splits};
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;

/// Normalized lattice lengths (genus 1) or absolute geodesic lengths (genus ≥ 2), through the
/// default pipeline of `ricci spectrum` (conformal flow, H² polish, cut, layout, deck group).
fn spectrum(s: &Surface, geometry: Geometry, count: usize) -> Vec<f64> {
    let f = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        geometry,
        Scheme::Conformal,
        if geometry == Geometry::Hyperbolic {
            1e-12
        } else {
            1e-11
        },
        &mut NoProgress,
    )
    .unwrap();
    assert!(
        f.converged && f.degenerate_faces == 0,
        "flow: {:e}, {} degenerate",
        f.max_curvature_error,
        f.degenerate_faces
    );
    let work = &f.triangulation.as_ref().unwrap().simplicial.mesh;
    if geometry == Geometry::Euclidean {
        let d = cut_disk(
            work,
            &IntrinsicMetric::new(geometry, f.lengths.to_vec()),
            None,
            None,
            &mut NoProgress,
        )
        .unwrap();
        let l = layout::<Euclidean>(&d.mesh, &d.metric, None).unwrap();
        assert!(l.flipped_faces.is_empty());
        let g = deck_group::<Euclidean>(&l, &d.polygon).unwrap();
        let gens = g.named_generators();
        let sp = lattice_spectrum(gens[0].1.t, gens[1].1.t, count).unwrap();
        sp.iter().map(|x| x / sp[0]).collect()
    } else {
        let p = polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(s.edge_lengths()), &f)
            .unwrap();
        let d = cut_disk_polished(work, &p.metric, None, None, &mut NoProgress).unwrap();
        let l = layout_dd::<Hyperbolic>(&d.mesh, &d.metric, None).unwrap();
        assert!(l.flipped_faces.is_empty());
        let g = deck_group::<Hyperbolic>(&l, &d.polygon).unwrap();
        let sp = fuchsian_spectrum(&l, &d.polygon, &g, count, 2_000_000).unwrap();
        sp.lengths()
    }
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) / y).abs())
        .fold(0.0, f64::max)
}

/// The three triangulations of one surface agree to `tol` (relative, every length).
fn check_retriangulations(name: &str, s: &Surface, geometry: Geometry, count: usize, tol: f64) {
    let base = spectrum(s, geometry, count);
    let sub = spectrum(&midpoint_subdivision(s).unwrap(), geometry, count);
    let split = spectrum(&random_face_splits(s, 0.5, 11).unwrap(), geometry, count);
    let (e1, e2) = (max_rel(&sub, &base), max_rel(&split, &base));
    eprintln!("{name}: {base:.5?}\n  subdivided {e1:.2e}, split {e2:.2e}");
    assert!(
        e1 <= tol,
        "{name}: midpoint subdivision moves the spectrum by {e1:e}"
    );
    assert!(
        e2 <= tol,
        "{name}: random face splits move the spectrum by {e2:e}"
    );
}

#[test]
fn irregular_tori_match_the_closed_form() {
    for (big, small, n) in [(1.0f64, 0.25f64, 4000), (2.0, 1.0, 6000)] {
        let s = irregular_torus(big, small, n, 5).unwrap();
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
        let (re, im) = torus_modulus(gens[0].1.t, gens[1].1.t).unwrap();
        let want = (big * big - small * small).sqrt() / small;
        let got = if want >= 1.0 { im } else { 1.0 / im };
        eprintln!("irregular torus R={big} r={small}: τ = {re:.5} + {im:.5}i, want {want:.5}");
        assert!(re.abs() < 3e-3, "a rectangle: Re τ = {re}");
        assert!(
            ((got - want) / want).abs() <= 3e-3,
            "R={big} r={small}: modulus {got} vs closed form {want}"
        );
    }
}

#[test]
fn generated_surfaces_under_retriangulation() {
    let t = ricci::mesh::generate::torus(1.0, 0.45, 24).unwrap();
    check_retriangulations("torus 1/0.45", &t, Geometry::Euclidean, 4, 3e-3);
    let g = genus(2, 20).unwrap();
    check_retriangulations("genus2:20", &g, Geometry::Hyperbolic, 4, 3e-3);
}

#[test]
fn shared_meshes_under_retriangulation() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let read = |n: &str| ricci::mesh::io::read_surface(&dir.join(n)).unwrap().0;
    check_retriangulations(
        "bob_tri",
        &read("bob_tri.obj"),
        Geometry::Euclidean,
        4,
        3e-3,
    );
    check_retriangulations("eight", &read("eight.off"), Geometry::Hyperbolic, 4, 3e-3);
}

/// Issue 15's re-triangulations of three more shared meshes: kitten and rocker-arm (genus 1,
/// the normalized lattice lengths of the deck group, i.e. the modulus τ) and 3holes (genus 3,
/// hyperbolic geodesic lengths), each against its own 1-to-4 subdivision and off-centre splits.
#[test]
fn shared_meshes_kitten_rocker_arm_3holes_under_retriangulation() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let read = |n: &str| ricci::mesh::io::read_surface(&dir.join(n)).unwrap().0;
    check_retriangulations(
        "kitten",
        &read("kitten.nf20k.off"),
        Geometry::Euclidean,
        3,
        3e-3,
    );
    check_retriangulations(
        "rocker-arm",
        &read("rocker-arm.off"),
        Geometry::Euclidean,
        3,
        3e-3,
    );
    check_retriangulations("3holes", &read("3holes.off"), Geometry::Hyperbolic, 3, 3e-3);
}

/// 3holes' spectrum beyond paper 002 Table 3's first ten (Holes3 lists 4.699184 and 4.708807
/// as 11th and 12th — twice its first two — and nothing in between, where ours has one more
/// length near 3.64 and two near 4.14): the first 14 lengths are properties of the conformal
/// structure, not of the triangulation — they move by at most 0.3 % under 1-to-4 subdivision
/// and off-centre splits — and the multiples are there as closed forms: the 14th is twice the
/// first (the systole traversed twice), as the table's 11th is twice its first.
#[test]
fn holes3_lengths_past_table_3_persist_under_retriangulation() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join("3holes.off"))
        .unwrap()
        .0;
    let base = spectrum(&s, Geometry::Hyperbolic, 14);
    assert!(
        (base[13] - 2.0 * base[0]).abs() <= 1e-9 * base[0],
        "the 14th length is the doubled systole: {base:?}"
    );
    check_retriangulations("3holes (14)", &s, Geometry::Hyperbolic, 14, 3e-3);
}

/// torus.off (R = 1, r = 0.25, 1 200 vertices) is its own polyhedral surface: its modulus is
/// 3.8888, 0.41 % above the smooth torus's √15 = 3.8730 (issue 15's reference column). Refined
/// *onto the smooth torus* (1-to-4 midpoint subdivision, new vertices projected onto the tube)
/// the meshes approach the smooth surface and the default pipeline follows them to √15 at second
/// order (the error falls ≥ 3× per level, 0.1 % and 0.03 % after one and two levels); refined
/// *flat* (the same polyhedral surface) the modulus stays at torus.off's own value (≤ 0.05 %).
#[test]
fn torus_off_approaches_the_smooth_torus_only_when_refined_onto_it() {
    let Some(dir) = ricci_meshes::ricci_meshes().filter(|d| d.is_dir()) else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join("torus.off"))
        .unwrap()
        .0;
    let onto_tube = |s: &Surface| -> Surface {
        let mut t = midpoint_subdivision(s).unwrap();
        for p in &mut t.positions {
            let rho = p[0].hypot(p[1]);
            let c = [p[0] / rho, p[1] / rho, 0.0];
            let d = [p[0] - c[0], p[1] - c[1], p[2]];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            *p = [
                c[0] + 0.25 * d[0] / n,
                c[1] + 0.25 * d[1] / n,
                0.25 * d[2] / n,
            ];
        }
        t
    };
    let smooth = 15f64.sqrt();
    let modulus = |s: &Surface| spectrum(s, Geometry::Euclidean, 4)[3];
    let own = modulus(&s);
    assert!((own / smooth - 1.0) > 3e-3, "torus.off: {own}");
    let mut errors = vec![own / smooth - 1.0];
    let mut t = s.clone();
    for _ in 0..2 {
        t = onto_tube(&t);
        errors.push(modulus(&t) / smooth - 1.0);
    }
    for w in errors.windows(2) {
        assert!(w[1].abs() * 3.0 < w[0].abs(), "errors {errors:?}");
    }
    assert!(errors[2].abs() < 5e-4, "errors {errors:?}");
    let flat = modulus(&midpoint_subdivision(&s).unwrap());
    assert!((flat / own - 1.0).abs() < 5e-4, "flat {flat} vs {own}");
}
