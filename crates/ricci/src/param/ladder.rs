//! Flip-free charts (issue 16: "0 flipped faces, every time"): the chart asked for, and when
//! its map cannot be written without flipped triangles, the nearest one that can.
//!
//! A conformal map with cones is exact, but it is written in double precision: where its
//! scale factor `e^u` is tiny the UV triangles are below the rounding of the chart's
//! coordinates and fold. This happens when the requested cones cannot flatten the surface
//! without extreme scale factors — camel.off (genus 1, the tail's handle) flattened as a flat
//! torus (no cones, rigid seams) or with 3–4 cones and free seams has `σ(log area) ≈ 6–12`
//! and pieces near the tail shrunk by `e^{−30}` in length (area ratio `e^{−60}`), far below
//! `ε ≈ 2·10^{−16}` of a unit chart: no layout precision can write them. The
//! remedy is the one the cone literature gives (Ben-Chen–Gotsman–Bunin 2008 §4; Soliman–
//! Slepčev–Crane 2018 §1: more cones, less area distortion): the chart is recomputed
//!
//! 1. with rigid seams and the same cones (free homology seams are the extreme case:
//!    `u = 0` along a short homology cut forces the rest of the surface to balloon),
//! 2. then with one greedy cone more at a time, up to [`EXTRA_CONES`] more (on a torus with
//!    rigid seams one cone is no cone, Gauss–Bonnet, so that step is skipped),
//!
//! and the first map with no unresolved triangle is kept, with [`super::Chart::fallback`]
//! saying what was asked, what it gave and what was used. The same ladder runs when the
//! flow does not converge for the cones asked (camel, 5 rigid cones). Given cones
//! (`--cones V=K,…`) and charts with boundary are never changed — except that greedy cones
//! with the free boundary get the second step, more cones — and their map is returned as it
//! is (the CLI warns when it has flipped triangles). When no step gets to 0, the map with the
//! fewest flipped triangles is kept, and said so.

use super::chart::{chart_uv, ChartUv};
use super::{BoundaryMode, ConeSpec, ParamOptions, Piece, SeamMode};
use crate::error::{Kind, Result};
use crate::mesh::topology;
use crate::progress::Progress;

/// Most cones the ladder adds to the count of the chart asked for.
pub(super) const EXTRA_CONES: usize = 4;

/// Triangles whose UV triangle (`uv[3t + i]`) is folded, degenerate or so thin that moving
/// its corners by a few units of rounding of the chart's coordinates could fold it: twice
/// its signed area is at most `4 ε · E · L`, `E` the chart's size (the larger of its
/// bounding box's diagonal and its largest coordinate), `L` the triangle's longest edge
/// (moving the corners by `δ` changes twice the area by at most about `2δ` times the
/// perimeter). These are the triangles that packing and writing could fold.
pub(super) fn unresolved_triangles(triangles: &[[u32; 3]], uv: &[[f64; 2]]) -> usize {
    unresolved_flags(triangles, uv)
        .iter()
        .filter(|&&x| x)
        .count()
}

/// Per triangle: is it unresolved ([`unresolved_triangles`])?
pub(super) fn unresolved_flags(triangles: &[[u32; 3]], uv: &[[f64; 2]]) -> Vec<bool> {
    let tol = unresolved_tolerance(uv);
    (0..triangles.len())
        .map(|t| is_unresolved(&uv[3 * t..3 * t + 3], tol))
        .collect()
}

/// The rounding tolerance of [`unresolved_triangles`] for the UVs `uv`: `4ε` times their
/// size (bounding-box diagonal or largest coordinate).
pub(super) fn unresolved_tolerance(uv: &[[f64; 2]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut big = 0.0f64;
    for p in uv {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
            big = big.max(p[k].abs());
        }
    }
    let size = (hi[0] - lo[0]).hypot(hi[1] - lo[1]).max(big);
    4.0 * f64::EPSILON * size
}

/// Is the UV triangle `q` folded or within `tol` ([`unresolved_tolerance`]) of folding?
/// A triangle whose doubled area exceeds twice `tol` times its longest edge's `|Δu| + |Δv|`
/// (at least its length) is not, without the square roots.
pub(super) fn is_unresolved(q: &[[f64; 2]], tol: f64) -> bool {
    let a2 = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
    let taxicab = |i: usize, j: usize| (q[j][0] - q[i][0]).abs() + (q[j][1] - q[i][1]).abs();
    if a2 > 2.0 * tol * taxicab(0, 1).max(taxicab(1, 2)).max(taxicab(2, 0)) {
        return false;
    }
    let e = |i: usize, j: usize| (q[j][0] - q[i][0]).hypot(q[j][1] - q[i][1]);
    let longest = e(0, 1).max(e(1, 2)).max(e(2, 0));
    a2.is_nan() || a2 <= tol * longest
}

/// What a chart's options ask for, in words (`"free seams, 3 cones"`).
fn asked(opts: &ParamOptions, cones: Option<usize>) -> String {
    let seams = match opts.seams {
        SeamMode::Free => "free seams",
        SeamMode::Rigid => "rigid seams",
    };
    match cones {
        Some(k) => format!("{seams}, {k} cone(s)"),
        None => seams.to_string(),
    }
}

/// The chart of `piece` for `opts` ([`chart_uv`]), or the first step of the ladder (module
/// docs) whose map has no unresolved triangle.
pub(super) fn flip_free_chart(
    piece: &Piece,
    component: usize,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<ChartUv> {
    let first = chart_uv(piece, component, opts, progress);
    let problem = match &first {
        Ok(cu) if cu.flipped == 0 => return first,
        Ok(cu) => format!("{} flipped triangle(s)", cu.flipped),
        Err(e) if e.kind() == Some(Kind::Numerical) => {
            let e = e.to_string();
            let own = format!("component {component}: ");
            format!("no map ({})", e.strip_prefix(&own).unwrap_or(&e))
        }
        Err(_) => return first,
    };
    let mesh = &piece.surface.mesh;
    // With boundary only greedy cones with the free boundary are changed (more cones).
    let greedy_free = matches!(opts.cones, ConeSpec::Count(1..) | ConeSpec::Auto { .. })
        && opts.boundary == BoundaryMode::Free
        && !opts.seamless;
    if matches!(opts.cones, ConeSpec::Given(_)) || mesh.has_boundary() && !greedy_free {
        return first;
    }
    let genus = topology(mesh).components[0].genus;
    let count = match (&first, &opts.cones) {
        (Ok(cu), _) => cu.chart.cones.len(),
        (Err(_), ConeSpec::Count(k)) => *k,
        (Err(_), _) => 0,
    };
    let mut steps = Vec::new();
    if opts.seams == SeamMode::Free && genus >= 1 && !mesh.has_boundary() {
        steps.push(ParamOptions {
            seams: SeamMode::Rigid,
            ..opts.clone()
        });
    }
    for k in count + 1..=count + EXTRA_CONES {
        if k == 1 && genus == 1 && opts.seams == SeamMode::Rigid && !mesh.has_boundary() {
            continue;
        }
        steps.push(ParamOptions {
            cones: ConeSpec::Count(k),
            ..opts.clone()
        });
    }
    let requested = match &opts.cones {
        ConeSpec::Count(k) => Some(*k),
        _ => None,
    };
    let before = format!(
        "{} gave {problem}",
        asked(
            opts,
            first
                .as_ref()
                .ok()
                .map(|c| c.chart.cones.len())
                .or(requested)
        )
    );
    let mut best = first;
    for step in &steps {
        progress.report(
            "cones",
            None,
            &format!("{before}; trying {}", asked(step, None)),
        );
        let Ok(cu) = chart_uv(piece, component, step, progress) else {
            continue;
        };
        let better = match &best {
            Ok(b) => cu.flipped < b.flipped,
            Err(_) => true,
        };
        if better {
            let mut cu = cu;
            let used = asked(step, Some(cu.chart.cones.len()));
            cu.chart.fallback = Some(if cu.flipped == 0 {
                format!("{before}; used {used}, the first with no flipped triangle")
            } else {
                format!(
                    "{before}; no step of the ladder (rigid seams, up to {EXTRA_CONES} more \
                     cones) has none; used {used} with {} flipped triangle(s)",
                    cu.flipped
                )
            });
            let done = cu.flipped == 0;
            best = Ok(cu);
            if done {
                break;
            }
        }
    }
    best
}
