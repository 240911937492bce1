//! The flow stage's errors with their data ([`FlowError`]): a flow that stopped above its
//! tolerance, a target that violates Gauss–Bonnet (paper 001 §IV), a target the Chow–Luo
//! condition refuses at a vertex or its one-ring (paper 000 eq. 7), a target curvature that
//! leaves a vertex no cone angle. Each converts into [`crate::Error::Stage`] with the same
//! sentence the flow always gave; [`crate::Error::stage_error`] gives the enum back, so a
//! caller can point at the vertex without parsing the message. (A face that violates the
//! triangle inequality is found by the metric stage: [`crate::metric::MetricError`].)

use std::fmt;

use super::FlowResult;
use crate::error::{Error, Kind, StageError};
use crate::metric::Geometry;

/// An error of the flow stage, with the vertex and the numbers it is about.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum FlowError {
    /// The flow stopped without a metric of the target curvature: max |K − K̄| reached
    /// (`max_error`) against `tolerance` after `iterations`, and the faces of the final metric
    /// that violate the triangle inequality (a curvature reached on them is not a metric).
    NotConverged {
        max_error: f64,
        tolerance: f64,
        iterations: usize,
        degenerate_faces: usize,
        /// Why the iteration stopped ([`FlowResult::stop_reason`]): the iteration budget, the
        /// line search, the flip budget, …
        reason: Option<String>,
    },
    /// Σ K̄ (`curvature_sum`) is not what Gauss–Bonnet asks of a metric of `geometry` on a
    /// surface of Euler characteristic `euler_characteristic` (E²: 2πχ; H² and S²: a positive
    /// area).
    GaussBonnet {
        geometry: Geometry,
        curvature_sum: f64,
        euler_characteristic: i64,
        message: String,
    },
    /// The Chow–Luo condition (paper 000 eq. 7) fails at `vertex` alone (`one_ring` false) or
    /// at its closed one-ring: Σ K̄ falls short of the bound by `shortfall`.
    ChowLuo {
        vertex: u32,
        one_ring: bool,
        shortfall: f64,
        message: String,
    },
    /// The target curvature `curvature` at `vertex` is not below `limit` (2π inside, π on the
    /// boundary): no cone angle is left.
    NoConeAngle {
        vertex: u32,
        curvature: f64,
        limit: f64,
    },
}

impl FlowError {
    /// Why `r` is not converged: the curvature error when that is the reason, otherwise the
    /// faces that violate the triangle inequality.
    pub fn not_converged(r: &FlowResult) -> Self {
        FlowError::NotConverged {
            max_error: r.max_curvature_error,
            tolerance: r.tolerance,
            iterations: r.iterations,
            degenerate_faces: r.degenerate_faces,
            reason: r.stop_reason.clone(),
        }
    }

    /// The vertex the error is about, if any.
    pub fn vertex(&self) -> Option<u32> {
        match self {
            FlowError::ChowLuo { vertex, .. } | FlowError::NoConeAngle { vertex, .. } => {
                Some(*vertex)
            }
            _ => None,
        }
    }
}

impl fmt::Display for FlowError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FlowError::NotConverged {
                max_error,
                tolerance,
                iterations,
                degenerate_faces,
                reason,
            } => {
                let reason = reason
                    .as_deref()
                    .map(|r| format!(": {r}"))
                    .unwrap_or_default();
                if max_error > tolerance {
                    write!(
                        f,
                        "the flow did not converge (max |K − K̄| = {max_error:.3e} > \
                         {tolerance:.1e} after {iterations} iterations){reason}"
                    )?;
                    if *degenerate_faces > 0 {
                        write!(
                            f,
                            "; {degenerate_faces} face(s) violate the triangle inequality in \
                             the final metric"
                        )?;
                    }
                    Ok(())
                } else if *degenerate_faces > 0 {
                    write!(
                        f,
                        "the flow did not converge: max |K − K̄| = {max_error:.3e} reached the \
                         tolerance, but {degenerate_faces} face(s) violate the triangle \
                         inequality in the final metric, so it is not a metric on this \
                         triangulation (try --scheme thurston, or --refine-degenerate N with \
                         --refined-out MESH)"
                    )
                } else {
                    write!(
                        f,
                        "the flow did not converge (max |K − K̄| = {max_error:.3e}, tolerance \
                         {tolerance:.1e}, {iterations} iterations){reason}"
                    )
                }
            }
            FlowError::GaussBonnet { message, .. } | FlowError::ChowLuo { message, .. } => {
                f.write_str(message)
            }
            FlowError::NoConeAngle {
                vertex,
                curvature,
                limit,
            } => write!(
                f,
                "target curvature {curvature:.6} at vertex {vertex} leaves no cone angle (it \
                 must be below {limit:.6})"
            ),
        }
    }
}

impl std::error::Error for FlowError {}

impl StageError for FlowError {
    fn kind(&self) -> Kind {
        match self {
            FlowError::NotConverged { .. } => Kind::Numerical,
            _ => Kind::InvalidInput,
        }
    }
}

impl From<FlowError> for Error {
    fn from(e: FlowError) -> Self {
        Error::stage(e)
    }
}
