//! Ricci flow with adaptive, metric-preserving refinement of the faces where the discrete
//! conformal metric does not exist on the given triangulation (docs/DESIGN.md §3; the splits of
//! [`crate::metric::refine`]).
//!
//! A discrete conformal class on a fixed triangulation can miss a target: with vertex scaling
//! the convex (extended) energy then has its minimum at a "metric" whose faces violate the
//! triangle inequality (paper 001 §IV admits the same for circle packings). A boundary that
//! zig-zags (turning angles of ±2 rad at neighbouring vertices, as on scanned disks) asks the
//! conformal factor to change by orders of magnitude within one ring, which a fixed coarse
//! triangulation cannot follow. Refinement resolves the factor: [`ricci_flow_refined`] runs
//! the flow, bisects (longest-edge bisection, [`Refiner::bisect`], in the *input* metric, so
//! the surface and its metric are unchanged and input vertices keep their ids and positions)
//! every face whose final metric is under-resolved — a triangle inequality fails, or a corner
//! angle is below [`MIN_ANGLE`] or above π − [`MAX_ANGLE_GAP`] — and flows again, until the
//! flow converges with no such face or the round limit is reached. The result says how many
//! rounds and splits it took; a flow that still fails is reported as not converged.

use super::{ricci_flow, FlowOptions, FlowResult};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::metric::refine::{Refined, Refiner};
use crate::metric::{Geometry, Scheme};
use crate::progress::Progress;
use std::f64::consts::PI;

/// Corner angles below this (radians) mark a face as under-resolved.
pub const MIN_ANGLE: f64 = 1e-3;
/// Corner angles above π minus this (radians) mark a face as under-resolved.
pub const MAX_ANGLE_GAP: f64 = 0.02;

/// Faces of `mesh` whose `lengths` (by edge id, in the background `geometry`) violate a
/// triangle inequality or have a corner angle below [`MIN_ANGLE`] or above
/// `π − MAX_ANGLE_GAP`.
pub fn under_resolved_faces(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> Vec<u32> {
    (0..mesh.n_faces() as u32)
        .filter(|&f| {
            let e = mesh.face_edges_opposite(f);
            let l = e.map(|e| lengths[e as usize]);
            if (0..3).any(|i| l[i] >= l[(i + 1) % 3] + l[(i + 2) % 3]) {
                return true;
            }
            (0..3).any(|i| {
                let a = geometry.angle(l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
                !(MIN_ANGLE..=PI - MAX_ANGLE_GAP).contains(&a)
            })
        })
        .collect()
}

/// Run [`ricci_flow`] on `refined` (Euclidean input lengths, any background geometry of
/// `options`; start with [`Refined::identity`] or the output of another refinement),
/// bisecting under-resolved faces and flowing again up to `max_rounds` times. Returns the
/// final refinement and the flow on it; the flow's notes say how many rounds and splits were
/// needed, `seconds` is the time of all rounds, and `converged` is true only if the last flow
/// converged with no under-resolved face (its `iterations` and `history` are those of the
/// last flow).
///
/// The faces to bisect come from the requested scheme's flow; when that flow is refused (a
/// circle packing failing Chow–Luo, whose intersection angles come from the triangulation)
/// or stops without a degenerate face, from a vertex-scaling flow with the same target (the
/// *probe*: its convex energy has its minimum at a degenerate metric exactly when no discrete
/// conformal metric exists on the triangulation). A refusal that persists after `max_rounds`
/// is returned as the error.
pub fn ricci_flow_refined(
    mut refined: Refined,
    options: &FlowOptions,
    max_rounds: usize,
    progress: &mut dyn Progress,
) -> Result<(Refined, FlowResult)> {
    let t0 = std::time::Instant::now();
    let splits0 = refined.splits();
    let mut round = 0;
    let mut probes = 0;
    let probe_options = FlowOptions {
        scheme: Scheme::Yamabe,
        ..options.clone()
    };
    loop {
        let attempt = ricci_flow(&refined.mesh, &refined.lengths, options, progress);
        let bad = match &attempt {
            // A conformal flow's lengths belong to its intrinsic triangulation, not to these
            // faces (read as the input's, they flagged thousands of faces and every round
            // doubled the mesh); its metric has no degenerate face.
            Ok(r) if r.triangulation.is_some() => Vec::new(),
            Ok(r) => under_resolved_faces(&refined.mesh, r.geometry, &r.lengths),
            Err(_) => Vec::new(),
        };
        let done = matches!(&attempt, Ok(r) if r.converged && bad.is_empty());
        if done || round >= max_rounds {
            let mut r = attempt?;
            let added = refined.splits() - splits0;
            if round > 0 {
                r.notes.push(format!(
                    "adaptive refinement: {round} round(s) of longest-edge bisection of the \
                     faces where the metric degenerated added {added} vertices ({} faces now; \
                     {probes} round(s) found the faces with a vertex-scaling probe); the last \
                     flow took {:.3} s, all rounds {:.3} s (`seconds`)",
                    refined.mesh.n_faces(),
                    r.seconds,
                    t0.elapsed().as_secs_f64()
                ));
            }
            r.seconds = t0.elapsed().as_secs_f64();
            if !bad.is_empty() {
                r.converged = false;
                r.notes.push(format!(
                    "{} faces are still under-resolved (triangle inequality violated, or an \
                     angle below {MIN_ANGLE} rad or above π − {MAX_ANGLE_GAP} rad) after \
                     {round} refinement round(s)",
                    bad.len()
                ));
            }
            return Ok((refined, r));
        }
        let bad = if bad.is_empty() && options.scheme != Scheme::Yamabe {
            probes += 1;
            match ricci_flow(&refined.mesh, &refined.lengths, &probe_options, progress) {
                Ok(p) => under_resolved_faces(&refined.mesh, p.geometry, &p.lengths),
                Err(_) => Vec::new(),
            }
        } else {
            bad
        };
        if bad.is_empty() {
            // Nothing to refine: report the flow as it is.
            let mut r = attempt?;
            r.seconds = t0.elapsed().as_secs_f64();
            r.notes.push(format!(
                "adaptive refinement stopped after {round} round(s): no degenerate face to \
                 bisect (neither in this flow nor in a vertex-scaling probe)"
            ));
            return Ok((refined, r));
        }
        round += 1;
        let mut rf = Refiner::resume(refined, Geometry::Euclidean)?;
        for f in bad {
            rf.bisect(f)?;
        }
        refined = rf.finish()?;
    }
}
