//! Cone placement on a closed surface, on the Green's functions of the sibling module `green`:
//!
//! 1. **Greedy** (Ben-Chen–Gotsman–Bunin 2008 §4; Boundary First Flattening's CETM strategy,
//!    Sawhney–Crane 2017 §6.2): the first cone at the vertex of most negative angle defect
//!    when `χ < 0` (most positive when `χ > 0`), then repeatedly at the vertex where the
//!    Dirichlet solution (`u = 0` at the cones) has the largest `|u|`. The greedy is run from
//!    two first cones — BFF's, and the extremum of the smooth solution `w₀` (the total
//!    curvature spread by area) — and the set with the smaller area-weighted `σ(2u)` is kept.
//!
//!    1b. Only with the wide search ([`super::ConeSearch::Energy`], opt-in) and a cone
//!    count (not a distortion bound), also the **greedy on the energy**
//!    from the same two first cones: each new cone is the best, by the energy below, of a
//!    few candidates — the extremes of the adjoint `φ = L⁺M(u − ū)` of the least-squares
//!    field (`φ_v − λ` is the derivative of the energy with respect to curvature moved to
//!    `v`; Soliman–Slepčev–Crane 2018 §4), its largest `|u|`, and the Dirichlet greedy's
//!    vertex. The set of least energy among all runs is kept.
//! 2. **Cone moves** (a Lloyd-type local search): each cone in turn is taken out and put
//!    back at the largest `|u|` of the others' Dirichlet solution (with the wide search: at
//!    the best of step 1b's candidates) when that lowers the energy below; rounds until
//!    nothing moves (at most [`MOVE_ROUNDS`]).
//! 3. **Curvatures** of least area-weighted `‖u − ū‖²` at the final positions
//!    (Soliman–Slepčev–Crane 2018 with the positions fixed), not the Dirichlet ones: on
//!    botijo with 8 cones the linearised `σ(2u)` drops from 1.41 to 1.21.
//!
//! The energy that ranks the two greedy runs and the moves is the `σ(2u)` of step 3's `u`.
//!
//! Every step costs triangular solves with one factorization (one per new cone vertex).

use super::green::GreenBasis;
use super::{ConeBudget, ConePlacement};
use crate::error::Result;

/// Rounds of cone moves (step 2 of the module docs).
pub(super) const MOVE_ROUNDS: usize = 4;

/// The non-cone vertex of largest `|u|` (`used` only).
fn farthest(u: &[f64], cones: &[u32], used: &[bool]) -> Option<u32> {
    (0..u.len())
        .filter(|&v| used[v] && !cones.contains(&(v as u32)))
        .max_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs()))
        .map(|v| v as u32)
}

/// Linearised `max |2u − mean(2u)|` (the `--max-area-distortion` measure).
fn spread(g: &GreenBasis, u: &[f64], used: &[bool]) -> f64 {
    let m = g.mean(u);
    (0..u.len())
        .filter(|&v| used[v])
        .map(|v| (2.0 * (u[v] - m)).abs())
        .fold(0.0, f64::max)
}

/// Area-weighted `σ(2u)` of the least-squares curvatures at `cones` (step 3).
fn energy(g: &mut GreenBasis, cones: &[u32]) -> Result<f64> {
    g.least_squares_sigma(cones)
}

/// The greedy from `first` (step 1), with its spread history.
fn greedy_from(
    g: &mut GreenBasis,
    first: u32,
    used: &[bool],
    max_cones: usize,
    bound: f64,
) -> Result<(Vec<u32>, Vec<f64>)> {
    let mut cones = vec![first];
    let (_, mut u) = g.dirichlet(&cones)?;
    let mut history = vec![spread(g, &u, used)];
    while cones.len() < max_cones {
        if bound >= 0.0 && spread(g, &u, used) <= bound {
            break;
        }
        let Some(c) = farthest(&u, &cones, used) else {
            break;
        };
        cones.push(c);
        u = g.dirichlet(&cones)?.1;
        history.push(spread(g, &u, used));
    }
    Ok((cones, history))
}

/// Where one more cone may go, given `cones` (step 1b of the module docs): the extremes of
/// the adjoint `φ − λ` of the least-squares field (the first-order best places for positive
/// and for negative curvature), the largest `|u|` of that field, and the largest `|u|` of the
/// Dirichlet field (the classic greedy's choice). Deduplicated.
fn candidates(g: &mut GreenBasis, cones: &[u32], used: &[bool], wide: bool) -> Result<Vec<u32>> {
    if !wide {
        // The classic move: the largest |u| of the Dirichlet field only.
        let (_, ud) = g.dirichlet(cones)?;
        return Ok(farthest(&ud, cones, used).into_iter().collect());
    }
    let (_, u) = g.least_squares(cones)?;
    let phi = g.adjoint(&u);
    let lambda = cones.iter().map(|&c| phi[c as usize]).sum::<f64>() / cones.len() as f64;
    let free = |v: &usize| used[*v] && !cones.contains(&(*v as u32));
    let d: Vec<f64> = phi.iter().map(|x| x - lambda).collect();
    let mut out = Vec::new();
    out.extend(
        (0..d.len())
            .filter(free)
            .max_by(|&a, &b| d[a].total_cmp(&d[b])),
    );
    out.extend(
        (0..d.len())
            .filter(free)
            .min_by(|&a, &b| d[a].total_cmp(&d[b])),
    );
    out.extend(
        (0..u.len())
            .filter(free)
            .max_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs())),
    );
    let (_, ud) = g.dirichlet(cones)?;
    out.extend(farthest(&ud, cones, used).map(|v| v as usize));
    let mut c: Vec<u32> = out.into_iter().map(|v| v as u32).collect();
    c.sort_unstable();
    c.dedup();
    Ok(c)
}

/// The greedy on the energy itself (step 1b): from `first`, each new cone is the candidate
/// of [`candidates`] whose least-squares `σ(2u)` is smallest.
fn greedy_by_energy(
    g: &mut GreenBasis,
    first: u32,
    used: &[bool],
    max_cones: usize,
) -> Result<Vec<u32>> {
    let mut cones = vec![first];
    while cones.len() < max_cones {
        let mut best: Option<(f64, u32)> = None;
        for c in candidates(g, &cones, used, true)? {
            let mut trial = cones.clone();
            trial.push(c);
            let s = energy(g, &trial)?;
            if best.is_none_or(|b| s < b.0) {
                best = Some((s, c));
            }
        }
        let Some((_, c)) = best else { break };
        cones.push(c);
    }
    Ok(cones)
}

/// Cone moves (step 2): returns the improved set and its `σ(2u)`. With a distortion bound,
/// a move is kept only if the linearised spread stays within it.
fn move_cones(
    g: &mut GreenBasis,
    mut cones: Vec<u32>,
    used: &[bool],
    bound: f64,
    wide: bool,
) -> Result<Vec<u32>> {
    let mut best = energy(g, &cones)?;
    for _ in 0..MOVE_ROUNDS {
        let mut moved = false;
        for i in 0..cones.len() {
            let mut others = cones.clone();
            others.remove(i);
            if others.is_empty() {
                continue;
            }
            for c in candidates(g, &others, used, wide)? {
                if c == cones[i] {
                    continue;
                }
                let mut trial = others.clone();
                trial.insert(i, c);
                let s = energy(g, &trial)?;
                let within = bound < 0.0 || {
                    let (_, u) = g.dirichlet(&trial)?;
                    spread(g, &u, used) <= bound
                };
                if s < best - 1e-12 && within {
                    best = s;
                    cones = trial;
                    moved = true;
                }
            }
        }
        if !moved {
            break;
        }
    }
    Ok(cones)
}

/// Steps 1–3 of the module docs on a closed, connected surface; `k0` the angle defects.
pub(super) fn place_cones(
    g: &mut GreenBasis,
    k0: &[f64],
    used: &[bool],
    budget: ConeBudget,
    wide: bool,
) -> Result<ConePlacement> {
    let (max_cones, bound) = match budget {
        ConeBudget::Count(c) => (c, -1.0),
        ConeBudget::AreaDistortion { bound, max_cones } => (max_cones, bound),
    };
    let candidates = (0..k0.len()).filter(|&v| used[v]);
    let by_defect = if g.chi > 0.0 {
        candidates.max_by(|&a, &b| k0[a].total_cmp(&k0[b]))
    } else {
        candidates.min_by(|&a, &b| k0[a].total_cmp(&k0[b]))
    };
    let by_smooth = (0..k0.len())
        .filter(|&v| used[v])
        .max_by(|&a, &b| g.w0[a].abs().total_cmp(&g.w0[b].abs()));
    if max_cones == 0 || by_defect.is_none() {
        return Ok(ConePlacement {
            cones: Vec::new(),
            distortion_history: Vec::new(),
        });
    }
    let mut best: Option<(f64, Vec<u32>, Vec<f64>)> = None;
    for first in [by_defect, by_smooth].into_iter().flatten() {
        let (cones, history) = greedy_from(g, first as u32, used, max_cones, bound)?;
        let s = energy(g, &cones)?;
        if best.as_ref().is_none_or(|b| s < b.0) {
            best = Some((s, cones, history));
        }
        if wide && bound < 0.0 {
            let cones = greedy_by_energy(g, first as u32, used, max_cones)?;
            let s = energy(g, &cones)?;
            if best.as_ref().is_none_or(|b| s < b.0) {
                let mut history = Vec::with_capacity(cones.len());
                for k in 1..=cones.len() {
                    let (_, u) = g.dirichlet(&cones[..k])?;
                    history.push(spread(g, &u, used));
                }
                best = Some((s, cones, history));
            }
        }
    }
    let Some((_, cones, history)) = best else {
        return Ok(ConePlacement {
            cones: Vec::new(),
            distortion_history: Vec::new(),
        });
    };
    let cones = move_cones(g, cones, used, bound, wide)?;
    let (k, _) = g.least_squares(&cones)?;
    Ok(ConePlacement {
        cones: k,
        distortion_history: history,
    })
}
