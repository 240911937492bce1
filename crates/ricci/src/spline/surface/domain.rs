//! Step 1 of the manifold spline surface (paper 000 §4 Steps 1–3 as §5 uses them): the flat
//! domain — a flat metric with at most one cone and its [`LocalCharts`].

use std::time::Instant;

use crate::error::{Error, Result};
use crate::flow::{flow_with_fallback, TargetSpec, UniformizationOptions};
use crate::mesh::{topology, Surface};
use crate::metric::{Geometry, IntrinsicMetric, Scheme};
use crate::progress::Progress;
use crate::spline::manifold::LocalCharts;

/// Where the cone of a closed surface of genus ≥ 2 goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Singularity {
    /// Least area distortion, as the affine atlas chooses it
    /// ([`crate::atlas::placement::place`]: linearized flow for every vertex, the best
    /// confirmed by full flows).
    Auto,
    Vertex(u32),
}

/// A flat metric with at most one cone and its charts.
pub struct FlatDomain {
    pub charts: LocalCharts,
    pub genus: i64,
    pub boundary_loops: usize,
    /// The cone vertex (id in the refined domain = id in the input).
    pub singular: Option<u32>,
    /// Vertices added by the valence raising.
    pub added_vertices: usize,
    pub flow_iterations: usize,
    pub flow_max_curvature_error: f64,
    pub flow_converged: bool,
    /// The conformal scheme whose flow gave the metric.
    pub scheme: Scheme,
    pub seconds: f64,
}

/// Step 1 (module docs).
pub fn flat_domain(
    surface: &Surface,
    singularity: Singularity,
    progress: &mut dyn Progress,
) -> Result<FlatDomain> {
    let t0 = Instant::now();
    let mesh = &surface.mesh;
    let topo = topology(mesh);
    if topo.components.len() != 1 {
        return Err(Error::topology(format!(
            "manifold spline: the mesh has {} components; one is needed",
            topo.components.len()
        )));
    }
    let genus = topo.genus();
    let boundary_loops = topo.boundary_loops();
    let lengths = surface.edge_lengths();
    let (m, l, p, singular, target) = if boundary_loops > 0 {
        (
            mesh.clone(),
            lengths,
            surface.positions.clone(),
            None,
            TargetSpec::FreeBoundary,
        )
    } else if genus == 0 {
        return Err(Error::topology(
            "manifold spline: a closed genus-0 surface needs at least two cones; only genus ≥ 1 or open surfaces are supported",
        ));
    } else if genus == 1 {
        (
            mesh.clone(),
            lengths,
            surface.positions.clone(),
            None,
            TargetSpec::Uniform,
        )
    } else {
        let s = match singularity {
            Singularity::Vertex(v) => {
                if v as usize >= mesh.n_vertices() || mesh.is_isolated(v) {
                    return Err(Error::input(format!(
                        "singular vertex {v} does not exist (the mesh has {} vertices)",
                        mesh.n_vertices()
                    )));
                }
                v
            }
            Singularity::Auto => {
                progress.report("cone placement", None, "least area distortion");
                crate::atlas::placement::place(
                    surface,
                    &IntrinsicMetric::euclidean(lengths.clone()),
                    &crate::atlas::AtlasOptions::default(),
                    progress,
                )?
                .chosen
            }
        };
        let g = genus as usize;
        let want = (4 * g + 4).max(8 * g - 2);
        progress.report(
            "valence",
            None,
            &format!("raising the valence of {s} to {want}"),
        );
        // Raise the valence, then grade the neighbourhood (as the cut does) so that the rings
        // around the cone also pass the Chow–Luo check and the seam of the fill has room.
        let mean_spoke = mesh
            .outgoing(s)
            .map(|h| lengths[mesh.he_edge(h) as usize])
            .sum::<f64>()
            / mesh.valence(s).max(1) as f64;
        let mut rf = crate::metric::refine::Refiner::new(
            mesh,
            &lengths,
            Geometry::Euclidean,
            Some(&surface.positions),
        )?;
        rf.raise_valence(s, want)?;
        let theta = rf.cone_angle(s);
        let radius = 1.5 * want as f64 * mean_spoke / theta.max(1e-3);
        rf.grade_around(s, want, radius, 40 * want * want + 1000)?;
        let r = rf.finish()?;
        let pos = r.positions.unwrap_or_default();
        (
            r.mesh,
            r.lengths,
            pos,
            Some(s),
            TargetSpec::SingleCone(Some(s)),
        )
    };
    // The papers' schemes in turn (Thurston's packing first; where its clamped intersection
    // angles make the target unreachable — Chow–Luo at a low-valence vertex, e.g. rocker-arm —
    // or it does not converge, the exact schemes, which start at the input metric): the first
    // converged flow, else the first that ran.
    let papers = UniformizationOptions::papers(target);
    let ran = flow_with_fallback(&m, &l, &papers, None, progress)?;
    let (flow, scheme) = (ran.result, ran.scheme);
    if !flow.converged {
        return Err(Error::numerical(format!(
            "manifold spline: the Ricci flow did not converge (max |K − K̄| = {:.2e} after {} iterations)",
            flow.max_curvature_error, flow.iterations
        )));
    }
    let added = m.n_vertices() - mesh.n_vertices();
    let charts = LocalCharts::new(
        m,
        IntrinsicMetric::euclidean(flow.lengths.clone()),
        p,
        singular.into_iter().collect(),
        None,
    )?;
    Ok(FlatDomain {
        charts,
        genus,
        boundary_loops,
        singular,
        added_vertices: added,
        flow_iterations: flow.iterations,
        flow_max_curvature_error: flow.max_curvature_error,
        flow_converged: flow.converged,
        scheme,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
