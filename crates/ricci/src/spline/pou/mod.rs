//! Smooth surfaces over the hyperbolic structure: partition-of-unity splines without
//! extraordinary points (paper 004, completed after its §4.2 as its abstract describes).
//!
//! Every closed surface with χ < 0 carries a hyperbolic metric conformal to its own (hyperbolic
//! Ricci flow, paper 004 §3.5/§4.1); its charts in the Poincaré disk have Möbius transitions, so
//! functions of the hyperbolic distance are the same in every chart. Radial C∞ bumps on
//! hyperbolic disks around the vertices, normalized to a partition of unity, blend one control
//! point per vertex into a surface that is C∞ everywhere — no extraordinary point and no hole
//! to fill (compare [`crate::spline::surface`], whose manifold spline has one).
//!
//! * [`jet`] — truncated bivariate Taylor polynomials: exact partials by the chain rule;
//! * [`atlas`] — the hyperbolic atlas: uniformization, fundamental domain in double-double,
//!   Fuchsian side pairings, one chart per vertex developed over the universal cover, point
//!   location, SU(1,1) transitions; the double cover of surfaces with boundary;
//! * [`surface`] — radii, the bump `exp(1 − 1/(1 − τ))` of `τ = tanh²(d/2)/tanh²(r/2)`,
//!   weights, evaluation with partials up to order 3 (what we chose, and why, is documented
//!   there);
//! * [`local`] — local quadratic (or affine) approximants per basis, so the blend reproduces
//!   polynomials and its reflection lines follow the surface;
//! * [`fit`] — least squares on the vertices and face centres with a thin-plate fairness term,
//!   solved by faer's sparse Cholesky;
//! * [`measure`] — chart independence, jumps across chart boundaries, tessellation, and the
//!   end-to-end [`measure::run`].

pub mod atlas;
pub mod fit;
pub(crate) mod jet;
pub mod local;
pub mod measure;
pub mod surface;

pub use atlas::{double_cover, HyperbolicAtlas};
pub use measure::{run, PouOptions, PouReport};
pub use surface::{PouBasis, PouSurface};
