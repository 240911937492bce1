//! Length spectra of surfaces with exact metrics against closed forms.

use num_complex::Complex64 as C;
use ricci::analysis::spectrum::{fuchsian_spectrum, lattice_spectrum};
use ricci::layout::synthetic::{flat_torus, regular_polygon_surface, Gluing};
use ricci::layout::{deck_group, layout};
use ricci::metric::IntrinsicMetric;
use ricci::metric::{Euclidean, Geometry, Hyperbolic};

/// All lattice vectors up to sign with |m|, |n| ≤ 40, sorted: a brute-force reference.
fn brute_lattice(w1: C, w2: C, count: usize) -> Vec<f64> {
    let mut v = Vec::new();
    for n in 0..=40i64 {
        for m in -40..=40i64 {
            if n == 0 && m <= 0 {
                continue;
            }
            v.push((w1 * m as f64 + w2 * n as f64).norm());
        }
    }
    v.sort_by(f64::total_cmp);
    v.truncate(count);
    v
}

#[test]
fn torus_spectrum_from_layout_matches_the_lattice() {
    for (w1, w2) in [
        (C::new(1.0, 0.0), C::new(0.3, 1.7)),
        (C::new(2.0, 0.5), C::new(-3.1, 1.2)), // far from reduced
    ] {
        let s = flat_torus(w1, w2, 10, 10, 0.2, 3).unwrap();
        let l = layout::<Euclidean>(
            &s.cut,
            &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, s.cut_lengths.to_vec()),
            None,
        )
        .unwrap();
        let g = deck_group::<Euclidean>(&l, &s.polygon).unwrap();
        let gens = g.named_generators();
        let got = lattice_spectrum(gens[0].1.t, gens[1].1.t, 12).unwrap();
        let want = brute_lattice(w1, w2, 12);
        for (a, b) in got.iter().zip(&want) {
            assert!((a - b).abs() < 1e-10, "{got:?} vs {want:?}");
        }
        // Non-primitive classes are included: twice the shortest vector is there.
        assert!(got.iter().any(|x| (x - 2.0 * got[0]).abs() < 1e-10));
    }
}

/// Long thin tori: the enumeration's work follows the vectors it finds, not the square of
/// side l/|a| (τ = 10⁶ i took ~10¹³ steps — a hang — before). Closed form: when |b| is far
/// above count·|a|, the first `count` lengths are |a|, 2|a|, …; a moderately thin skewed torus
/// against the brute-force enumeration.
#[test]
fn thin_tori_spectrum_is_quick_and_exact() {
    let t0 = std::time::Instant::now();
    for (w1, w2) in [
        (C::new(1.0, 0.0), C::new(0.0, 1e6)),
        (C::new(0.0, 2.0), C::new(-3e5, 0.7)),
        (C::new(1.0, 0.0), C::new(0.5, 1e4)),
    ] {
        let got = lattice_spectrum(w1, w2, 20).unwrap();
        let a = w1.norm().min(w2.norm());
        for (k, x) in got.iter().enumerate() {
            let want = a * (k + 1) as f64;
            assert!((x - want).abs() < 1e-9 * want, "{w1} {w2}: {got:?}");
        }
    }
    let (w1, w2) = (C::new(1.0, 0.0), C::new(0.37, 6.5));
    let got = lattice_spectrum(w1, w2, 30).unwrap();
    let want = brute_lattice(w1, w2, 30);
    for (a, b) in got.iter().zip(&want) {
        assert!((a - b).abs() < 1e-12, "{got:?} vs {want:?}");
    }
    assert!(t0.elapsed().as_secs_f64() < 5.0, "{:?}", t0.elapsed());
}

#[test]
fn bolza_surface_has_twelve_systoles() {
    // The Bolza surface (regular octagon, angles π/4, opposite sides glued) has exactly 12
    // systoles, of length 2 acosh(1 + √2) (Schmutz Schaller 1993).
    let sys = 2.0 * (1.0 + 2f64.sqrt()).acosh();
    let mut spectra = Vec::new();
    for n in [3, 6] {
        let s = regular_polygon_surface(Geometry::Hyperbolic, 2, Gluing::Opposite, n).unwrap();
        let l = layout::<Hyperbolic>(
            &s.cut,
            &IntrinsicMetric::new(ricci::metric::Geometry::Hyperbolic, s.cut_lengths.to_vec()),
            None,
        )
        .unwrap();
        let g = deck_group::<Hyperbolic>(&l, &s.polygon).unwrap();
        let sp = fuchsian_spectrum(&l, &s.polygon, &g, 20, 200_000).unwrap();
        assert_eq!(sp.unmatched_links, 0);
        let len = sp.lengths();
        for x in &len[..12] {
            assert!((x - sys).abs() < 1e-8, "{len:?}");
        }
        assert!(len[12] > sys + 0.1, "{len:?}");
        spectra.push(len);
    }
    // Same surface, different triangulations: same spectrum.
    for (a, b) in spectra[0].iter().zip(&spectra[1]) {
        assert!((a - b).abs() < 1e-8);
    }
}
