//! Rounding the UVs of the common subdivision without losing orientation.
//!
//! A piece of the overlay is positively oriented in exact arithmetic when its face of `T` is
//! and the determinant of its corners' barycentric coordinates on that face is positive
//! ([`super::CommonSubdivision::barycentric_orientation`]). Its written UVs are the correctly
//! rounded (E²: to a few ulps) images of its corners; where the conformal factor is tiny the
//! whole face of `T` spans only a few ulps (camel.off: the flat torus metric shrinks the
//! legs by ~1e-15, and two crossings on one edge of `T`, 1e-17 apart, rounded to the same
//! point), and a piece can come out degenerate or flipped although the map is not. Such a
//! piece is repaired by moving one of its vertices by a few ulps (the rounding error itself):
//! every corner written with that vertex's UV moves with it (so the OBJ keeps one `vt` there),
//! and a move is kept only if every piece that uses the moved UV is then positively oriented.

use super::piece_positive;
use crate::metric::Geometry;

/// Largest move, in ulps per coordinate.
const MAX_ULPS: i32 = 3;

/// `x` moved by `k` ulps (towards +∞ for `k > 0`).
fn step_ulps(mut x: f64, k: i32) -> f64 {
    for _ in 0..k.unsigned_abs() {
        x = if k > 0 { x.next_up() } else { x.next_down() };
    }
    x
}

/// The moves tried, smallest first: `(i, j)` ulps in the two coordinates, `(0, 0)` excluded.
fn moves() -> Vec<(i32, i32)> {
    let mut m: Vec<(i32, i32)> = (-MAX_ULPS..=MAX_ULPS)
        .flat_map(|i| (-MAX_ULPS..=MAX_ULPS).map(move |j| (i, j)))
        .filter(|&(i, j)| (i, j) != (0, 0))
        .collect();
    m.sort_by_key(|&(i, j)| (i.abs().max(j.abs()), i.abs() + j.abs()));
    m
}

/// Repair the triangles of `triangles` (vertex ids) whose UV triangles (`uv[3t + i]`) are not
/// positively oriented although `repairable(t)` says they are in exact arithmetic, by moving
/// one of their vertices' UV by at most [`MAX_ULPS`] ulps per coordinate (see the module
/// docs). `first_movable` is the first vertex id tried first (the crossings of the overlay:
/// vertices `≥ first_movable` are tried before the others). Returns the number of UVs moved.
pub fn repair_rounded_pieces(
    geometry: Geometry,
    triangles: &[[u32; 3]],
    uv: &mut [[f64; 2]],
    first_movable: u32,
    repairable: impl Fn(usize) -> bool,
) -> usize {
    let bad: Vec<usize> = (0..triangles.len())
        .filter(|&t| !piece_positive(geometry, uv, t) && repairable(t))
        .collect();
    if bad.is_empty() {
        return 0;
    }
    // Corners of every vertex (CSR).
    let nv = triangles
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0);
    let mut start = vec![0usize; nv + 1];
    for &v in triangles.iter().flatten() {
        start[v as usize + 1] += 1;
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut corners = vec![0usize; 3 * triangles.len()];
    for (k, &v) in triangles.iter().flatten().enumerate() {
        corners[fill[v as usize]] = k;
        fill[v as usize] += 1;
    }
    let moves = moves();
    let mut moved = 0;
    for t in bad {
        if piece_positive(geometry, uv, t) {
            continue; // repaired by an earlier move
        }
        let mut order = [0usize, 1, 2];
        order.sort_by_key(|&c| triangles[t][c] < first_movable);
        'corner: for c in order {
            let v = triangles[t][c] as usize;
            let z = uv[3 * t + c];
            let group: Vec<usize> = corners[start[v]..start[v + 1]]
                .iter()
                .copied()
                .filter(|&k| {
                    uv[k][0].to_bits() == z[0].to_bits() && uv[k][1].to_bits() == z[1].to_bits()
                })
                .collect();
            let mut pieces: Vec<usize> = group.iter().map(|&k| k / 3).collect();
            pieces.sort_unstable();
            pieces.dedup();
            for &(i, j) in &moves {
                let w = [step_ulps(z[0], i), step_ulps(z[1], j)];
                for &k in &group {
                    uv[k] = w;
                }
                if pieces.iter().all(|&p| piece_positive(geometry, uv, p)) {
                    moved += 1;
                    break 'corner;
                }
            }
            for &k in &group {
                uv[k] = z;
            }
        }
    }
    moved
}
