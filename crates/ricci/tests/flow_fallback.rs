//! Issue 22 item 2 ("when a scheme fails, nothing falls back"): [`flow_with_fallback`] tries
//! the next scheme when one fails. On the generated genus-2 surface a single cone carrying all
//! of 2πχ at a vertex of valence ≤ 12 is refused by Thurston's circle packing (Chow–Luo,
//! paper 000 eq. 7) and reached by vertex scaling with intrinsic flips (no such condition).

use ricci::flow::{
    flow_with_fallback, separated_vertices, Fallback, TargetPolicy, TargetSpec,
    UniformizationOptions,
};
use ricci::mesh::generate;
use ricci::metric::{self, Geometry, Scheme};
use ricci::progress::NoProgress;
use std::f64::consts::PI;

fn options(schemes: Vec<Scheme>, v: u32) -> UniformizationOptions {
    UniformizationOptions {
        geometry: Some(Geometry::Euclidean),
        schemes,
        tolerance: 1e-10,
        max_iterations: None,
        target: TargetPolicy::Given(TargetSpec::SingleCone(Some(v))),
        fallback: Fallback::KeepFirst,
    }
}

#[test]
fn a_refused_scheme_falls_back_to_the_next_one() {
    let s = generate::genus(2, 12).unwrap();
    let chi = metric::euler_characteristic(&s.mesh) as f64;
    let v = separated_vertices(&s.mesh, 1, 5)[0];
    let l = s.edge_lengths();
    // Thurston alone: refused (the precondition of this test).
    let alone = flow_with_fallback(
        &s.mesh,
        &l,
        &options(vec![Scheme::Thurston], v),
        None,
        &mut NoProgress,
    );
    assert!(
        alone.is_err(),
        "Thurston's packing was expected to refuse the single cone at vertex {v}"
    );
    // Thurston, then the conformal scheme: the second one's converged metric.
    let f = flow_with_fallback(
        &s.mesh,
        &l,
        &options(vec![Scheme::Thurston, Scheme::Conformal], v),
        None,
        &mut NoProgress,
    )
    .expect("the conformal scheme after Thurston's");
    assert_eq!(f.scheme, Scheme::Conformal);
    assert!(f.result.converged, "{:?}", f.notes);
    assert!(f.result.max_curvature_error <= 1e-10);
    assert!(
        f.notes.iter().any(|n| n.contains("thurston flow failed")),
        "the refusal is reported: {:?}",
        f.notes
    );
    // Gauss–Bonnet from the topology, not the flow: all of 2πχ at the cone, 0 elsewhere.
    let k = &f.result.curvature;
    assert!(
        (k[v as usize] - 2.0 * PI * chi).abs() < 1e-8,
        "K_v = {}",
        k[v as usize]
    );
    let elsewhere = k
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != v as usize)
        .map(|(_, x)| x.abs())
        .fold(0.0, f64::max);
    assert!(elsewhere < 1e-8, "max |K| elsewhere {elsewhere}");
}
