//! One chart of [`super::parametrize`]: the target curvature of a connected component (step
//! 1 of the [module docs](super)), the conformal flow with the optional cone-curvature
//! corrections (step 2), and the UVs through [`super::transfer`] (steps 3–5), on the input's
//! own faces when they do not fold, otherwise on the common subdivision of the input and the
//! flat triangulation.

use super::boundary::{cones_carrying_the_interior, fixed_angle_targets};
use super::cones::{
    correct_cone_curvatures, greedy_cones_with, round_to_quarter_turns, ConeBudget,
    CONE_SCALE_CEILING,
};
use super::develop::input_map;
use super::free::{free_seam_target, held_boundary_cones, homology_disk, HomologyDisk};
use super::ladder::unresolved_triangles;
use super::lscm::improve;
use super::transfer::{
    folded_faces, input_route, scale_to_area, seam_edges, seam_report, subdivision_route,
    SeamReport, SubdivisionChart,
};
use super::{log_scale_sigma, BoundaryMode, Chart, Cone, ConeSpec};
use super::{ParamOptions, Piece, SeamMode};
use crate::error::{Error, Result};
use crate::flow::{flow_with_fallback, FlowResult, TargetSpec, UniformizationOptions};
use crate::mesh::{topology, Mesh, Surface};
use crate::metric::{Geometry, IntrinsicMetric, Scheme};
use crate::progress::Progress;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::time::Instant;

/// The UVs of one chart: `corner_uv[3f + i]` per corner of the piece's faces, and — when the
/// input's faces fold — the common subdivision that carries the map instead.
pub(super) struct ChartUv {
    pub corner_uv: Vec<[f64; 2]>,
    pub cut: Vec<bool>,
    pub subdivision: Option<SubdivisionChart>,
    /// The subdivision's triangles as a mesh (built for the seam report; reused by
    /// [`super::parametrize`] when this is the only chart).
    pub subdivision_mesh: Option<Mesh>,
    pub chart: Chart,
    /// Written triangles (the subdivision's, else the input's faces) that fold or lie within
    /// rounding of folding ([`super::ladder::unresolved_triangles`]).
    pub flipped: usize,
}

/// Target curvature of a chart, with its cones, how they were chosen and the greedy's
/// distortion history.
struct ConePlan {
    target: TargetSpec,
    cones: Vec<(u32, f64)>,
    source: String,
    history: Vec<f64>,
}

/// Target of a chart with boundary: flat inside, or — with cones asked for (`--cones
/// N|auto|V=K,…`) — cones inside, given or placed and curved by the greedy with the boundary
/// held ([`held_boundary_cones`]: least-squares curvatures, the cones' linearised log scale
/// bounded above by [`CONE_SCALE_CEILING`]), and on the boundary the condition
/// of `opts` ([`super::boundary`]): `free` holds `u = 0`; `round` puts each loop on a circle
/// carrying `2πχ − Σ K̄` (genus 0: the longest loop `2π − Σ K̄`, holes `−2π`); `fixed-angles`
/// keeps the boundary's geodesic curvature, greedy cones moved to carry the interior's
/// curvature; `--seamless` rounds the cones and the boundary's turning to quarter turns.
fn boundary_target(
    piece: &Piece,
    component: usize,
    opts: &ParamOptions,
    lengths: &[f64],
    progress: &mut dyn Progress,
) -> Result<ConePlan> {
    let asks_cones = match &opts.cones {
        ConeSpec::Given(c) => c.iter().any(|x| piece.vertices.contains(&x.0)),
        ConeSpec::Count(k) => *k > 0,
        ConeSpec::Auto { .. } => true,
        ConeSpec::None | ConeSpec::Default => false,
    };
    let (mut cones, source, history) = if asks_cones {
        let on_boundary = |v: u32| {
            Error::input(format!(
                "cone vertex {v} lies on the boundary of component {component}; cones must be \
                 interior vertices (the boundary follows --boundary)"
            ))
        };
        let n = piece.vertices.len();
        let ceiling = Some(CONE_SCALE_CEILING);
        let (_, cones, source, history) =
            held_boundary_cones(piece, n, &opts.cones, opts, progress, &on_boundary, ceiling)?;
        (cones, source, history)
    } else {
        (Vec::new(), "none".to_string(), Vec::new())
    };
    let mesh = &piece.surface.mesh;
    let target = match (opts.boundary, opts.seamless) {
        (BoundaryMode::Free, false) if cones.is_empty() => TargetSpec::FreeBoundary,
        (BoundaryMode::Free, false) => TargetSpec::FreeBoundaryCones(cones.clone()),
        (BoundaryMode::Round, false) if cones.is_empty() => TargetSpec::RoundBoundary,
        // With cones summing beyond 2π (camelhead: 11.07 for 4 greedy cones) the loop turns
        // negatively: arcs of one radius curving away from the chart, still constant
        // geodesic curvature.
        (BoundaryMode::Round, false) => TargetSpec::RoundBoundaryCones(cones.clone()),
        (BoundaryMode::FixedAngles, _) | (_, true) => {
            if opts.boundary == BoundaryMode::FixedAngles && source == "greedy" {
                cones = cones_carrying_the_interior(mesh, lengths, &cones, component)?;
            }
            let (t, used) = fixed_angle_targets(mesh, lengths, &cones, opts.seamless)?;
            cones = used;
            TargetSpec::PerVertex(t)
        }
    };
    Ok(ConePlan {
        target,
        cones,
        source,
        history,
    })
}

fn closed_target(
    piece: &Piece,
    component: usize,
    genus: i64,
    opts: &ParamOptions,
    lengths: &[f64],
    progress: &mut dyn Progress,
) -> Result<ConePlan> {
    let mesh = &piece.surface.mesh;
    let chi = 2.0 - 2.0 * genus as f64;
    let spec = match &opts.cones {
        ConeSpec::Default if genus == 1 => ConeSpec::None,
        ConeSpec::Default => ConeSpec::Auto {
            max_area_distortion: 1.0,
        },
        c => c.clone(),
    };
    let (mut cones, mut source, mut history) = (Vec::new(), "none".to_string(), Vec::new());
    let budget = match spec {
        // Gauss–Bonnet: the curvatures sum to 4π on a sphere and each is below 2π.
        ConeSpec::Count(k @ 1..=2) if genus == 0 => {
            return Err(Error::input(format!(
                "component {component} (closed, genus 0) needs at least 3 cones to be flattened \
                 (their curvatures sum to 4π and each must stay below 2π); --cones {k} is too few \
                 (or use --sphere)"
            )));
        }
        ConeSpec::Count(k) => Some(ConeBudget::Count(k)),
        ConeSpec::Auto {
            max_area_distortion,
        } => Some(ConeBudget::AreaDistortion {
            bound: max_area_distortion,
            max_cones: opts.max_cones,
        }),
        ConeSpec::Given(c) => {
            // Checked here, by input vertex id: the flow would name the chart-local vertex.
            if let Some((v, k)) = c
                .iter()
                .find(|(v, k)| piece.vertices.contains(v) && (k.is_nan() || *k >= 2.0 * PI))
            {
                return Err(Error::input(format!(
                    "cone at vertex {v}: curvature {k:.6} leaves no cone angle (it must be \
                     below 2π = {:.6})",
                    2.0 * PI
                )));
            }
            let to_local: HashMap<u32, u32> = piece
                .vertices
                .iter()
                .enumerate()
                .map(|(i, &v)| (v, i as u32))
                .collect();
            cones = c
                .iter()
                .filter_map(|(v, k)| to_local.get(v).map(|&l| (l, *k)))
                .collect();
            source = "given".into();
            None
        }
        ConeSpec::None | ConeSpec::Default => None,
    };
    if let Some(b) = budget {
        progress.report("cones", None, "greedy cone placement");
        let p = greedy_cones_with(
            mesh,
            &IntrinsicMetric::euclidean(lengths.to_vec()),
            b,
            opts.cone_search,
        )?;
        cones = p.cones;
        history = p.distortion_history;
        source = "greedy".into();
    }
    if opts.seamless {
        cones = round_to_quarter_turns(&cones, 2.0 * PI * chi, 3);
    }
    if cones.is_empty() && genus != 1 {
        return Err(Error::input(format!(
            "component {component} (closed, genus {genus}) needs cones to be flattened \
             (--cones N, auto or V=K,…; or --sphere for genus 0)"
        )));
    }
    let target = if cones.is_empty() {
        TargetSpec::Uniform
    } else {
        TargetSpec::Cones(cones.clone())
    };
    Ok(ConePlan {
        target,
        cones,
        source,
        history,
    })
}

/// The flow that was kept: its result, cones, correction rounds run and flows run.
struct KeptFlow {
    r: FlowResult,
    cones: Vec<(u32, f64)>,
    corrections: usize,
    runs: usize,
}

fn flow_once(
    mesh: &Mesh,
    lengths: &[f64],
    target: TargetSpec,
    tolerance: f64,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    progress.report("flow", None, "conformal flow with intrinsic Delaunay flips");
    let fo = UniformizationOptions::single(Some(Geometry::Euclidean), Scheme::Conformal, tolerance)
        .with_target(target);
    let r = flow_with_fallback(mesh, lengths, &fo, None, progress)?.result;
    if !r.converged {
        return Err(Error::numerical(format!(
            "the conformal flow did not converge (max |K − K̄| = {:.3e} after {} iterations{})",
            r.max_curvature_error,
            r.iterations,
            if r.notes.is_empty() {
                String::new()
            } else {
                format!("; {}", r.notes.join("; "))
            }
        )));
    }
    Ok(r)
}

/// The conformal flow to `plan`'s target, then up to `opts.cone_corrections` rounds of
/// [`correct_cone_curvatures`] (greedy cones only), each kept only while the area-weighted
/// `σ(2u)` drops and the flow converges.
fn flow_with_corrections(
    piece: &Piece,
    component: usize,
    lengths: &[f64],
    plan: &ConePlan,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<KeptFlow> {
    let mesh = &piece.surface.mesh;
    let r = flow_once(mesh, lengths, plan.target.clone(), opts.tolerance, progress)
        .map_err(|e| Error::numerical(format!("component {component}: {e}")))?;
    let rounds = if plan.source == "greedy" && !opts.seamless && !mesh.has_boundary() {
        opts.cone_corrections
    } else {
        0
    };
    // Measured only when a correction round will compare with it.
    let mut sigma = if rounds > 0 {
        log_scale_sigma(&piece.surface, &r.u)
    } else {
        0.0
    };
    let mut kept = KeptFlow {
        r,
        cones: plan.cones.clone(),
        corrections: 0,
        runs: 1,
    };
    let metric = IntrinsicMetric::euclidean(lengths.to_vec());
    for _ in 0..rounds {
        progress.report("cones", None, "cone curvatures corrected on the flow");
        let Ok(next) = correct_cone_curvatures(mesh, &metric, &kept.cones, &kept.r.u, 1.0) else {
            break;
        };
        kept.runs += 1;
        let target = TargetSpec::Cones(next.clone());
        let Ok(r) = flow_once(mesh, lengths, target, opts.tolerance, progress) else {
            break;
        };
        let s = log_scale_sigma(&piece.surface, &r.u);
        if s >= sigma {
            break;
        }
        sigma = s;
        kept.r = r;
        kept.cones = next;
        kept.corrections += 1;
    }
    Ok(kept)
}

/// The target of a chart, and with free seams (closed, genus ≥ 1, `--seams free`) the disk
/// it is cut into along its homology generators ([`super::free`]).
fn open_and_plan(
    piece: &Piece,
    component: usize,
    genus: i64,
    boundary_loops: usize,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<(Option<HomologyDisk>, ConePlan)> {
    let lengths = piece.surface.edge_lengths();
    if boundary_loops > 0 {
        let plan = boundary_target(piece, component, opts, &lengths, progress)?;
        return Ok((None, plan));
    }
    if opts.seams != SeamMode::Free || genus == 0 {
        let plan = closed_target(piece, component, genus, opts, &lengths, progress)?;
        return Ok((None, plan));
    }
    if opts.seamless {
        return Err(Error::input(
            "--seamless needs rigid seams (free homology seams are not rotations by k·90°); \
             drop --seams free",
        ));
    }
    progress.report(
        "cut",
        None,
        "cut through the homology generators (free seams)",
    );
    let disk = homology_disk(piece, component)?;
    let (target, cones, source, history) =
        free_seam_target(&disk, component, genus, opts, progress)?;
    let plan = ConePlan {
        target,
        cones,
        source,
        history,
    };
    Ok((Some(disk), plan))
}

/// The cones `(piece vertex, curvature)` named by their input vertices, with their angles.
fn input_cones(work: &Piece, cones: &[(u32, f64)]) -> Vec<Cone> {
    cones
        .iter()
        .map(|&(v, k)| Cone {
            vertex: work.vertices[v as usize],
            curvature: k,
            angle: 2.0 * PI - k,
        })
        .collect()
}

/// The flow's target description (`cone:v=K,…`, `free-boundary+cone:…`, …: the flow's
/// [`TargetSpec`] written out) with its cones named by their **input** vertices, as the JSON's
/// `cones` and the `--cones V=K,…` option name them: the flow numbers the vertices of its own
/// mesh (the component, or the disk cut open along free seams). The list is `cones` itself —
/// the same curvatures in the same order; any other description is kept as it is.
fn input_target_description(description: &str, cones: &[Cone]) -> String {
    let Some((head, list)) = description.split_once("cone:") else {
        return description.to_string();
    };
    if list.split(',').count() != cones.len() {
        return description.to_string();
    }
    let named: Vec<String> = cones
        .iter()
        .map(|c| format!("{}={}", c.vertex, c.curvature))
        .collect();
    format!("{head}cone:{}", named.join(","))
}

/// Closed genus ≥ 1 with `--seamless`: the flow's result with the least change of log lengths
/// that makes the holonomy of the homology loops quarter turns too (`seamless`, CSZZ 2019).
fn seamless_result(
    kept: &KeptFlow,
    n_vertices: usize,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    let t_mesh = &kept
        .r
        .triangulation
        .as_ref()
        .ok_or_else(|| Error::numerical("the conformal flow returned no triangulation"))?
        .simplicial
        .mesh;
    let lengths = super::seamless::chart_holonomy(
        t_mesh,
        &kept.r.metric(),
        n_vertices,
        &kept.cones,
        progress,
    )?;
    Ok(FlowResult {
        lengths,
        ..kept.r.clone()
    })
}

/// UVs of one connected component (module docs, steps 1–5).
pub(super) fn chart_uv(
    piece: &Piece,
    component: usize,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<ChartUv> {
    let t0 = Instant::now();
    let topo = topology(&piece.surface.mesh);
    let comp = &topo.components[0];
    let (disk, plan) = open_and_plan(
        piece,
        component,
        comp.genus,
        comp.boundary_loops,
        opts,
        progress,
    )?;
    // With free seams the rest runs on the disk (same faces, seam vertices doubled).
    let work = disk.as_ref().map_or(piece, |d| &d.piece);
    let s = &work.surface;
    let mesh = &s.mesh;
    let lengths = s.edge_lengths();
    let kept = flow_with_corrections(work, component, &lengths, &plan, opts, progress)?;
    let seamless_metric;
    let r = if opts.seamless && comp.genus > 0 && comp.boundary_loops == 0 {
        seamless_metric = seamless_result(&kept, mesh.n_vertices(), progress)?;
        &seamless_metric
    } else {
        &kept.r
    };
    let cone_vertices: Vec<u32> = kept.cones.iter().map(|c| c.0).collect();
    let needs_cut =
        disk.is_none() && (comp.boundary_loops != 1 || comp.genus > 0) || !cone_vertices.is_empty();
    progress.report("cut", None, "cut graph through the cones and the handles");
    let faces = mesh.faces();
    let on_input = input_route(s, &lengths, r, &cone_vertices, needs_cut);
    let input_folds = match &on_input {
        Ok((_, uv)) => folded_faces(faces, uv),
        Err(_) => faces.len(),
    };
    let no_input_cut = on_input.is_err();
    let mut on_input = on_input;
    let mut lscm_refined = lscm_refinement(
        s,
        &cone_vertices,
        opts,
        &mut on_input,
        input_folds,
        progress,
    );
    let written_folds = if lscm_refined { 0 } else { input_folds };
    let (mut cut, mut corner_uv, mut subdivision) = match on_input {
        Ok((cut, uv)) if written_folds == 0 && !opts.on_subdivision => (cut, uv, None),
        first => {
            progress.report("layout", None, "UVs on the common subdivision");
            let sub = subdivision_route(s, &lengths, r, &cone_vertices, needs_cut);
            subdivision_unless_worse(sub, first, written_folds, component)?
        }
    };
    // On the subdivision because no cut on kept input edges reaches every cone: the same map
    // developed on the input faces along a cut on any input edges, refined until nothing
    // folds ([`super::develop`]).
    let mut input_folds = input_folds;
    if let Some(sub) = subdivision
        .as_ref()
        .filter(|_| no_input_cut && opts.lscm_refinement && !opts.on_subdivision)
    {
        progress.report("layout", None, "developed map on the input faces");
        if let Some((c, uv, folds)) =
            input_map(&s.positions, mesh, &lengths, &cone_vertices, needs_cut, sub)
        {
            (cut, corner_uv, subdivision) = (c, uv, None);
            (input_folds, lscm_refined) = (folds, true);
        }
    }
    let (seams, subdivision_mesh) = scaled_seams(
        &s.positions,
        mesh,
        &cut,
        &mut corner_uv,
        subdivision.as_mut(),
    )?;
    let tr = r
        .triangulation
        .as_ref()
        .ok_or_else(|| Error::numerical("the conformal flow returned no triangulation"))?;
    let cones = input_cones(work, &kept.cones);
    let chart = Chart {
        component,
        faces: mesh.n_faces(),
        vertices: piece.surface.mesh.n_vertices(),
        genus: comp.genus,
        boundary_loops: comp.boundary_loops,
        target: input_target_description(&r.target_description, &cones),
        seams: if disk.is_some() { "free" } else { "rigid" }.into(),
        cones,
        cone_source: plan.source,
        cone_distortion_history: plan.history,
        flow_iterations: r.iterations,
        flow_converged: r.converged,
        max_curvature_error: r.max_curvature_error,
        flips: tr.initial_flips + tr.flips,
        splits: tr.splits,
        uv_faces: if subdivision.is_some() {
            "common_subdivision".into()
        } else {
            "input".into()
        },
        input_flipped_faces: input_folds,
        lscm_refined,
        moved_cones: 0,
        seam_edges: seams.edges,
        seam_length: seams.length,
        seam_length_mismatch: seams.mismatch,
        transition_angles: seams.angles,
        quarter_turn_error: seams.quarter_turn_error,
        flow_seconds: r.seconds,
        flow_runs: kept.runs,
        cone_corrections: kept.corrections,
        log_scale_sigma: log_scale_sigma(s, &r.u),
        fallback: None,
        seconds: t0.elapsed().as_secs_f64(),
    };
    let flipped = match &subdivision {
        Some(sub) => unresolved_triangles(&sub.triangles, &sub.corner_uv),
        None => unresolved_triangles(faces, &corner_uv),
    };
    let cut = match &disk {
        Some(d) => d.lift_cut(piece, &cut),
        None => cut,
    };
    Ok(ChartUv {
        corner_uv,
        cut,
        subdivision,
        subdivision_mesh,
        chart,
        flipped,
    })
}

/// The cut of the input's edges, the corner UVs on the input faces (empty when the map is on
/// the common subdivision) and the common subdivision's map, if that is the one written.
type WrittenMap = (Vec<bool>, Vec<[f64; 2]>, Option<SubdivisionChart>);

/// The common subdivision's map `sub`, unless it folds more triangles than the input faces'
/// map `first` (which folds `written_folds`), or cannot be built while `first` can.
fn subdivision_unless_worse(
    sub: Result<SubdivisionChart>,
    first: Result<(Vec<bool>, Vec<[f64; 2]>)>,
    written_folds: usize,
    component: usize,
) -> Result<WrittenMap> {
    Ok(match (sub, first) {
        (Ok(sub), Ok((cut, uv))) if sub.flipped > written_folds => (cut, uv, None),
        (Ok(sub), _) => (sub.input_cut.clone(), Vec::new(), Some(sub)),
        (Err(_), Ok((cut, uv))) => (cut, uv, None),
        (Err(e), Err(first)) => {
            return Err(Error::numerical(format!(
                "component {component}: no cut on the input's edges ({first}), and none on \
                 the common subdivision ({e})"
            )));
        }
    })
}

/// The least-squares conformal map on the input faces, same cones and seam rotations
/// ([`super::lscm`]), in place of the exact map on the input route when it is kept (it may
/// unfold what the exact map folds); says whether it was.
fn lscm_refinement(
    s: &Surface,
    cone_vertices: &[u32],
    opts: &ParamOptions,
    on_input: &mut Result<(Vec<bool>, Vec<[f64; 2]>)>,
    input_folds: usize,
    progress: &mut dyn Progress,
) -> bool {
    let Ok((cut, uv)) = on_input.as_mut() else {
        return false;
    };
    if !opts.lscm_refinement || opts.on_subdivision {
        return false;
    }
    progress.report("layout", None, "least-squares conformal refinement");
    match improve(&s.positions, &s.mesh, cut, cone_vertices, uv, input_folds) {
        Some(better) => {
            *uv = better;
            true
        }
        None => false,
    }
}

/// Scales the written UVs to the surface's area and measures the seams: on the common
/// subdivision (whose mesh is returned for reuse; the input corners take its UVs) or on the
/// input faces cut along `cut`.
fn scaled_seams(
    positions: &[[f64; 3]],
    mesh: &Mesh,
    cut: &[bool],
    corner_uv: &mut Vec<[f64; 2]>,
    subdivision: Option<&mut SubdivisionChart>,
) -> Result<(SeamReport, Option<Mesh>)> {
    Ok(match subdivision {
        Some(sub) => {
            scale_to_area(&sub.positions, &sub.triangles, &mut sub.corner_uv);
            *corner_uv = input_corners_of(mesh, sub);
            let m = Mesh::from_triangles(sub.positions.len(), sub.triangles.clone())?;
            let seam = seam_edges(&m, &sub.corner_uv);
            (
                seam_report(&m, &sub.positions, &sub.corner_uv, &seam),
                Some(m),
            )
        }
        None => {
            scale_to_area(positions, mesh.faces(), corner_uv);
            (seam_report(mesh, positions, corner_uv, cut), None)
        }
    })
}

/// UV per corner of the input's faces from the common subdivision: the corner of the piece
/// at that input vertex inside that face (the map is exact at the input vertices; the input
/// face's own UV triangle may still fold).
fn input_corners_of(mesh: &Mesh, sub: &SubdivisionChart) -> Vec<[f64; 2]> {
    let mut uv = vec![[f64::NAN; 2]; mesh.n_corners()];
    for (t, tri) in sub.triangles.iter().enumerate() {
        let f = sub.input_face[t] as usize;
        let face = mesh.face(f as u32);
        for (c, &v) in tri.iter().enumerate() {
            if let Some(i) = face.iter().position(|&w| w == v) {
                uv[3 * f + i] = sub.corner_uv[3 * t + c];
            }
        }
    }
    uv
}
