//! The cylinder decomposition of the domain manifold (paper 003 §2, genus ≥ 2; issue 18):
//! the holomorphic form with integer imaginary periods, its zeros (2g − 2), the bands between
//! critical levels and their cylinders. Checked against facts that do not come from the
//! decomposition: the imaginary periods (δ_kl on the loops), the number of zeros, the coarea
//! formula Σ L·H = ∫ du∧dv (the net's signed uv area, computed face by face), equal
//! circumferences of homologous level curves at two levels of each band, L > 0 (Re ω = |ω| > 0
//! along a horizontal trajectory), and the count of cylinders for genus 1 (one, no zeros).

mod ricci_meshes;
mod tspline_cases;

use ricci::analysis::forms::HolomorphicForms;
use ricci::spline::tspline::cylinders::{cylinders, integral_form, CylinderDecomposition};
use tspline_cases::{forms, genus_two_cases};

fn decompose(name: &str, h: &HolomorphicForms, class: usize) -> CylinderDecomposition {
    let (form, defect) = integral_form(h, class).unwrap();
    let d = cylinders(h, &form, class, defect).unwrap();
    eprintln!(
        "{name} class {class}: {} zeros, levels {:?}, {} cylinders {:?}, area {:.6} vs Σ L·H {:.6}",
        d.zeros.len(),
        d.levels,
        d.cylinders.len(),
        d.cylinders
            .iter()
            .map(|c| (c.band, c.height, c.circumference))
            .collect::<Vec<_>>(),
        d.area,
        d.cylinder_area
    );
    assert!(
        d.period_defect < 1e-9,
        "{name}: periods off by {}",
        d.period_defect
    );
    let rel = (d.cylinder_area - d.area).abs() / d.area.abs();
    assert!(
        rel < 1e-9,
        "{name}: Σ L·H differs from the net's area by {rel:e}"
    );
    for c in &d.cylinders {
        assert!(c.circumference > 0.0, "{name}: {c:?}");
        let r = (c.circumference - c.circumference_check).abs() / c.circumference;
        assert!(
            r < 1e-9,
            "{name}: circumference differs between levels: {c:?}"
        );
    }
    let heights: f64 = d
        .levels
        .iter()
        .enumerate()
        .map(|(i, _)| {
            d.cylinders
                .iter()
                .find(|c| c.band == i)
                .map_or(0.0, |c| c.height)
        })
        .sum();
    if !d.levels.is_empty() {
        assert!(
            (heights - 1.0).abs() < 1e-12,
            "{name}: band heights sum to {heights}"
        );
    }
    d
}

#[test]
fn genus_one_is_one_cylinder_without_zeros() {
    let s = ricci::mesh::generate::torus(1.0, 0.4, 32).unwrap();
    let h = forms(&s);
    for class in 0..2 {
        let d = decompose("torus", &h, class);
        assert!(d.zeros.is_empty() && d.levels.is_empty());
        assert_eq!(d.cylinders.len(), 1);
        assert_eq!(d.cylinders[0].height, 1.0);
    }
}

#[test]
fn genus_two_splits_into_cylinders_at_the_critical_trajectories() {
    for (name, s) in genus_two_cases() {
        let h = forms(&s);
        for class in 0..4 {
            let d = decompose(name, &h, class);
            let count: u32 = d.zeros.iter().map(|z| z.multiplicity).sum();
            assert_eq!(count, 2, "{name}: 2g − 2 = 2 zeros");
            // between 1 and g + #zeros − 1 = 3 cylinders
            assert!(
                (1..=3).contains(&d.cylinders.len()),
                "{name}: {} cylinders",
                d.cylinders.len()
            );
        }
    }
}
