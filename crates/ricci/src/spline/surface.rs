//! The manifold spline surface of a mesh, end to end (paper 000 §5, Table 1).
//!
//! 1. [`flat_domain`]: a flat metric with at most one cone — genus 1 closed: uniform E²;
//!    open surfaces: free boundary (all curvature on the boundary); closed genus `g ≥ 2`: the
//!    valence of the singular vertex is raised to `max(4g + 4, 8g − 2)` by metric-preserving
//!    link splits and its neighbourhood graded like the cut's base vertex (paper 000 Step 2;
//!    the Chow–Luo bound for one cone of `2πχ` needs valence `> 8g − 4`, and its rings need
//!    room too), then the flow puts `2πχ` on it. Its charts are the independent provider
//!    [`LocalCharts`] (the affine atlas plugs in through the same [`FlatCharts`] trait).
//! 2. [`build`]: initial control points from the degree-`n` subdivision of the domain, the
//!    fairing of paper 000 eq. 14 with parameter `r`, optionally a least-squares fit of the
//!    control points to the mesh vertices with the thin-plate fairness term
//!    ([`crate::spline::fit`]), and a G¹ fill patch at every cone ([`Hole`]).
//! 3. Measurements: [`continuity`] (jumps of all partials up to order `n` across every
//!    interior edge, the two one-sided limits evaluated in their own canonical charts and
//!    transformed into one), [`tessellate`] and [`MeshDistance`] (errors of spline samples
//!    against the input mesh as a percentage of the bounding-box diagonal).
//!
//! The tessellation is one welded, consistently oriented mesh, closed for a closed input: the
//! spline part is trimmed exactly at each seam (the crossings of the grid with the seam curve
//! are computed on the seam in (face, barycentric) coordinates through the hole's unrolled
//! cone coordinates) and the fill patch is triangulated on rings whose outer ring is exactly
//! those seam vertices, so there is no gap and no T-junction and vertex normals average
//! across the seam (`tests/spline_seam.rs`).

//!
//! The steps live in their own files: `surface/domain.rs` ([`flat_domain`]), this file
//! ([`build`], [`run`]), `surface/tessellate.rs` ([`tessellate`]) and `surface/measure.rs`
//! ([`continuity`], [`MeshDistance`]).

mod domain;
mod measure;
mod tessellate;

pub use domain::{flat_domain, FlatDomain, Singularity};
pub use measure::{
    continuity, error_percent, point_triangle_distance, ContinuityReport, MeshDistance,
};
pub use tessellate::{tessellate, SeamLoop, Tessellation, FILL_GRADING, FILL_GROWTH, SEAM_SNAP};

use std::time::Instant;

use crate::atlas::FlatCharts;
use crate::error::{Error, Result};
use crate::progress::Progress;

use super::dms::KnotOptions;
use super::fit::{fair, fit_with_progress, DataPoint, FairingReport, FitOptions, FitReport};
use super::hole::Hole;
use super::manifold::{ManifoldReport, ManifoldSpace};

/// Options of [`build`].
#[derive(Debug, Clone, Copy)]
pub struct SplineOptions {
    pub degree: usize,
    /// Fairness parameter `r`, `0 ≤ r ≤ n − 1` (paper 000 eq. 14).
    pub fairness: usize,
    /// Fit the control points to the mesh vertices after the fairing, with this thin-plate
    /// weight `λ` (`None`: no fit).
    pub fit_smoothing: Option<f64>,
    pub knots: KnotOptions,
}

impl Default for SplineOptions {
    fn default() -> Self {
        SplineOptions {
            degree: 3,
            fairness: 1,
            fit_smoothing: None,
            knots: KnotOptions::default(),
        }
    }
}

/// The spline: control points (3 per control point, all faces), the fill patches and what
/// the construction reported.
pub struct ManifoldSpline {
    pub control: Vec<f64>,
    pub holes: Vec<Hole>,
    pub fairing: FairingReport,
    pub fit: Option<FitReport>,
    /// Ridge weight the fit needed (1e-9 unless the normal matrix was too ill-conditioned).
    pub fit_ridge: Option<f64>,
    pub seconds_fairing: f64,
    pub seconds_fit: f64,
    pub seconds_fill: f64,
}

/// Step 2 (module docs).
pub fn build<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    opts: &SplineOptions,
    progress: &mut dyn Progress,
) -> Result<ManifoldSpline> {
    let c0 = space.subdivision_control_points();
    progress.report("fairing", None, &format!("r = {}", opts.fairness));
    let t = Instant::now();
    let (c1, fairing) = fair(space, &c0, 3, opts.fairness)?;
    let seconds_fairing = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut fit_ridge = None;
    let (control, fit_report) = if let Some(lam) = opts.fit_smoothing {
        progress.report("fit", None, "least squares to the mesh vertices");
        let charts = space.charts();
        let mesh = charts.mesh();
        let pos = charts.positions();
        let mut data = Vec::new();
        for v in 0..mesh.n_vertices() as u32 {
            if let Some(h) = mesh.vertex_corners(v).find(|&h| space.is_active(h / 3)) {
                let f = h / 3;
                data.push(DataPoint {
                    face: f,
                    param: space.canonical_coords(f)[h as usize % 3],
                    target: pos[v as usize].to_vec(),
                });
            }
        }
        // The normal matrix can be too ill-conditioned for the default ridge (1e-9 of the data
        // term); retry with a stronger ridge towards the faired control points.
        let mut result = None;
        let mut last = None;
        for ridge in [1e-9, 1e-7, 1e-5] {
            match fit_with_progress(
                space,
                &data,
                &c1,
                3,
                &FitOptions {
                    smoothing: lam,
                    ridge,
                },
                progress,
            ) {
                Ok(x) => {
                    result = Some((x, ridge));
                    break;
                }
                Err(e) => last = Some(e),
            }
        }
        let Some(((c, rep), ridge)) = result else {
            return Err(last.unwrap_or_else(|| Error::numerical("fit failed")));
        };
        fit_ridge = Some(ridge);
        (c, Some(rep))
    } else {
        (c1, None)
    };
    let seconds_fit = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut holes = Vec::new();
    for &s in space.charts().singular_vertices() {
        progress.report("fill", None, &format!("hole at vertex {s}"));
        holes.push(Hole::new(space, &control, s)?);
    }
    Ok(ManifoldSpline {
        control,
        holes,
        fairing,
        fit: fit_report,
        fit_ridge,
        seconds_fairing,
        seconds_fit,
        seconds_fill: t.elapsed().as_secs_f64(),
    })
}

/// Relative jump below which [`run`] counts an order of partials as continuous: the issue's
/// 1e-8 (with the double-double recurrence every mesh of the benchmark measures ≤ 3.7e-10 at
/// order `n − 1`; in double precision face.off reached 4.4e-8), while the order-`n` partials of
/// a degree-`n` spline jump by O(1).
pub const CONTINUITY_TOLERANCE: f64 = 1e-8;

/// Everything [`run`] measured, in the keys of the CLI's JSON.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SplineReport {
    pub degree: usize,
    pub fairness: usize,
    pub control_points: usize,
    pub domain_faces: usize,
    pub active_faces: usize,
    pub rms_error_percent: f64,
    pub max_error_percent: f64,
    /// Errors of the fill patches' samples alone.
    pub fill_max_error_percent: Option<f64>,
    pub continuity: ContinuityReport,
    pub space: ManifoldReport,
    pub fairing: FairingReport,
    pub fit: Option<FitReport>,
    pub fit_ridge: Option<f64>,
    pub seconds_knots: f64,
    pub seconds_fairing: f64,
    pub seconds_fit: f64,
    pub seconds_fill: f64,
    /// Spline construction (knots, bases, fairing, fit, fill), without measurements.
    pub seconds: f64,
}

/// Build the space, the spline, tessellate and measure (the CLI's work, minus files).
pub fn run<A: FlatCharts + Sync + ?Sized>(
    charts: &A,
    input: &MeshDistance,
    opts: &SplineOptions,
    tessellation: usize,
    progress: &mut dyn Progress,
) -> Result<(SplineReport, Tessellation, Vec<f64>)> {
    let t0 = Instant::now();
    progress.report("knots", None, "knot clouds and bases");
    let space = ManifoldSpace::new(charts, opts.degree, &opts.knots)?;
    let seconds_knots = t0.elapsed().as_secs_f64();
    let spline = build(&space, opts, progress)?;
    let seconds = t0.elapsed().as_secs_f64();
    progress.report("measure", None, "continuity, tessellation, errors");
    let cont = continuity(&space, &spline.control, &spline.holes, CONTINUITY_TOLERANCE)?;
    let tess = tessellate(&space, &spline, tessellation)?;
    let (rms, max) = error_percent(input, &tess.positions);
    let fill_pts: Vec<[f64; 3]> = tess
        .positions
        .iter()
        .zip(&tess.vertex_face)
        .filter(|(_, f)| **f < 0)
        .map(|(p, _)| *p)
        .collect();
    let fill_max = (!fill_pts.is_empty()).then(|| error_percent(input, &fill_pts).1);
    let rep = space.report();
    Ok((
        SplineReport {
            degree: opts.degree,
            fairness: opts.fairness,
            control_points: rep.control_points,
            domain_faces: charts.mesh().n_faces(),
            active_faces: rep.active_faces,
            rms_error_percent: rms,
            max_error_percent: max,
            fill_max_error_percent: fill_max,
            continuity: cont,
            space: rep,
            fairing: spline.fairing.clone(),
            fit: spline.fit.clone(),
            fit_ridge: spline.fit_ridge,
            seconds_knots,
            seconds_fairing: spline.seconds_fairing,
            seconds_fit: spline.seconds_fit,
            seconds_fill: spline.seconds_fill,
            seconds,
        },
        tess,
        spline.control,
    ))
}
