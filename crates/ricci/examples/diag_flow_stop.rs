//! How much the H² layout depends on where the flow stopped: the translation lengths of the
//! deck generators after the flow to 1e-12 and to 1e-10, by the two polish routes of the
//! layout pipeline — the flow variables polished to double-double before the cut
//! (`polish_uniformization`, the class fixed by the input) and the flow's double lengths
//! polished in place on the cut's refined mesh (the class of the rounded lengths; `ricci layout`
//! did this until session 13, and now polishes before the cut, docs/notes/wave2-s13-dd14.md).
//!
//! `cargo run --release -p ricci --example diag_flow_stop -- MESH`
use ricci::layout::pipeline::{cut_disk_polished, polish_uniformization, uniformization_metric};
use ricci::layout::{deck_group, layout_dd};
use ricci::metric::{Geometry, Hyperbolic, IntrinsicMetric, Scheme};
use ricci::progress::NoProgress;

/// Translation lengths of the deck generators and the relation error.
fn lengths(
    work: &ricci::mesh::Mesh,
    metric: &IntrinsicMetric,
    pos: Option<&[[f64; 3]]>,
) -> (Vec<f64>, f64) {
    let d = cut_disk_polished(work, metric, pos, None, &mut NoProgress).unwrap();
    let l = layout_dd::<Hyperbolic>(&d.mesh, &d.metric, None).unwrap();
    let g = deck_group::<Hyperbolic>(&l, &d.polygon).unwrap();
    let t = g
        .generators
        .iter()
        .map(|m| m.as_ref().map_or(f64::NAN, |m| m.translation_length()))
        .collect();
    (t, g.relation_error.unwrap_or(f64::NAN))
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / x.abs())
        .fold(0.0, f64::max)
}

fn main() {
    let path = std::env::args().nth(1).expect("mesh");
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(&path)).unwrap();
    let input = IntrinsicMetric::euclidean(s.edge_lengths());
    let mut deferred = Vec::new();
    let mut polished = Vec::new();
    for tol in [1e-12, 1e-10] {
        let f = uniformization_metric(
            &s.mesh,
            &input,
            Geometry::Hyperbolic,
            Scheme::Conformal,
            tol,
            &mut NoProgress,
        )
        .unwrap();
        let work = f
            .triangulation
            .as_ref()
            .map(|t| t.simplicial.mesh.clone())
            .unwrap_or(s.mesh.clone());
        let pos = f.triangulation.is_none().then_some(&s.positions[..]);
        let (a, ea) = lengths(
            &work,
            &IntrinsicMetric::new(Geometry::Hyperbolic, f.lengths.clone()),
            pos,
        );
        let p = polish_uniformization(&s.mesh, &input, &f).unwrap();
        let (b, eb) = lengths(&work, &p.metric, pos);
        println!(
            "flow to {tol:.0e}: {} it, max |K − K̄| {:.2e}; relation error deferred {ea:.1e}, \
             polished first {eb:.1e}; the two routes differ by {:.2e}",
            f.iterations,
            f.max_curvature_error,
            max_rel(&a, &b)
        );
        deferred.push(a);
        polished.push(b);
    }
    println!(
        "1e-12 vs 1e-10, largest relative difference of the {} translation lengths: \
         polish after the cut {:.2e}, polish before the cut {:.2e}",
        deferred[0].len(),
        max_rel(&deferred[0], &deferred[1]),
        max_rel(&polished[0], &polished[1])
    );
}
