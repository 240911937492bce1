//! Monotone repair of a common subdivision's crossing places.
//!
//! The pieces of the common subdivision are polygons whose corners lie on the boundary of
//! their input face (crossings on its edges, placed by `input_t`) and on the boundary of their
//! face of `T` (the same crossings, placed by `t_log_ratio`). Both boundaries are convex, so
//! every piece is positively oriented — in 3D and in the layout — whenever the places are
//! strictly monotone in the combinatorial order (the normal coordinates' ranks) along every
//! input edge and every edge of `T`. Places computed from edge lengths can break that order
//! where a vertex lies within rounding of an input edge (the split disk 300/11 of issue 15: an
//! input face of height 7.1e-9 × its side, below what its lengths resolve: a + b − c ≈ 2.5e-17 c).
//! [`repair`] keeps the longest strictly monotone subsequence of places on every edge and
//! re-places the others (and the ones left NaN) between their kept neighbours; it reports how
//! many moved and how far, so that a repair beyond rounding is visible.

use super::CommonSubdivision;
use crate::mesh::Mesh;

/// What [`repair`] changed.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MonotoneRepair {
    /// Crossings re-placed on their input edge.
    pub input_placed: usize,
    /// Crossings re-placed on their edge of `T`.
    pub t_placed: usize,
    /// Crossings that had no place (NaN) before the repair.
    pub unplaced: usize,
    /// Largest move of a re-placed crossing that had a place, along its input edge (as a
    /// fraction of the edge).
    pub input_shift: f64,
    /// Largest move of a re-placed crossing that had a place, along its edge of `T` (as a
    /// change of the projective weight `β_1 / (β_0 + β_1)`).
    pub t_shift: f64,
    /// Largest distance of a re-placed place outside the interval of its kept neighbours along
    /// its input edge: how far out of order the places found were (every re-placed place lies
    /// outside that interval, so this is the least move a repair needs).
    pub input_disorder: f64,
    /// The same along the edges of `T`, in the projective weight.
    pub t_disorder: f64,
}

/// Indices of a longest strictly increasing subsequence of the finite entries of `x` for
/// which `keep` holds.
fn longest_increasing(x: &[f64], keep: impl Fn(f64) -> bool) -> Vec<usize> {
    // tails[k]: index of the smallest tail of an increasing run of length k + 1.
    let mut tails: Vec<usize> = Vec::new();
    let mut parent = vec![usize::MAX; x.len()];
    for (i, &v) in x.iter().enumerate() {
        if !(v.is_finite() && keep(v)) {
            continue;
        }
        let k = tails.partition_point(|&j| x[j] < v);
        if k > 0 {
            parent[i] = tails[k - 1];
        }
        if k == tails.len() {
            tails.push(i);
        } else {
            tails[k] = i;
        }
    }
    let mut out = Vec::with_capacity(tails.len());
    let mut i = tails.last().copied().unwrap_or(usize::MAX);
    while i != usize::MAX {
        out.push(i);
        i = parent[i];
    }
    out.reverse();
    out
}

/// How close to the kept neighbour on their side re-placed places go (a fraction of the even
/// spacing between the two kept neighbours), when all of a run's places lie on that side.
const NEAR: f64 = 1e-3;

/// A re-placed entry of [`make_increasing`]: its index and the kept values around it.
type Moved = (usize, Option<f64>, Option<f64>);

/// Make `x` strictly increasing: keep a longest increasing subsequence, re-place the rest by
/// `fill(lower kept value or None, upper or None, step, steps)` (even spacing); a run whose
/// places all lie below (above) its two kept neighbours goes next to the lower (upper) one
/// instead — the least move — when that stays strictly ordered. Returns the re-placed entries.
fn make_increasing(
    x: &mut [f64],
    keep: impl Fn(f64) -> bool,
    fill: impl Fn(Option<f64>, Option<f64>, usize, usize) -> f64,
) -> Vec<Moved> {
    let kept = longest_increasing(x, keep);
    if kept.len() == x.len() {
        return Vec::new();
    }
    let mut moved = Vec::new();
    let mut prev: Option<usize> = None;
    for next in kept.iter().copied().map(Some).chain([None]) {
        let lo = prev.map_or(0, |i| i + 1);
        let hi = next.unwrap_or(x.len());
        let (a, b) = (prev.map(|i| x[i]), next.map(|i| x[i]));
        let steps = hi - lo + 1;
        let even: Vec<f64> = (lo..hi).map(|k| fill(a, b, k - lo + 1, steps)).collect();
        let near: Option<Vec<f64>> = match (a, b) {
            (Some(a), Some(_)) if x[lo..hi].iter().all(|&o| o <= a) => {
                Some(even.iter().map(|&e| a + NEAR * (e - a)).collect())
            }
            (Some(_), Some(b)) if x[lo..hi].iter().all(|&o| o >= b) => {
                Some(even.iter().map(|&e| b - NEAR * (b - e)).collect())
            }
            _ => None,
        };
        let ordered = |v: &[f64]| {
            a.is_none_or(|a| v.first().is_none_or(|&f| f > a))
                && b.is_none_or(|b| v.last().is_none_or(|&l| l < b))
                && v.windows(2).all(|w| w[0] < w[1])
        };
        let place = near.filter(|v| ordered(v)).unwrap_or(even);
        for (k, v) in (lo..hi).zip(place) {
            x[k] = v;
            moved.push((k, a, b));
        }
        prev = next;
    }
    moved
}

/// How far `o` lies outside `[a, b]` (a missing bound is no bound), in `f`'s scale.
fn outside(o: f64, a: Option<f64>, b: Option<f64>, f: impl Fn(f64) -> f64) -> f64 {
    let below = a.map_or(0.0, |a| (f(a) - f(o)).max(0.0));
    let above = b.map_or(0.0, |b| (f(o) - f(b)).max(0.0));
    below.max(above)
}

/// Re-place crossings so that their places are strictly monotone along every input edge and
/// every edge of `T` (module docs).
pub(super) fn repair(mesh: &Mesh, sub: &mut CommonSubdivision, out: &mut MonotoneRepair) {
    out.unplaced += sub
        .crossings
        .iter()
        .filter(|c| !(c.input_t.is_finite() && c.t_log_ratio.is_finite()))
        .count();
    // Along the input edges: 0 < t_1 < t_2 < … < 1 by rank.
    let mut by_edge: Vec<Vec<u32>> = vec![Vec::new(); mesh.n_edges()];
    for (id, c) in sub.crossings.iter().enumerate() {
        by_edge[c.input_edge as usize].push(id as u32);
    }
    for ids in &mut by_edge {
        ids.sort_by_key(|&id| sub.crossings[id as usize].input_rank);
        let mut x: Vec<f64> = ids
            .iter()
            .map(|&id| sub.crossings[id as usize].input_t)
            .collect();
        let old = x.clone();
        let moved = make_increasing(
            &mut x,
            |v| v > 0.0 && v < 1.0,
            |a, b, k, n| {
                let (a, b) = (a.unwrap_or(0.0), b.unwrap_or(1.0));
                a + (b - a) * k as f64 / n as f64
            },
        );
        for (k, a, b) in moved {
            if old[k].is_finite() {
                out.input_shift = out.input_shift.max((x[k] - old[k]).abs());
                let d = outside(old[k], a, b, |t| t);
                out.input_disorder = out.input_disorder.max(d);
            }
            sub.crossings[ids[k] as usize].input_t = x[k];
            out.input_placed += 1;
        }
    }
    // Along the edges of T: log(β_0/β_1) strictly decreasing, i.e. x = log(β_1/β_0)
    // increasing; an end without a kept neighbour halves the odds towards the vertex per step.
    let weight = |x: f64| 1.0 / (1.0 + (-x).exp());
    for e in 0..sub.triangulation.n_edges() {
        let (lo, hi) = (
            sub.crossing_offset[e] as usize,
            sub.crossing_offset[e + 1] as usize,
        );
        let mut x: Vec<f64> = sub.crossings[lo..hi]
            .iter()
            .map(|c| -c.t_log_ratio)
            .collect();
        let old = x.clone();
        let ln2 = std::f64::consts::LN_2;
        let moved = make_increasing(
            &mut x,
            |_| true,
            |a, b, k, n| match (a, b) {
                (Some(a), Some(b)) => a + (b - a) * k as f64 / n as f64,
                (Some(a), None) => a + ln2 * k as f64,
                (None, Some(b)) => b - ln2 * (n - k) as f64,
                (None, None) => ln2 * (k as f64 - 0.5 * n as f64),
            },
        );
        for (k, a, b) in moved {
            if old[k].is_finite() {
                out.t_shift = out.t_shift.max((weight(x[k]) - weight(old[k])).abs());
                out.t_disorder = out.t_disorder.max(outside(old[k], a, b, weight));
            }
            sub.crossings[lo + k].t_log_ratio = -x[k];
            out.t_placed += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn longest_increasing_subsequence_of_a_known_sequence() {
        let x = [3.0, 1.0, f64::NAN, 2.0, 5.0, 4.0, 6.0];
        let k = longest_increasing(&x, |_| true);
        let v: Vec<f64> = k.iter().map(|&i| x[i]).collect();
        assert_eq!(v.len(), 4);
        assert!(v.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn make_increasing_fills_between_kept_neighbours() {
        let mut x = [0.1, 0.2, 0.15, f64::NAN, 0.4, 0.9];
        let moved = make_increasing(
            &mut x,
            |v| v > 0.0 && v < 1.0,
            |a, b, k, n| {
                let (a, b) = (a.unwrap_or(0.0), b.unwrap_or(1.0));
                a + (b - a) * k as f64 / n as f64
            },
        );
        assert_eq!(moved.len(), 2);
        assert!(x.windows(2).all(|w| w[0] < w[1]), "{x:?}");
        assert!(x.iter().all(|&v| v > 0.0 && v < 1.0));
    }

    #[test]
    fn a_place_above_both_kept_neighbours_goes_next_to_the_upper_one() {
        // Kept: 0.1, 0.2, 0.5; 0.3 lies above the interval (0.1, 0.2) it must go into.
        let mut x = [0.1, 0.3, 0.2, 0.5];
        let moved = make_increasing(
            &mut x,
            |_| true,
            |a, b, k, n| {
                let (a, b) = (a.unwrap_or(0.0), b.unwrap_or(1.0));
                a + (b - a) * k as f64 / n as f64
            },
        );
        assert_eq!(moved, vec![(1, Some(0.1), Some(0.2))]);
        // Even spacing would give 0.15; next to 0.2 instead: 0.2 − NEAR · (0.2 − 0.15).
        assert!((x[1] - (0.2 - NEAR * 0.05)).abs() < 1e-15, "{x:?}");
        assert!((outside(0.3, Some(0.1), Some(0.2), |t| t) - 0.1).abs() < 1e-15);
    }
}
