//! Uniformization: the flow to the metric of constant curvature that the surface's topology
//! calls for (paper 001 §V Step 3, paper 000 §4 Step 3; docs/DESIGN.md §3), with one options
//! type ([`UniformizationOptions`]: geometry, schemes tried in order, tolerance, iteration
//! limit, target policy) and one flow with a scheme fallback ([`flow_with_fallback`]).
//!
//! * Geometry ([`uniformization_geometry`]): S² for closed genus 0, E² for genus 1 and for
//!   disks, H² otherwise.
//! * Target ([`TargetPolicy::Topology`], [`topology_target`]): `uniform` for closed surfaces,
//!   `geodesic-boundary` for bordered surfaces in H², `free-boundary` otherwise.
//! * Tolerance of the layout pipeline ([`layout_tolerance`]): 1e-12 in H², 1e-10 in E² and
//!   S².
//! * Fallback: the schemes are tried in order until one converges. Which unconverged result
//!   is kept when none converges, and whether a refused target stops the search, are part of
//!   the options ([`Fallback`]), so that each caller keeps its behaviour.

use super::{ricci_flow, FlowOptions, FlowResult, TargetSpec};
use crate::error::{Error, Kind, Result};
use crate::mesh::{topology, Mesh};
use crate::metric::{Geometry, Scheme};
use crate::progress::Progress;

/// The geometry of the uniformization metric of a connected surface: S² for closed genus 0,
/// E² for genus 1 and for disks, H² otherwise.
pub fn uniformization_geometry(mesh: &Mesh) -> Result<Geometry> {
    let t = topology(mesh);
    if t.components.len() != 1 {
        return Err(Error::topology(format!(
            "the surface has {} components; lay out one at a time",
            t.components.len()
        )));
    }
    let c = &t.components[0];
    Ok(match (c.genus, c.boundary_loops) {
        (0, 0) => Geometry::Spherical,
        (0, 1) | (1, 0) => Geometry::Euclidean,
        _ => Geometry::Hyperbolic,
    })
}

/// The target that suits the topology in `geometry`: `uniform` for closed surfaces,
/// `geodesic-boundary` for bordered ones in H², `free-boundary` for bordered ones otherwise.
pub fn topology_target(mesh: &Mesh, geometry: Geometry) -> TargetSpec {
    match (geometry, mesh.has_boundary()) {
        (_, false) => TargetSpec::Uniform,
        (Geometry::Hyperbolic, true) => TargetSpec::GeodesicBoundary,
        (_, true) => TargetSpec::FreeBoundary,
    }
}

/// The tolerance of the layout pipeline (`ricci layout`): H² 1e-12 (Newton's last step then
/// lands near the double-precision floor ~5e-15; the deck group's accuracy is limited by this
/// residual times ~sinh of the polygon's size, e.g. genus3's relation error is 7e-7 at 3e-12
/// and 5e-10 at 5e-15); E² 1e-10, the bound of issue 15 (1e-12 stalls at rounding on some
/// 20k-face meshes, and camel.off's conformal flow stalls at 4.2e-11: the rounding of
/// `K = 2π − Σθ` on its tiny triangles; a flat metric's holonomy only scales this residual by
/// the size of the domain, so the deck group stays accurate); S² 1e-10 (the spherical angles
/// of horse's tiny triangles, legs shrunk ~1e-5 by the map, carry ~1e-11 of rounding).
pub fn layout_tolerance(geometry: Geometry) -> f64 {
    match geometry {
        Geometry::Hyperbolic => 1e-12,
        Geometry::Spherical | Geometry::Euclidean => 1e-10,
    }
}

/// The flow tolerance of the layout pipeline when the flow's hyperbolic metric is polished
/// to double-double afterwards (`ricci layout` without `--no-polish`, `ricci spectrum`): 1e-10
/// in H² (issue 15's convergence bound), else [`layout_tolerance`]. The polish
/// ([`super::polish`]) multiplies the residual by ~1e-16·cond(H) per step, so from 1e-10 it
/// reaches its 1e-26 in the same two steps as from 1e-12 — and a large mesh's flow cannot
/// resolve 1e-12 reliably: seahorse2_100K's conformal flow reaches 1.1e-11 at iteration 9,
/// then takes 18 steps of ~1e-13 at the rounding floor of `K = 2π − Σθ` (errors 1e-12 to
/// 9e-11) before one lands below 1e-12 by chance (two thirds of its Newton steps).
pub fn polished_layout_tolerance(geometry: Geometry) -> f64 {
    match geometry {
        Geometry::Hyperbolic => 1e-10,
        g => layout_tolerance(g),
    }
}

/// Where the target curvature comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum TargetPolicy {
    /// [`topology_target`].
    Topology,
    /// This target.
    Given(TargetSpec),
}

impl TargetPolicy {
    /// The target for `mesh` in `geometry`.
    pub fn resolve(&self, mesh: &Mesh, geometry: Geometry) -> TargetSpec {
        match self {
            TargetPolicy::Topology => topology_target(mesh, geometry),
            TargetPolicy::Given(t) => t.clone(),
        }
    }
}

/// What [`flow_with_fallback`] does when a scheme does not give a converged metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fallback {
    /// Keep the last unconverged result; an input refusal (kind `InvalidInput`: Gauss–Bonnet,
    /// Chow–Luo) of the first scheme ends the search (every scheme would refuse it). The
    /// atlas's flat metric ([`crate::atlas::flat_flow_limited`]).
    KeepLast,
    /// Keep the first unconverged result and try every scheme whatever the errors.
    KeepFirst,
}

/// Options of a uniformization flow.
#[derive(Debug, Clone)]
pub struct UniformizationOptions {
    /// The background geometry; `None`: [`uniformization_geometry`].
    pub geometry: Option<Geometry>,
    /// Schemes tried in order until one converges (at least one).
    pub schemes: Vec<Scheme>,
    /// Stop when max |K − K̄| ≤ tolerance.
    pub tolerance: f64,
    /// Newton iterations per scheme (`None`: [`ricci_flow`]'s default).
    pub max_iterations: Option<usize>,
    pub target: TargetPolicy,
    pub fallback: Fallback,
}

impl UniformizationOptions {
    /// One scheme, the topology's target, no fallback.
    pub fn single(geometry: Option<Geometry>, scheme: Scheme, tolerance: f64) -> Self {
        UniformizationOptions {
            geometry,
            schemes: vec![scheme],
            tolerance,
            max_iterations: None,
            target: TargetPolicy::Topology,
            fallback: Fallback::KeepLast,
        }
    }

    /// The atlas's flat metric: E², `scheme` then inversive distance and tangential circle
    /// packing (strong cones can break Thurston's clamped packing), at most `max_iterations`
    /// Newton iterations per scheme.
    pub fn flat(target: TargetSpec, scheme: Scheme, tolerance: f64, max_iterations: usize) -> Self {
        let mut schemes = vec![scheme];
        for s in [Scheme::Inversive, Scheme::Tangential] {
            if !schemes.contains(&s) {
                schemes.push(s);
            }
        }
        UniformizationOptions {
            geometry: Some(Geometry::Euclidean),
            schemes,
            tolerance,
            max_iterations: Some(max_iterations),
            target: TargetPolicy::Given(target),
            fallback: Fallback::KeepLast,
        }
    }

    /// The papers' schemes: Thurston's circle packing, then inversive distance, Yamabe and
    /// tangential packing, tolerance 1e-11, the geometry of `FlowOptions::default()` (E²).
    /// The manifold splines' flat cone metric.
    pub fn papers(target: TargetSpec) -> Self {
        UniformizationOptions {
            geometry: Some(FlowOptions::default().geometry),
            schemes: vec![
                Scheme::Thurston,
                Scheme::Inversive,
                Scheme::Yamabe,
                Scheme::Tangential,
            ],
            tolerance: 1e-11,
            max_iterations: None,
            target: TargetPolicy::Given(target),
            fallback: Fallback::KeepFirst,
        }
    }

    /// The same options with the target `target` (instead of the topology's).
    pub fn with_target(mut self, target: TargetSpec) -> Self {
        self.target = TargetPolicy::Given(target);
        self
    }

    /// The geometry for `mesh`.
    pub fn geometry_for(&self, mesh: &Mesh) -> Result<Geometry> {
        match self.geometry {
            Some(g) => Ok(g),
            None => uniformization_geometry(mesh),
        }
    }

    /// The [`FlowOptions`] of one scheme's run on `mesh` with at most `max_iterations`
    /// iterations (`None`: the options' own limit).
    pub fn flow_options(
        &self,
        mesh: &Mesh,
        scheme: Scheme,
        max_iterations: Option<usize>,
    ) -> Result<FlowOptions> {
        let geometry = self.geometry_for(mesh)?;
        Ok(FlowOptions {
            geometry,
            scheme,
            target: self.target.resolve(mesh, geometry),
            tolerance: self.tolerance,
            max_iterations: max_iterations.or(self.max_iterations),
            ..FlowOptions::default()
        })
    }
}

/// What [`flow_with_fallback`] produced.
#[derive(Debug, Clone)]
pub struct FallbackFlow {
    /// The converged flow, or the unconverged one [`Fallback`] keeps.
    pub result: FlowResult,
    /// The scheme of `result`.
    pub scheme: Scheme,
    /// Which schemes did not converge or failed, and the notes of `result`.
    pub notes: Vec<String>,
    /// Newton iterations of all the schemes tried together.
    pub iterations: usize,
    /// The smallest max |K − K̄| any scheme reached.
    pub best_error: f64,
}

/// The uniformization flow of `opts` on `mesh` with edge `lengths`, trying its schemes in
/// order until one converges. With a `budget`, every run gets at most the budget's
/// iterations, the iterations spent are subtracted, and no further scheme is tried once it
/// is 0. Errors: the first scheme's input refusal ([`Fallback::KeepLast`]), or the first
/// error when no scheme ran to the end.
pub fn flow_with_fallback(
    mesh: &Mesh,
    lengths: &[f64],
    opts: &UniformizationOptions,
    mut budget: Option<&mut usize>,
    progress: &mut dyn Progress,
) -> Result<FallbackFlow> {
    let mut notes = Vec::new();
    let mut kept: Option<(FlowResult, Scheme)> = None;
    let mut first_error = None;
    let mut iterations = 0;
    let mut best_error = f64::INFINITY;
    for (k, &s) in opts.schemes.iter().enumerate() {
        let limit = match budget.as_deref() {
            Some(&0) => {
                notes.push(format!(
                    "the iteration budget was spent before the {} scheme could run",
                    s.name()
                ));
                break;
            }
            Some(&b) => Some(opts.max_iterations.map_or(b, |m| m.min(b)).max(1)),
            None => None,
        };
        let run = ricci_flow(mesh, lengths, &opts.flow_options(mesh, s, limit)?, progress);
        if let (Ok(f), Some(b)) = (&run, budget.as_deref_mut()) {
            *b = b.saturating_sub(f.iterations.max(1));
        }
        match run {
            Ok(f) if f.converged => {
                if k > 0 {
                    notes.push(format!(
                        "the {} flow did not converge; the metric comes from the {} scheme",
                        opts.schemes[0].name(),
                        s.name()
                    ));
                }
                notes.extend(f.notes.iter().cloned());
                iterations += f.iterations;
                best_error = best_error.min(f.max_curvature_error);
                return Ok(FallbackFlow {
                    result: f,
                    scheme: s,
                    notes,
                    iterations,
                    best_error,
                });
            }
            Ok(f) => {
                notes.push(format!(
                    "{} flow: max |K − K̄| = {:.3e} after {} iterations (not converged)",
                    s.name(),
                    f.max_curvature_error,
                    f.iterations
                ));
                iterations += f.iterations;
                if f.max_curvature_error.is_finite() {
                    best_error = best_error.min(f.max_curvature_error);
                }
                if opts.fallback == Fallback::KeepLast || kept.is_none() {
                    kept = Some((f, s));
                }
            }
            Err(e) => {
                // A refused target (Gauss–Bonnet, Chow–Luo) is refused by every scheme.
                let refused = e.kind() == Some(Kind::InvalidInput);
                if k == 0 && refused && opts.fallback == Fallback::KeepLast {
                    return Err(e);
                }
                notes.push(format!("{} flow failed: {e}", s.name()));
                if first_error.is_none() {
                    first_error = Some(e);
                }
            }
        }
    }
    match (kept, first_error) {
        (Some((f, s)), _) => {
            notes.extend(f.notes.iter().cloned());
            Ok(FallbackFlow {
                result: f,
                scheme: s,
                notes,
                iterations,
                best_error,
            })
        }
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::numerical("no flow was run")),
    }
}
