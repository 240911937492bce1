//! Cut-and-paste moves planned on the word of the fundamental polygon ([`super`], phase 2):
//! letters `±(id+1)` in boundary order; commutator blocks `d e d⁻¹ e⁻¹`; the move along a
//! chord between two corners that glues the pieces back along a side pair (paper 002
//! §6.2.2.1, Fig. 49); and the plan that turns a linked pair of letters into a block in at
//! most two moves, with the other letters grouped into unsplittable opaque letters.

/// Letters at or above this value are opaque groups of letters (no move splits them).
const OPAQUE: i64 = 1 << 40;

/// Commutator blocks `d e d⁻¹ e⁻¹` of a cyclic word (letters `±(id+1)`), opaque letters
/// excluded, as `(d, e)`.
pub(super) fn blocks(w: &[i64]) -> Vec<(i64, i64)> {
    let n = w.len();
    let mut out = Vec::new();
    if n < 4 {
        return out;
    }
    for r in 0..n {
        let (d, e, d2, e2) = (w[r], w[(r + 1) % n], w[(r + 2) % n], w[(r + 3) % n]);
        if d.abs() >= OPAQUE || e.abs() >= OPAQUE || d.abs() == e.abs() {
            continue;
        }
        let used = |l: i64| {
            out.iter()
                .any(|&(a, b): &(i64, i64)| a.abs() == l.abs() || b.abs() == l.abs())
        };
        if d2 == -d && e2 == -e && !used(d) && !used(e) {
            out.push((d, e));
        }
    }
    out
}

/// The cut-and-paste move on a cyclic word: chord `c` from the corner before `w[p]` to the
/// corner before `w[q]`, glue along letter `s` (either sign).
fn paste(w: &[i64], p: usize, q: usize, s: i64, c: i64) -> Option<Vec<i64>> {
    let n = w.len();
    let q = (q + n - p) % n;
    if q == 0 {
        return None;
    }
    let rot: Vec<i64> = w[p..].iter().chain(&w[..p]).copied().collect();
    let (w1, w2) = rot.split_at(q);
    let s = if w1.contains(&s) && w2.contains(&-s) {
        s
    } else if w1.contains(&-s) && w2.contains(&s) {
        -s
    } else {
        return None;
    };
    let i = w1.iter().position(|&t| t == s)?;
    let j = w2.iter().position(|&t| t == -s)?;
    let (al, be) = (&w1[..i], &w1[i + 1..]);
    let (ga, de) = (&w2[..j], &w2[j + 1..]);
    let mut out = Vec::with_capacity(n);
    out.extend_from_slice(be);
    out.push(-c);
    out.extend_from_slice(al);
    out.extend_from_slice(de);
    out.push(c);
    out.extend_from_slice(ga);
    Some(out)
}

/// The candidate moves `(corner p, corner q, letter s)` in the order found (the caller takes the
/// first): each is the first of at most two that turn a linked pair of letters outside the
/// commutator blocks into a new block (the other letters are grouped into unsplittable opaque
/// letters for the search).
pub(super) fn plan(w: &[i64]) -> Option<Vec<(usize, usize, i64)>> {
    let bl = blocks(w);
    let done = |l: i64| {
        bl.iter()
            .any(|&(d, e)| d.abs() == l.abs() || e.abs() == l.abs())
    };
    // A linked pair (a, b) of letters not in blocks.
    let pair = linked_pairs(w, &done).first().copied();
    let (a, b, ia) = pair?;
    // The moves that complete a block for some linked pair (the second move of a plan made
    // earlier), or else the first moves of two-move plans for the first pair.
    let mut out = Vec::new();
    for (a2, b2, i2) in linked_pairs(w, &done) {
        out.extend(plan_pair(w, a2, b2, i2, false));
    }
    if out.is_empty() {
        out = plan_pair(w, a, b, ia, true);
    }
    Some(out)
}

/// All linked pairs `(a, b, first index of a)` of letters outside blocks.
fn linked_pairs(w: &[i64], done: &dyn Fn(i64) -> bool) -> Vec<(i64, i64, usize)> {
    let n = w.len();
    let at = |l: i64| (0..n).find(|&k| w[k] == l).unwrap_or(0);
    let mut out = Vec::new();
    for k in 0..n {
        let a = w[k];
        if a < 0 || done(a) {
            continue;
        }
        let (ia, ja) = (at(a), at(-a));
        for &b in w {
            if b < 0 || b == a || done(b) {
                continue;
            }
            let inside = |t: usize| (t + n - ia) % n < (ja + n - ia) % n;
            if inside(at(b)) != inside(at(-b)) {
                out.push((a, b, ia));
            }
        }
    }
    out
}

/// A move for the pair `(a, b)` that makes a block now, or (with `two`) the first of two.
fn plan_pair(w: &[i64], a: i64, b: i64, ia: usize, two: bool) -> Vec<(usize, usize, i64)> {
    let n = w.len();
    // Compress from `a`'s first occurrence.
    let mut toks: Vec<i64> = Vec::new();
    let mut start: Vec<usize> = Vec::new();
    for k in 0..n {
        let i = (ia + k) % n;
        let t = w[i];
        if t.abs() == a || t.abs() == b {
            toks.push(t);
            start.push(i);
        } else if toks.last().is_some_and(|&l| l.abs() >= OPAQUE) {
            continue;
        } else {
            toks.push(OPAQUE + toks.len() as i64);
            start.push(i);
        }
    }
    let m = toks.len();
    let (c, d) = (OPAQUE / 2, OPAQUE / 2 + 1);
    let gain = |v: &[i64]| !blocks(v).is_empty();
    let mut out = Vec::new();
    for p in 0..m {
        for q in 0..m {
            for s in [a, b] {
                if let Some(w1) = paste(&toks, p, q, s, c) {
                    if gain(&w1) {
                        out.push((start[p], start[q], s));
                    }
                }
            }
        }
    }
    if !two || !out.is_empty() {
        return out;
    }
    for p in 0..m {
        for q in 0..m {
            for s in [a, b] {
                let Some(w1) = paste(&toks, p, q, s, c) else {
                    continue;
                };
                let other = if s == a { b } else { a };
                let m1 = w1.len();
                'second: for p2 in 0..m1 {
                    for q2 in 0..m1 {
                        for s2 in [other, c] {
                            if let Some(w2) = paste(&w1, p2, q2, s2, d) {
                                if gain(&w2) {
                                    out.push((start[p], start[q], s));
                                    break 'second;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Number of vertices of the polygon schema (corners identified by the side pairing).
    fn vertices(w: &[i64]) -> usize {
        let n = w.len();
        let ends = |l: i64| {
            let k = 2 * (l.unsigned_abs() as usize);
            if l > 0 {
                (k, k + 1)
            } else {
                (k + 1, k)
            }
        };
        let top = w
            .iter()
            .map(|l| l.unsigned_abs() as usize)
            .max()
            .unwrap_or(0);
        let mut parent: Vec<usize> = (0..2 * top + 2).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for k in 0..n {
            let (_, head) = ends(w[k]);
            let (tail, _) = ends(w[(k + 1) % n]);
            let (r1, r2) = (find(&mut parent, head), find(&mut parent, tail));
            parent[r1] = r2;
            let _ = n;
        }
        let mut roots: Vec<usize> = w
            .iter()
            .flat_map(|&l| {
                let (t, h) = ends(l);
                [t, h]
            })
            .map(|i| find(&mut parent, i))
            .collect();
        roots.sort_unstable();
        roots.dedup();
        roots.len()
    }

    fn is_canonical_after(mut w: Vec<i64>, genus: usize) -> usize {
        assert_eq!(vertices(&w), 1, "{w:?} is not a one-vertex schema");
        // Apply planned moves symbolically until the word is canonical; the number of moves.
        for (moves, next) in (0..4 * genus + 8).zip(100..) {
            if blocks(&w).len() == genus {
                return moves;
            }
            let (p, q, s) = plan(&w).and_then(|m| m.first().copied()).expect("a move");
            w = paste(&w, p, q, s, next).expect("a valid move");
            assert_eq!(vertices(&w), 1, "the move made {w:?}");
        }
        panic!("not canonical: {w:?}");
    }

    #[test]
    fn planned_moves_reach_the_canonical_word_in_two_moves_per_handle() {
        assert_eq!(is_canonical_after(vec![1, 2, -1, -2], 1), 0);
        assert_eq!(is_canonical_after(vec![1, 2, -1, -2, 3, 4, -3, -4], 2), 0);
        // The standard 4g-gon x₁ … x_2g x₁⁻¹ … x_2g⁻¹ (one vertex).
        for g in 1..=8i64 {
            let w: Vec<i64> = (1..=2 * g).chain((1..=2 * g).map(|k| -k)).collect();
            assert!(is_canonical_after(w, g as usize) <= 2 * g as usize);
        }
        // Random one-vertex words: random cut-and-paste moves applied to canonical words.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = |n: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        for trial in 0..200 {
            let g = 1 + trial % 6;
            let mut w: Vec<i64> = (0..g as i64)
                .flat_map(|k| [2 * k + 1, 2 * k + 2, -(2 * k + 1), -(2 * k + 2)])
                .collect();
            let mut next = 1000;
            for _ in 0..3 * g {
                let n = w.len();
                let (p, q, s) = (rnd(n), rnd(n), w[rnd(n)]);
                if let Some(w2) = paste(&w, p, q, s, next) {
                    w = w2;
                    next += 1;
                }
            }
            assert!(is_canonical_after(w, g) <= 2 * g);
        }
    }
}
