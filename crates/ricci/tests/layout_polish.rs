//! The double-double metric polish (`ricci::flow::polish`) and its path through the cut and
//! the hyperbolic layout (`cut_disk_polished`, `layout_dd`), on generated surfaces (no
//! `RICCI_MESHES` needed).

use ricci::flow::polish::{curvature_dd, max_curvature_dd, polish_metric, PolishSettings};
use ricci::layout::deck_group;
use ricci::layout::pipeline::{
    cut_disk, cut_disk_polished, polish_uniformization, uniformization_metric,
};
use ricci::layout::place::{layout, layout_dd};
use ricci::mesh::generate;
use ricci::metric::{ConformalStructure, Evaluator, Geometry, Hyperbolic, IntrinsicMetric, Scheme};
use ricci::progress::NoProgress;

#[test]
fn double_double_curvature_agrees_with_the_flow_kernel_and_the_polish_converges() {
    let s = generate::genus(2, 16).unwrap();
    let input = s.edge_lengths();
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(input.to_vec()),
        Geometry::Hyperbolic,
        Scheme::Thurston,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    assert!(flow.converged);
    let structure = ConformalStructure::new(
        &s.mesh,
        &input,
        Geometry::Hyperbolic,
        Scheme::Thurston,
        flow.input_scale,
    )
    .unwrap();
    // Same u, two implementations: the double-precision kernel of the flow and the
    // double-double one of the polish (different length and angle code) must agree to the
    // kernel's rounding, at a point where K is not small (u moved off the solution).
    let u: Vec<f64> = flow
        .u
        .iter()
        .enumerate()
        .map(|(v, &x)| x + 2e-5 * (v as f64).sin())
        .collect();
    let mut ev = Evaluator::new(&s.mesh, structure.clone());
    assert!(ev.evaluate(&u));
    let kd = curvature_dd(&s.mesh, &structure, None, &u, &vec![0.0; u.len()]).unwrap();
    let kmax = ev.ws.curvature.iter().fold(0.0f64, |m, k| m.max(k.abs()));
    assert!(kmax > 1e-6, "the perturbation should change K ({kmax:e})");
    let diff = ev
        .ws
        .curvature
        .iter()
        .zip(&kd)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        diff < 1e-13,
        "f64 and double-double curvature differ by {diff:e}"
    );
    // Iterative refinement from the flow's u: the residual drops from the double-precision
    // floor to the double-double one in a few steps, and the metric hardly moves.
    let p =
        polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(input.to_vec()), &flow).unwrap();
    assert!(p.residual_start > 1e-17, "{:?}", p.history);
    assert!(p.converged && p.residual_dd <= 1e-26, "{:?}", p.history);
    assert!(p.steps <= 3, "{:?}", p.history);
    // Recomputed from the polished u by the same double-double evaluation (u_lo included).
    let k = curvature_dd(&s.mesh, &structure, None, &p.u, &p.u_lo).unwrap();
    assert!(k.iter().all(|x| x.abs() <= 1e-26));
    // Rounded to double precision, the polished u gives the flow kernel's lengths.
    let mut ev = Evaluator::new(&s.mesh, structure.clone());
    assert!(ev.evaluate(&p.u));
    for (e, (&a, &b)) in ev.ws.lengths.iter().zip(p.metric.lengths()).enumerate() {
        assert!((a - b).abs() <= 1e-15 * b, "edge {e}: {a} vs {b}");
    }
    // The vertex-scaling polish of the polished double-double lengths has nothing left to
    // do (its length law reproduces them through sinh/asinh).
    let q = ricci::layout::pipeline::polish_lengths(&s.mesh, &p.metric).unwrap();
    assert!(q.residual_start <= 1e-26, "{:?}", q.history);
}

#[test]
fn polished_metric_makes_deck_maps_from_different_edges_agree() {
    // The same surface cut and laid out with the flow's metric (double precision) and with
    // the polished one: the disagreement of the per-edge side maps, limited by the
    // metric's curvature error, must drop by orders of magnitude.
    let s = generate::genus(2, 16).unwrap();
    let input = s.edge_lengths();
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(input.to_vec()),
        Geometry::Hyperbolic,
        Scheme::Thurston,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    let plain = cut_disk(
        &s.mesh,
        &IntrinsicMetric::new(Geometry::Hyperbolic, flow.lengths.to_vec()),
        None,
        None,
        &mut NoProgress,
    )
    .unwrap();
    let lp = layout::<Hyperbolic>(&plain.mesh, &plain.metric, None).unwrap();
    let gp = deck_group::<Hyperbolic>(&lp, &plain.polygon).unwrap();
    let p =
        polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(input.to_vec()), &flow).unwrap();
    let disk = cut_disk_polished(&s.mesh, &p.metric, None, None, &mut NoProgress).unwrap();
    if let Some(r) = disk.refined_polish {
        assert!(r.converged, "{r:?}");
    }
    let l = layout_dd::<Hyperbolic>(&disk.mesh, &disk.metric, None).unwrap();
    let g = deck_group::<Hyperbolic>(&l, &disk.polygon).unwrap();
    eprintln!(
        "plain: relation {:e} spread {:e} / {:e}; polished: relation {:e} spread {:e} / {:e}",
        gp.relation_error.unwrap(),
        gp.max_edge_spread_matrix,
        gp.max_edge_spread,
        g.relation_error.unwrap(),
        g.max_edge_spread_matrix,
        g.max_edge_spread
    );
    assert!(l.flipped_faces.is_empty());
    assert!(g.relation_error.unwrap() < 1e-20);
    assert!(g.max_edge_spread_matrix < 1e-20 && g.max_edge_spread < 1e-20);
    assert!(g.max_edge_spread_matrix < 1e-4 * gp.max_edge_spread_matrix);
    // With zero low parts the double-double entry point is the plain layout.
    let zero_lo = IntrinsicMetric::with_low_parts(
        Geometry::Hyperbolic,
        plain.metric.to_vec(),
        vec![0.0; plain.metric.len()],
    )
    .unwrap();
    let z = layout_dd::<Hyperbolic>(&plain.mesh, &zero_lo, None).unwrap();
    assert_eq!(z.positions, lp.positions);
}

#[test]
fn polish_refuses_what_it_cannot_do() {
    let t = generate::torus(1.0, 0.4, 12).unwrap();
    let flow = uniformization_metric(
        &t.mesh,
        &IntrinsicMetric::euclidean(t.edge_lengths()),
        Geometry::Euclidean,
        Scheme::Thurston,
        1e-10,
        &mut NoProgress,
    )
    .unwrap();
    let e = polish_uniformization(
        &t.mesh,
        &IntrinsicMetric::euclidean(t.edge_lengths()),
        &flow,
    )
    .unwrap_err();
    assert!(e.to_string().contains("hyperbolic"), "{e}");
    // A nonzero target is refused, naming the vertex.
    let s = generate::genus(2, 12).unwrap();
    let st = ConformalStructure::new(
        &s.mesh,
        &s.edge_lengths(),
        Geometry::Hyperbolic,
        Scheme::Thurston,
        0.1,
    )
    .unwrap();
    let n = s.mesh.n_vertices();
    let mut target = vec![0.0; n];
    target[3] = 0.5;
    let e = polish_metric(
        &s.mesh,
        &st,
        None,
        &st.u0,
        &target,
        &vec![false; n],
        &PolishSettings::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("vertex 3"), "{e}");
}

#[test]
fn vertex_scaling_metrics_are_polished_too() {
    // The other H² length law: vertex scaling (sinh(l/2) = e^{(ui+uj)/2} sinh(l⁰/2)).
    let s = generate::genus(2, 12).unwrap();
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Geometry::Hyperbolic,
        Scheme::Yamabe,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    assert!(flow.converged);
    let p = polish_uniformization(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        &flow,
    )
    .unwrap();
    assert!(p.converged && p.residual_dd <= 1e-26, "{:?}", p.history);
    let moved = p
        .metric
        .iter()
        .zip(&flow.lengths)
        .map(|(a, b)| ((a - b) / b).abs())
        .fold(0.0, f64::max);
    assert!(moved < 1e-12, "{moved:e}");
}

#[test]
fn a_double_precision_uniform_metric_is_polished_once_on_the_refined_mesh() {
    // A double-precision metric passed straight to `cut_disk_polished` (one polish, on the
    // cut's refined mesh): the refined metric must reach double-double there, lay out with a
    // relation error at double-double level, and be the same hyperbolic metric as the one
    // polished first (on the edges both refined meshes keep from the flow's triangulation).
    let s = generate::genus(2, 16).unwrap();
    let input = s.edge_lengths();
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(input.to_vec()),
        Geometry::Hyperbolic,
        Scheme::Conformal,
        1e-12,
        &mut NoProgress,
    )
    .unwrap();
    let work = &flow.triangulation.as_ref().unwrap().simplicial.mesh;
    let once = cut_disk_polished(work, &flow.metric(), None, None, &mut NoProgress).unwrap();
    let r = once.refined_polish.expect("a double metric is polished");
    assert!(r.converged && r.residual_dd <= 1e-26, "{r:?}");
    assert!(r.residual_start > 1e-17, "{r:?}");
    let l = layout_dd::<Hyperbolic>(&once.mesh, &once.metric, None).unwrap();
    let g = deck_group::<Hyperbolic>(&l, &once.polygon).unwrap();
    assert!(l.flipped_faces.is_empty());
    assert!(g.relation_error.unwrap() < 1e-20, "{:?}", g.relation_error);
    assert!(g.max_edge_spread < 1e-20, "{}", g.max_edge_spread);
    let p =
        polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(input.to_vec()), &flow).unwrap();
    let twice = cut_disk_polished(work, &p.metric, None, None, &mut NoProgress).unwrap();
    // The polished metrics, by the refined-mesh vertices of their cut-mesh edges.
    let by_pair = |d: &ricci::layout::pipeline::CutDisk| {
        let mut m = std::collections::HashMap::new();
        for e in 0..d.mesh.n_edges() as u32 {
            let [a, b] = d.mesh.edge_vertices(e).map(|v| d.vertex_origin[v as usize]);
            m.insert((a.min(b), a.max(b)), d.metric[e as usize]);
        }
        m
    };
    let (ma, mb) = (by_pair(&once), by_pair(&twice));
    let nv0 = once.cut.refined.original_vertices as u32;
    let mut compared = 0;
    for (&(a, b), &x) in &ma {
        let Some(&y) = mb.get(&(a, b)) else { continue };
        if b >= nv0 {
            continue;
        }
        assert!((x - y).abs() <= 1e-13 * y, "edge {a}–{b}: {x} vs {y}");
        compared += 1;
    }
    assert!(compared > work.n_edges() / 2, "{compared} edges compared");
}

#[test]
fn the_cut_splits_a_polished_metric_in_double_double_and_it_stays_converged() {
    // Polished before the cut, the metric keeps its double-double accuracy through the cut's
    // splits (Stewart's theorem in double-double): the refined metric's curvature right after
    // the splits is at the polish's floor, so it is only checked, not polished (0 steps).
    // Split in double (the leading parts alone), the same refined metric is ~1e-16 off.
    let s = generate::genus(2, 16).unwrap();
    let input = s.edge_lengths();
    let flow = uniformization_metric(
        &s.mesh,
        &IntrinsicMetric::euclidean(input.to_vec()),
        Geometry::Hyperbolic,
        Scheme::Conformal,
        1e-10,
        &mut NoProgress,
    )
    .unwrap();
    let p =
        polish_uniformization(&s.mesh, &IntrinsicMetric::euclidean(input.to_vec()), &flow).unwrap();
    assert!(p.converged, "{:?}", p.history);
    let work = &flow.triangulation.as_ref().unwrap().simplicial.mesh;
    let disk = cut_disk_polished(work, &p.metric, None, None, &mut NoProgress).unwrap();
    let refined = &disk.cut.refined;
    assert!(refined.splits() > 0, "the cut should refine");
    let r = disk.refined_polish.expect("a refined metric is checked");
    assert!(
        r.residual_start <= 1e-20 && r.steps == 0 && r.converged,
        "{r:?}"
    );
    // The same curvature by the polish's vertex-scaling length law (another evaluation).
    let lo = refined.lengths_lo.clone().expect("low parts carried");
    let dd =
        IntrinsicMetric::with_low_parts(Geometry::Hyperbolic, refined.lengths.clone(), lo).unwrap();
    let q = ricci::layout::pipeline::polish_lengths(&refined.mesh, &dd).unwrap();
    assert!(q.residual_start <= 1e-20, "{:?}", q.history);
    let plain = IntrinsicMetric::new(Geometry::Hyperbolic, refined.lengths.clone());
    let k = max_curvature_dd(&refined.mesh, &plain).unwrap();
    assert!(k > 1e-19, "double-precision splits: {k:e}");
    // And the layout: relation and per-edge deck spread at the double-double level.
    let l = layout_dd::<Hyperbolic>(&disk.mesh, &disk.metric, None).unwrap();
    let g = deck_group::<Hyperbolic>(&l, &disk.polygon).unwrap();
    assert!(l.flipped_faces.is_empty());
    assert!(g.relation_error.unwrap() < 1e-20, "{:?}", g.relation_error);
    assert!(g.max_edge_spread < 1e-20, "{}", g.max_edge_spread);
}
