//! A finite portion of the universal cover (paper 001 §V "Tile the canonical domain", paper
//! 002 §4.3.3): copies `γF` of the laid-out fundamental polygon under deck transformations,
//! placed domain by domain (each copy is the image of the whole layout under one isometry,
//! which keeps errors from accumulating across copies — paper 001 §VI.d).
//!
//! Two ways to choose the copies:
//! * [`tiles_by_words`] — all freely reduced words in the generators `D(a_i)^{±1}, D(b_i)^{±1}`
//!   up to a length (copies may repeat when two words are equal in the group);
//! * [`tiles_by_radius`] — the distinct copies whose image of a base point lies within a
//!   radius, found breadth first through the side pairings (neighbouring copies share a
//!   side), each with a word in the generators.

use super::deck::{DeckGroup, Polygon};
use super::isometry::Isometry;
use super::place::Space;
use crate::error::{Error, Result};
use std::collections::{HashMap, VecDeque};

/// A word in the generators: (letter index, inverse).
pub type Word = Vec<(usize, bool)>;

/// One copy of the fundamental polygon.
#[derive(Debug, Clone)]
pub struct Tile<I> {
    /// Word in the generators: (letter index, inverse).
    pub word: Vec<(usize, bool)>,
    /// The deck transformation placing this copy.
    pub map: I,
}

/// Human-readable form of a word, e.g. `"a1 b1^-1"` (empty word: `"id"`).
pub fn word_string(letters: &[String], w: &[(usize, bool)]) -> String {
    if w.is_empty() {
        return "id".into();
    }
    w.iter()
        .map(|&(l, inv)| {
            let n = letters.get(l).cloned().unwrap_or_else(|| format!("x{l}"));
            if inv {
                format!("{n}^-1")
            } else {
                n
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn reduce(w: &mut Vec<(usize, bool)>) {
    let mut out: Vec<(usize, bool)> = Vec::with_capacity(w.len());
    for &x in w.iter() {
        if let Some(&last) = out.last() {
            if last.0 == x.0 && last.1 != x.1 {
                out.pop();
                continue;
            }
        }
        out.push(x);
    }
    *w = out;
}

/// All freely reduced words of length ≤ `max_len` in the generators and their inverses
/// (identity first). Fails if a generator is missing or the count would exceed `max_tiles`.
pub fn tiles_by_words<I: Isometry>(
    group: &DeckGroup<I>,
    max_len: usize,
    max_tiles: usize,
) -> Result<Vec<Tile<I>>> {
    let gens: Vec<I> = group
        .generators
        .iter()
        .map(|g| g.ok_or_else(|| Error::input("the deck group has undetermined generators")))
        .collect::<Result<_>>()?;
    let mut out = vec![Tile {
        word: Vec::new(),
        map: I::identity(),
    }];
    let mut frontier = vec![0usize];
    for _ in 0..max_len {
        let mut next = Vec::new();
        for &t in &frontier {
            for (l, g) in gens.iter().enumerate() {
                for inv in [false, true] {
                    if let Some(&(pl, pinv)) = out[t].word.last() {
                        if pl == l && pinv != inv {
                            continue;
                        }
                    }
                    let mut word = out[t].word.clone();
                    word.push((l, inv));
                    let step = if inv { g.inverse() } else { *g };
                    out.push(Tile {
                        word,
                        map: out[t].map.compose(&step).normalized(),
                    });
                    if out.len() > max_tiles {
                        return Err(Error::input(format!(
                            "more than {max_tiles} words of length ≤ {max_len}; ask for shorter words"
                        )));
                    }
                    next.push(out.len() - 1);
                }
            }
        }
        frontier = next;
    }
    Ok(out)
}

/// The distinct copies `γF` with `d(base, γ base) ≤ radius`, breadth first through the side
/// pairings from `F` (at most `max_tiles`). The base point should lie inside the polygon.
/// Copies are told apart by the image of the base point (distance > 1e-7).
pub fn tiles_by_radius<S: Space>(
    group: &DeckGroup<S::Iso>,
    poly: &Polygon,
    base: S::Point,
    radius: f64,
    max_tiles: usize,
) -> Result<Vec<Tile<S::Iso>>> {
    let n = poly.sides.len();
    // Words of the side maps: S_s = Q_s Q_{m+1}⁻¹ (s positive) with Q_s = D(prefix_s).
    let prefix = |k: usize| -> Vec<(usize, bool)> {
        poly.sides[..k]
            .iter()
            .filter_map(|s| s.letter.map(|l| (l, s.inverse)))
            .collect()
    };
    let inverse_word = |w: &[(usize, bool)]| -> Vec<(usize, bool)> {
        w.iter().rev().map(|&(l, i)| (l, !i)).collect()
    };
    let mut side_words: Vec<Option<Vec<(usize, bool)>>> = vec![None; n];
    for p in &group.pairings {
        let (s, m) = (p.side, p.partner);
        let mut w = prefix(s);
        w.extend(inverse_word(&prefix(m + 1)));
        reduce(&mut w);
        side_words[m] = Some(inverse_word(&w));
        side_words[s] = Some(w);
    }
    let maps: Vec<(S::Iso, Word)> = (0..n)
        .filter_map(|s| Some((group.side_map(s)?, side_words[s].clone()?)))
        .collect();
    if maps.is_empty() {
        return Err(Error::input("the polygon has no paired sides to tile with"));
    }
    const BAND: f64 = 1e-3;
    let key = |p: S::Point| (S::distance(base, p) / BAND).floor() as i64;
    let mut bands: HashMap<i64, Vec<usize>> = HashMap::new();
    let mut images: Vec<S::Point> = vec![base];
    bands.entry(key(base)).or_default().push(0);
    let mut out = vec![Tile {
        word: Vec::new(),
        map: S::Iso::identity(),
    }];
    let mut queue = VecDeque::from([0usize]);
    while let Some(t) = queue.pop_front() {
        for (sm, sw) in &maps {
            let g = out[t].map.compose(sm).normalized();
            let p = g.apply(base);
            if S::distance(base, p) > radius {
                continue;
            }
            let k = key(p);
            let known = (k - 1..=k + 1).any(|kk| {
                bands
                    .get(&kk)
                    .is_some_and(|l| l.iter().any(|&i| S::distance(images[i], p) < 1e-7))
            });
            if known {
                continue;
            }
            let mut word = out[t].word.clone();
            word.extend(sw.iter().copied());
            reduce(&mut word);
            images.push(p);
            bands.entry(k).or_default().push(out.len());
            out.push(Tile { word, map: g });
            queue.push_back(out.len() - 1);
            if out.len() >= max_tiles {
                return Ok(out);
            }
        }
    }
    Ok(out)
}
