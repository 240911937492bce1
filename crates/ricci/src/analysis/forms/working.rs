//! The triangulation the 1-forms are computed on (paper 002 §4.2 works on the input mesh; the
//! cotangent weights are positive only on a Delaunay triangulation).
//!
//! * [`FormsTriangulation::Delaunay`] (default): the intrinsic Delaunay triangulation of the
//!   input metric — the same polyhedral surface (isometric flips), the one on which the
//!   discrete conformal class of the flow is defined, with non-negative cotangent weights.
//! * [`FormsTriangulation::Input`]: the input triangles with their own lengths (weights may be
//!   negative on obtuse meshes; the Laplacian stays positive semidefinite).
//! * [`FormsTriangulation::Flat`] (genus 1): the flat metric of the default conformal flow on
//!   its intrinsic Delaunay triangulation (`FlowResult::triangulation`); there the developing
//!   map is affine on every face and the holomorphic form is exactly `dz`.

use crate::error::{Error, Result};
use crate::flow::{flow_with_fallback, TargetSpec, UniformizationOptions};
use crate::mesh::{topology, Mesh, NONE};
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::metric::IntrinsicMetric;
use crate::metric::{Geometry, Scheme};
use crate::progress::Progress;
use serde::Serialize;

/// Which triangulation and metric the forms are computed on (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FormsTriangulation {
    #[default]
    Delaunay,
    Input,
    Flat,
}

impl FormsTriangulation {
    pub fn name(self) -> &'static str {
        match self {
            FormsTriangulation::Delaunay => "delaunay",
            FormsTriangulation::Input => "input",
            FormsTriangulation::Flat => "flat",
        }
    }
}

/// A closed triangle mesh with Euclidean edge lengths (and positions where they are known).
#[derive(Debug, Clone)]
pub struct WorkingSurface {
    pub kind: FormsTriangulation,
    pub mesh: Mesh,
    pub lengths: Vec<f64>,
    /// Input positions of the vertices (`None` when vertices were inserted).
    pub positions: Option<Vec<[f64; 3]>>,
    /// Intrinsic flips from the input triangulation.
    pub flips: usize,
    /// Curvature error of the flow (`Flat` only).
    pub flow_error: Option<f64>,
}

/// Build the working triangulation of a closed connected surface of genus ≥ 1.
pub fn working_surface(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    positions: Option<&[[f64; 3]]>,
    kind: FormsTriangulation,
    progress: &mut dyn Progress,
) -> Result<WorkingSurface> {
    let lengths = metric.lengths();
    let t = topology(mesh);
    if t.components.len() != 1 {
        return Err(Error::topology(format!(
            "holomorphic 1-forms need a connected surface; this mesh has {} components",
            t.components.len()
        )));
    }
    let c = &t.components[0];
    if c.boundary_loops > 0 {
        return Err(Error::topology(format!(
            "the surface has {} boundary loop(s); holomorphic 1-forms of bordered surfaces \
             (through the double cover) are not implemented",
            c.boundary_loops
        )));
    }
    if c.genus < 1 {
        return Err(Error::topology(
            "a closed genus-0 surface has no holomorphic 1-forms",
        ));
    }
    let pos_of = |origin: &[u32]| -> Option<Vec<[f64; 3]>> {
        let p = positions?;
        origin
            .iter()
            .map(|&o| (o != NONE).then(|| p[o as usize]))
            .collect()
    };
    match kind {
        FormsTriangulation::Input => Ok(WorkingSurface {
            kind,
            mesh: mesh.clone(),
            lengths: lengths.to_vec(),
            positions: positions.map(|p| p.to_vec()),
            flips: 0,
            flow_error: None,
        }),
        FormsTriangulation::Delaunay => {
            let mut tri = IntrinsicTriangulation::from_mesh(mesh, Geometry::Euclidean, lengths)?;
            let budget = 50 * mesh.n_edges() + 1000;
            let rep = tri.make_delaunay_isometric(Geometry::Euclidean, budget);
            if !rep.delaunay {
                return Err(Error::numerical(format!(
                    "the intrinsic Delaunay flips did not finish within {budget} flips"
                )));
            }
            let s = tri.to_simplicial(Geometry::Euclidean, &[])?;
            Ok(WorkingSurface {
                kind,
                positions: pos_of(&s.vertex_origin),
                mesh: s.mesh,
                lengths: s.lengths,
                flips: rep.flips,
                flow_error: None,
            })
        }
        FormsTriangulation::Flat => {
            if c.genus != 1 {
                return Err(Error::input(format!(
                    "the flat triangulation exists for genus 1 only; this surface has genus {}",
                    c.genus
                )));
            }
            let opts =
                UniformizationOptions::single(Some(Geometry::Euclidean), Scheme::Conformal, 1e-11)
                    .with_target(TargetSpec::Uniform);
            let f = flow_with_fallback(mesh, lengths, &opts, None, progress)?.result;
            if !f.converged {
                return Err(Error::numerical(format!(
                    "the flat metric did not converge (curvature error {:.1e})",
                    f.max_curvature_error
                )));
            }
            let tri = f.triangulation.as_ref().ok_or_else(|| {
                Error::numerical("the conformal flow returned no intrinsic triangulation")
            })?;
            Ok(WorkingSurface {
                kind,
                positions: pos_of(&tri.simplicial.vertex_origin),
                mesh: tri.simplicial.mesh.clone(),
                lengths: f.lengths.clone(),
                flips: tri.flips,
                flow_error: Some(f.max_curvature_error),
            })
        }
    }
}
