//! The atlas stage's errors with their data ([`AtlasError`]): a cone or singular vertex that
//! does not exist, lies on the boundary, is listed twice or is not wanted by the topology;
//! cone curvatures that break Gauss–Bonnet or leave no cone angle; a cone that cannot be
//! joined to the cut; a chart that does not develop into the plane; a single-cone flow that
//! did not converge. They convert into [`crate::Error::Stage`] with the same sentence as
//! before; [`crate::Error::stage_error`] gives the enum back.

use std::fmt;

use crate::error::{Error, Kind, StageError};

/// An error of the atlas stage, with the vertex or face it is about.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum AtlasError {
    /// The `role` ("cone" or "singular") vertex `vertex` is not below `n_vertices`.
    VertexMissing {
        role: &'static str,
        vertex: u32,
        n_vertices: usize,
    },
    /// The `role` vertex `vertex` lies on the boundary (cones must be interior).
    VertexOnBoundary { role: &'static str, vertex: u32 },
    /// Cone vertex `vertex` asks for `curvature` ≥ 2π (no positive cone angle), or a
    /// curvature that is not finite.
    NoConeAngle { vertex: u32, curvature: f64 },
    /// The cone curvatures sum to `sum`, not 2πχ with `euler_characteristic` χ.
    GaussBonnet { sum: f64, euler_characteristic: i64 },
    /// Cone vertex `vertex` appears twice in the list.
    ConeListedTwice { vertex: u32 },
    /// A singular vertex was given for a surface whose flat metric has none: an open surface
    /// (`genus_one == false`) or a closed genus-1 surface (`genus_one == true`).
    SingularVertexNotNeeded { vertex: u32, genus_one: bool },
    /// Cone vertex `vertex` cannot be joined to the cut graph.
    ConeNotJoined { vertex: u32 },
    /// The neighbourhood of face `face` does not develop consistently into the plane (a chart
    /// that does not close).
    ChartNotFlat { face: u32 },
    /// The single-cone flow at vertex `vertex` did not converge, for `reason`.
    SingleConeNotConverged { vertex: u32, reason: String },
}

impl AtlasError {
    /// The vertex the error is about, if it names one.
    pub fn vertex(&self) -> Option<u32> {
        match self {
            AtlasError::VertexMissing { vertex, .. }
            | AtlasError::VertexOnBoundary { vertex, .. }
            | AtlasError::NoConeAngle { vertex, .. }
            | AtlasError::ConeListedTwice { vertex }
            | AtlasError::SingularVertexNotNeeded { vertex, .. }
            | AtlasError::ConeNotJoined { vertex }
            | AtlasError::SingleConeNotConverged { vertex, .. } => Some(*vertex),
            AtlasError::GaussBonnet { .. } | AtlasError::ChartNotFlat { .. } => None,
        }
    }
}

impl fmt::Display for AtlasError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use std::f64::consts::PI;
        match self {
            AtlasError::VertexMissing {
                role,
                vertex,
                n_vertices,
            } => write!(
                f,
                "{role} vertex {vertex} does not exist (the mesh has {n_vertices} vertices)"
            ),
            AtlasError::VertexOnBoundary { role, vertex } => write!(
                f,
                "{role} vertex {vertex} lies on the boundary; cones must be interior vertices"
            ),
            AtlasError::NoConeAngle { vertex, curvature } => write!(
                f,
                "cone vertex {vertex} asks for curvature {curvature:.6}; a cone angle 2π − K̄ \
                 must be positive, so K̄ < 2π"
            ),
            AtlasError::GaussBonnet {
                sum,
                euler_characteristic: chi,
            } => write!(
                f,
                "the cone curvatures sum to {sum:.6} but Gauss–Bonnet needs 2πχ = {:.6} \
                 (χ = {chi}); off by {:.3e}",
                2.0 * PI * *chi as f64,
                sum - 2.0 * PI * *chi as f64
            ),
            AtlasError::ConeListedTwice { vertex } => {
                write!(f, "cone vertex {vertex} is listed twice")
            }
            AtlasError::SingularVertexNotNeeded {
                vertex,
                genus_one: false,
            } => write!(
                f,
                "an open surface needs no singular vertex (its curvature goes to the \
                 boundary), but vertex {vertex} was given"
            ),
            AtlasError::SingularVertexNotNeeded {
                vertex,
                genus_one: true,
            } => write!(
                f,
                "a closed genus-1 surface has a flat metric without singular points, but \
                 vertex {vertex} was given"
            ),
            AtlasError::ConeNotJoined { vertex } => {
                write!(f, "cone vertex {vertex} cannot be joined to the cut graph")
            }
            AtlasError::ChartNotFlat { face } => write!(
                f,
                "face {face}: its neighbourhood does not develop consistently into the plane \
                 (is the metric flat there?)"
            ),
            AtlasError::SingleConeNotConverged { vertex, reason } => write!(
                f,
                "the single-cone flow at vertex {vertex} did not converge ({reason})"
            ),
        }
    }
}

impl std::error::Error for AtlasError {}

impl StageError for AtlasError {
    fn kind(&self) -> Kind {
        match self {
            AtlasError::ConeNotJoined { .. } => Kind::Topology,
            AtlasError::ChartNotFlat { .. } | AtlasError::SingleConeNotConverged { .. } => {
                Kind::Numerical
            }
            _ => Kind::InvalidInput,
        }
    }
}

impl From<AtlasError> for Error {
    fn from(e: AtlasError) -> Self {
        Error::stage(e)
    }
}
