//! The genus ≥ 2 surfaces of the T-spline tests and their holomorphic 1-forms, shared by the
//! test files (`mod ricci_meshes; mod tspline_cases;`): a generated genus-2 surface always,
//! eight.off when `$RICCI_MESHES` is set.

#![allow(dead_code)]

use ricci::analysis::forms::{holomorphic_forms, FormsOptions, HolomorphicForms};
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;

/// The holomorphic 1-forms of `s` (default options, the flat metric of its edge lengths).
pub fn forms(s: &Surface) -> HolomorphicForms {
    holomorphic_forms(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Some(&s.positions),
        &FormsOptions::default(),
        &mut NoProgress,
    )
    .unwrap()
}

/// `genus(2, 20)` and, with `$RICCI_MESHES`, eight.off (a note on stderr without it).
pub fn genus_two_cases() -> Vec<(&'static str, Surface)> {
    let mut cases = vec![("genus(2, 20)", ricci::mesh::generate::genus(2, 20).unwrap())];
    match super::ricci_meshes::ricci_meshes() {
        Some(dir) => cases.push((
            "eight",
            ricci::mesh::io::read_surface(&dir.join("eight.off"))
                .unwrap()
                .0,
        )),
        None => eprintln!("RICCI_MESHES is not set: skipping eight.off"),
    }
    cases
}

/// The domain manifold of `s` (its best genus domain, the strips glued) and its longest
/// circumference.
pub fn glued_domain(
    s: &Surface,
) -> (
    ricci::spline::tspline::genus_domain::GenusDomain,
    ricci::spline::tspline::glue::Gluing,
    f64,
) {
    let d = ricci::spline::tspline::genus_domain::best_genus_domain(&forms(s), s.positions.len())
        .unwrap();
    let g = ricci::spline::tspline::glue::gluing(&d).unwrap();
    let l = d
        .cylinders
        .iter()
        .map(|c| c.circumference)
        .fold(0.0, f64::max);
    (d, g, l)
}

/// The largest distance of the domain-mesh fit `f` of `d` — evaluated here from its Bézier
/// patches — to the input vertices `positions`.
pub fn max_vertex_error(
    d: &ricci::spline::tspline::genus_domain::GenusDomain,
    f: &ricci::spline::tspline::domain_fit::DomainFit,
    positions: &[[f64; 3]],
) -> f64 {
    let mut max = 0.0f64;
    for (p, &(c, a, b)) in d.points.iter().zip(&f.located) {
        let q = f.mesh.patch(c, &f.control, 0.0, 0.0);
        let x = q.point(q.u0 + a * (q.u1 - q.u0), q.v0 + b * (q.v1 - q.v0));
        let y = positions[p.vertex as usize];
        max = max.max((0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>().sqrt());
    }
    max
}

/// The domain-mesh fit of the vertices `positions` of `d` glued by `g` at `tolerance`, with the
/// default refinement (`blocks`) or the spacing refined everywhere instead of blocks.
pub fn fit_at(
    d: &ricci::spline::tspline::genus_domain::GenusDomain,
    g: &ricci::spline::tspline::glue::Gluing,
    positions: &[[f64; 3]],
    tolerance: f64,
    blocks: bool,
) -> ricci::spline::tspline::domain_fit::DomainFit {
    let opts = ricci::spline::tspline::domain_fit::DomainFitOptions {
        tolerance,
        blocks,
        ..Default::default()
    };
    ricci::spline::tspline::domain_fit::fit_domain_mesh(d, g, positions, &opts).unwrap()
}
