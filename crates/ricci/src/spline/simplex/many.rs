//! Batched evaluation of a [`SimplexFamily`]: the same recurrence as
//! [`SimplexFamily::eval_offset`] (orders ≤ 2) at [`LANES`] nearby points at once.
//!
//! A family's DAG nodes are fetched once per batch instead of once per point, and every
//! three-term sum of the recurrence runs over the lanes (`[f64; LANES]` per partial, which the
//! compiler vectorises). Each lane performs exactly the operations of the scalar path in the
//! same order — its own variant choice, its own barycentric coordinates — and a node that is
//! dead at a lane (all its children vanish there) is set to `+0` in that lane, as the scalar
//! path writes it: the results are bitwise those of [`SimplexFamily::eval_offset`].

use super::{limit_directions, n_partials, Node, Point, SimplexFamily, Variant, LIVE_WORDS};

/// Number of points of one batched evaluation ([`SimplexFamily::eval_offset_many`]).
pub const LANES: usize = 4;

/// Partials per node of the order-≤ 2 layout.
const S: usize = 6;

/// One node's (or child's) values: `[partial][lane]`.
type Block = [[f64; LANES]; S];

/// [`Node::variant_at`] returning the variant's index (the same operations).
#[inline]
fn variant_index_at(nd: &Node, x: Point) -> (usize, [f64; 3]) {
    let lam = nd.var[0].lambda(x);
    if nd.two {
        let lam2 = nd.var[1].lambda(x);
        let s1 = lam[0].abs() + lam[1].abs() + lam[2].abs();
        let s2 = lam2[0].abs() + lam2[1].abs() + lam2[2].abs();
        if s2 < s1 {
            return (1, lam2);
        }
    }
    (0, lam)
}

#[inline(always)]
fn load(done: &[f64], id: u32) -> Block {
    let mut b = [[0.0; LANES]; S];
    let at = id as usize * S * LANES;
    for (p, row) in b.iter_mut().enumerate() {
        row.copy_from_slice(&done[at + p * LANES..at + (p + 1) * LANES]);
    }
    b
}

/// `Σ_j c[j] · kids[j][from]` per lane, in the scalar path's order.
#[inline(always)]
fn sum3(c: &[[f64; LANES]; 3], kids: &[Block; 3], from: usize) -> [f64; LANES] {
    std::array::from_fn(|l| {
        c[0][l] * kids[0][from][l] + c[1][l] * kids[1][from][l] + c[2][l] * kids[2][from][l]
    })
}

impl SimplexFamily {
    /// [`Self::eval_offset`] at the points `origin() + xs[l]` with directions `dirs[l]`, at most
    /// [`LANES`] of them, partials up to `order ≤ 2` (higher orders, or families too large for
    /// the live-node masks, are evaluated one point at a time). Point `l`'s results go to
    /// `out[l * stride..]` in the layout of [`Self::eval_offset`]; they are bitwise equal to
    /// that function's (module docs).
    pub fn eval_offset_many(
        &self,
        xs: &[Point],
        dirs: &[Point],
        order: usize,
        work: &mut Vec<f64>,
        out: &mut [f64],
        stride: usize,
    ) {
        let n = xs.len();
        debug_assert!(n == dirs.len() && n <= LANES);
        if order > 2 || !(2..=LANES).contains(&n) || self.n_nodes() > 64 * LIVE_WORDS {
            for l in 0..n.min(dirs.len()) {
                self.eval_offset(xs[l], dirs[l], order, work, &mut out[l * stride..]);
            }
            return;
        }
        let np = n_partials(order);
        // Unused lanes repeat the first point (their results are not written out).
        let x: [Point; LANES] = std::array::from_fn(|l| xs[if l < n { l } else { 0 }]);
        let ld: [(Point, Point); LANES] =
            std::array::from_fn(|l| limit_directions(dirs[if l < n { l } else { 0 }]));
        let need = self.n_nodes() * S * LANES;
        if work.len() < need {
            work.resize(need, 0.0);
        }
        // Per node: the lanes at which it is not identically zero (see `eval_offset_upto2`).
        let mut mask = [0u8; 64 * LIVE_WORDS];
        let nl = self.leaves.len();
        for (i, leaf) in self.leaves.iter().enumerate() {
            let mut m = 0u8;
            for (l, &(d, dp)) in ld.iter().enumerate() {
                if leaf.lines.iter().all(|ln| ln.admits(x[l], d, dp)) {
                    m |= 1 << l;
                }
            }
            mask[i] = m;
            let blk = &mut work[i * S * LANES..(i + 1) * S * LANES];
            blk.fill(0.0);
            for l in 0..LANES {
                if m >> l & 1 == 1 {
                    blk[l] = leaf.inv_det;
                }
            }
        }
        for (k, nd) in self.nodes.iter().enumerate() {
            let id = nl + k;
            let kids = |v: &Variant| v.child.iter().fold(0u8, |m, &c| m | mask[c as usize]);
            let m = kids(&nd.var[0]) | if nd.two { kids(&nd.var[1]) } else { 0 };
            mask[id] = m;
            let (done, rest) = work.split_at_mut(id * S * LANES);
            let me = &mut rest[..S * LANES];
            if m == 0 {
                me.fill(0.0);
                continue;
            }
            self.node_many(nd, &x, order, done, me);
            for l in 0..LANES {
                if m >> l & 1 == 0 {
                    for p in 0..S {
                        me[p * LANES + l] = 0.0;
                    }
                }
            }
        }
        for (r, &id) in self.roots.iter().enumerate() {
            let at = id as usize * S * LANES;
            for l in 0..n {
                for p in 0..np {
                    out[l * stride + r * np + p] = work[at + p * LANES + l];
                }
            }
        }
    }

    /// One internal node of [`Self::eval_offset_many`] at all lanes, from its children's blocks
    /// in `done`, written to `me` (`[partial][lane]`).
    #[inline(always)]
    fn node_many(&self, nd: &Node, x: &[Point; LANES], order: usize, done: &[f64], me: &mut [f64]) {
        let mut sel = [0usize; LANES];
        let mut lam = [[0.0; LANES]; 3];
        for l in 0..LANES {
            let (s, lm) = variant_index_at(nd, x[l]);
            sel[l] = s;
            for j in 0..3 {
                lam[j][l] = lm[j];
            }
        }
        let mut bx = [[0.0; LANES]; 3];
        let mut by = [[0.0; LANES]; 3];
        let kids: [Block; 3] = if sel.iter().all(|&s| s == sel[0]) {
            // The usual case: one variant at every lane, the children's blocks load as rows.
            let v = &nd.var[sel[0]];
            for j in 0..3 {
                bx[j] = [v.bx[j]; LANES];
                by[j] = [v.by[j]; LANES];
            }
            v.child.map(|c| load(done, c))
        } else {
            let mut kids = [[[0.0; LANES]; S]; 3];
            for l in 0..LANES {
                let v = &nd.var[sel[l]];
                for j in 0..3 {
                    bx[j][l] = v.bx[j];
                    by[j][l] = v.by[j];
                    let at = v.child[j] as usize * S * LANES;
                    for (p, row) in kids[j].iter_mut().enumerate() {
                        row[l] = done[at + p * LANES + l];
                    }
                }
            }
            kids
        };
        let mut o: Block = [[0.0; LANES]; S];
        o[0] = sum3(&lam, &kids, 0);
        // Partials of order above the node's degree vanish (see `eval_offset`).
        let top = order.min(nd.degree as usize);
        if top >= 1 {
            let p = nd.degree;
            let scale = |s: [f64; LANES]| s.map(|z| p * z);
            o[1] = scale(sum3(&bx, &kids, 0));
            o[2] = scale(sum3(&by, &kids, 0));
            if top >= 2 {
                o[3] = scale(sum3(&bx, &kids, 1));
                o[4] = scale(sum3(&bx, &kids, 2));
                o[5] = scale(sum3(&by, &kids, 2));
            }
        }
        for (p, row) in o.iter().enumerate() {
            me[p * LANES..(p + 1) * LANES].copy_from_slice(row);
        }
    }
}
