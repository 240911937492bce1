//! Conformal invariants are invariants: length spectra of generated surfaces at three
//! resolutions agree, and the torus of revolution matches its closed form.

use num_complex::Complex64 as C;
use ricci::analysis::spectrum::{fuchsian_spectrum, lattice_spectrum};
use ricci::layout::deck_group;
use ricci::layout::pipeline::{cut_disk, uniformization_metric};
use ricci::layout::place::layout;
use ricci::mesh::generate;
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;

fn spectrum(s: &Surface, geometry: Geometry, scheme: Scheme, count: usize) -> Vec<f64> {
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        geometry,
        scheme,
        1e-11,
        &mut NoProgress,
    )
    .unwrap();
    assert!(flow.converged, "flow: {:e}", flow.max_curvature_error);
    let disk = cut_disk(
        &s.mesh,
        &IntrinsicMetric::new(geometry, flow.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    if geometry == Geometry::Euclidean {
        let l = layout::<Euclidean>(&disk.mesh, &disk.metric, None).unwrap();
        assert!(l.flipped_faces.is_empty());
        let g = deck_group::<Euclidean>(&l, &disk.polygon).unwrap();
        let gens = g.named_generators();
        let sp = lattice_spectrum(gens[0].1.t, gens[1].1.t, count).unwrap();
        sp.iter().map(|x| x / sp[0]).collect()
    } else {
        let l = layout::<Hyperbolic>(&disk.mesh, &disk.metric, None).unwrap();
        assert!(l.flipped_faces.is_empty());
        let g = deck_group::<Hyperbolic>(&l, &disk.polygon).unwrap();
        let sp = fuchsian_spectrum(&l, &disk.polygon, &g, count, 2_000_000).unwrap();
        assert_eq!(sp.unmatched_links, 0);
        sp.lengths()
    }
}

fn brute_lattice(w1: C, w2: C, count: usize) -> Vec<f64> {
    let mut v = Vec::new();
    for n in 0..=20i64 {
        for m in -20..=20i64 {
            if n == 0 && m <= 0 {
                continue;
            }
            v.push((w1 * m as f64 + w2 * n as f64).norm());
        }
    }
    v.sort_by(f64::total_cmp);
    v.truncate(count);
    let s = v[0];
    v.iter().map(|x| x / s).collect()
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) / y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn torus_of_revolution_matches_its_closed_form() {
    // Conformal to a rectangle with side ratio r/√(R² − r²).
    for (big, small) in [(2.0f64, 1.0f64), (3.0, 1.0)] {
        let ratio: f64 = small / (big * big - small * small).sqrt();
        let want = brute_lattice(C::new(1.0, 0.0), C::new(0.0, 1.0 / ratio), 8);
        let mut spectra = Vec::new();
        for res in [40, 56, 72] {
            let s = generate::torus(big, small, res).unwrap();
            let sp = spectrum(&s, Geometry::Euclidean, Scheme::Yamabe, 8);
            eprintln!("torus ({big}, {small}) res {res}: {sp:?} (closed form {want:?})");
            spectra.push(sp);
        }
        assert!(
            max_rel(&spectra[2], &want) < 5e-3,
            "{:?} vs {want:?}",
            spectra[2]
        );
        for s in &spectra {
            assert!(max_rel(s, &spectra[2]) < 5e-3);
        }
    }
}

#[test]
fn genus_two_spectrum_is_resolution_independent() {
    let mut spectra = Vec::new();
    for res in [40, 50, 60] {
        let s = generate::genus(2, res).unwrap();
        let sp = spectrum(&s, Geometry::Hyperbolic, Scheme::Yamabe, 8);
        eprintln!("genus 2 res {res} ({} faces): {sp:?}", s.mesh.n_faces());
        spectra.push(sp);
    }
    for s in &spectra[..2] {
        assert!(max_rel(s, &spectra[2]) < 5e-3, "{s:?} vs {:?}", spectra[2]);
    }
}

/// Two independent searches agree: the canonical polygon with its deck group
/// (`fuchsian_spectrum`) and the compact fundamental domain grown from a central vertex
/// (`surface_spectrum`, its own side pairings), on the same hyperbolic metric of a generated
/// genus-2 surface, to 1e-8 relative; the compact domain's radius is below the polygon's.
#[test]
fn compact_domain_spectrum_matches_the_canonical_polygon() {
    use ricci::analysis::spectrum::surface_spectrum;
    let s = generate::genus(2, 40).unwrap();
    let want = spectrum(&s, Geometry::Hyperbolic, Scheme::Yamabe, 10);
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Hyperbolic,
        Scheme::Yamabe,
        1e-11,
        &mut NoProgress,
    )
    .unwrap();
    let (sp, dom) = surface_spectrum(&s.mesh, &flow.metric(), None, 10, 2_000_000).unwrap();
    assert_eq!(sp.unmatched_links, 0);
    let got = sp.lengths();
    for (a, b) in got.iter().zip(&want) {
        assert!((a - b).abs() < 1e-8 * b, "{got:?} vs {want:?}");
    }
    assert!(dom.radius > 0.0 && dom.generators >= 4, "{dom:?}");
    // A budget too small is an error, not a hang.
    assert!(surface_spectrum(&s.mesh, &flow.metric(), None, 10, 50).is_err());
}
