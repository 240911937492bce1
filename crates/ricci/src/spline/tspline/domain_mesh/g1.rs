//! G¹ at the zeros of the domain mesh (parent module doc): the Bézier point at every zero, the
//! linear conditions that make the spline C¹ in the translation chart across every side at a
//! zero, solved once into a [`Reduction`] — some control points of the zeros' 1-rings become
//! fixed combinations of the others, so every fitted net keeps the conditions.

use super::*;

/// The linear conditions for G¹ at the zeros (C¹ in the translation chart across every side at
/// a zero, see the module doc) solved once: some vertices of the zeros' 1-rings are fixed
/// combinations of the others.
#[derive(Debug, Clone, Default)]
pub struct Reduction {
    /// The number of free values (control points that remain unknowns).
    pub free: usize,
    /// Per vertex: its value as a combination of free values (indices `0..free`).
    pub expand: Vec<Combination>,
}

impl DomainMesh {
    /// The Bézier point at every zero: the mean of the side points next to it (each side point
    /// is met from both cells of its side, so every one counts twice).
    pub(super) fn points_at_zeros(&mut self) {
        let mut sums: std::collections::HashMap<u32, (Combination, usize)> = Default::default();
        for c in 0..self.n_cells() {
            for k in 0..4 {
                let z = self.corners[c][k];
                if !self.is_zero(z) {
                    continue;
                }
                let (_, along_u, along_v) = CORNER_POINTS[k];
                let e = sums.entry(z).or_default();
                for (i, j) in [along_u, along_v] {
                    for &(v, w) in &self.bezier[c][i][j] {
                        add(&mut e.0, v, w);
                    }
                    e.1 += 1;
                }
            }
        }
        for c in 0..self.n_cells() {
            for k in 0..4 {
                if let Some((sum, n)) = sums.get(&self.corners[c][k]) {
                    let (i, j) = CORNER_POINTS[k].0;
                    self.bezier[c][i][j] = sum.iter().map(|&(v, w)| (v, w / *n as f64)).collect();
                }
            }
        }
    }

    /// The conditions of C¹ across every side at a zero, per zero: for each of the side's four
    /// Bézier points `S` (shared), the points `a`, `b` next to it across the side in the two
    /// cells (sizes `α`, `β` across the side), `β a + α b − (α + β) S = 0`.
    fn g1_conditions(&self) -> Vec<(u32, Vec<Combination>)> {
        let mut out: std::collections::BTreeMap<u32, Vec<Combination>> = Default::default();
        for (a, side, at_zero) in self.sides() {
            if !at_zero {
                continue;
            }
            let b = self.nb(a, side);
            let q = self.corners[a as usize];
            let ends = if side == RIGHT {
                [q[1], q[2]]
            } else {
                [q[2], q[3]]
            };
            let Some(&z) = ends.iter().find(|&&v| self.is_zero(v)) else {
                continue;
            };
            let axis = if side == RIGHT { Axis::U } else { Axis::V };
            let (alpha, beta) = (self.len(a, axis), self.len(b, axis));
            let (ba, bb) = (&self.bezier[a as usize], &self.bezier[b as usize]);
            for k in 0..4 {
                let (s, x, y) = if side == RIGHT {
                    (&ba[3][k], &ba[2][k], &bb[1][k])
                } else {
                    (&ba[k][3], &ba[k][2], &bb[k][1])
                };
                let mut row = Combination::new();
                for (comb, w) in [(x, beta), (y, alpha), (s, -(alpha + beta))] {
                    for &(v, c) in comb {
                        add(&mut row, v, w * c);
                    }
                }
                out.entry(z).or_default().push(row);
            }
        }
        out.into_iter().collect()
    }

    /// Solve [`Self::g1_conditions`] zero by zero (Gauss–Jordan with full pivoting on the
    /// 1-ring's vertices): the pivots become combinations of the other vertices.
    pub(super) fn g1_reduction(&self) -> Result<Reduction, String> {
        let nv = self.n_vertices();
        let mut dependent: Vec<Option<Combination>> = vec![None; nv];
        let mut used = vec![false; nv];
        for (z, rows) in self.g1_conditions() {
            // substitute the vertices already solved for (rings of other zeros)
            let rows: Vec<Combination> = rows
                .iter()
                .map(|r| {
                    let mut out = Combination::new();
                    for &(v, w) in r {
                        match &dependent[v as usize] {
                            Some(d) => d.iter().for_each(|&(x, c)| add(&mut out, x, w * c)),
                            None => add(&mut out, v, w),
                        }
                    }
                    out
                })
                .collect();
            let mut cols: Vec<u32> = rows.iter().flatten().map(|x| x.0).collect();
            cols.sort_unstable();
            cols.dedup();
            // one scale for the whole group: the conditions that hold identically (the three
            // columns away from the zero, module doc) stay at rounding level
            let big = rows.iter().flatten().fold(0.0f64, |a, x| a.max(x.1.abs()));
            if !(big > 0.0) {
                continue;
            }
            let mut m: Vec<Vec<f64>> = rows
                .iter()
                .map(|r| {
                    let mut dense = vec![0.0; cols.len()];
                    for &(v, w) in r {
                        dense[cols.binary_search(&v).unwrap_or(0)] += w / big;
                    }
                    dense
                })
                .collect();
            let candidate: Vec<bool> = cols.iter().map(|&v| !used[v as usize]).collect();
            let mut pivots: Vec<(usize, usize)> = Vec::new();
            const TOL: f64 = 1e-10;
            for r in 0..m.len() {
                let mut best = (0.0, 0, 0);
                for (i, row) in m.iter().enumerate().skip(r) {
                    for (j, &x) in row.iter().enumerate() {
                        if candidate[j] && !pivots.iter().any(|p| p.1 == j) && x.abs() > best.0 {
                            best = (x.abs(), i, j);
                        }
                    }
                }
                if best.0 <= TOL {
                    break;
                }
                let (_, i, j) = best;
                m.swap(r, i);
                let d = m[r][j];
                m[r].iter_mut().for_each(|x| *x /= d);
                let pivot_row = m[r].clone();
                for (i, row) in m.iter_mut().enumerate() {
                    if i != r && row[j] != 0.0 {
                        let f = row[j];
                        row.iter_mut()
                            .zip(&pivot_row)
                            .for_each(|(x, p)| *x -= f * p);
                    }
                }
                pivots.push((r, j));
            }
            if m[pivots.len()..]
                .iter()
                .any(|row| row.iter().any(|x| x.abs() > TOL))
            {
                return Err(format!(
                    "the G1 conditions at zero {z} involve vertices already solved for at another zero (the zeros are too close for the mesh)"
                ));
            }
            for &(r, j) in &pivots {
                let expr: Combination = cols
                    .iter()
                    .enumerate()
                    .filter(|&(k, _)| k != j && m[r][k].abs() > 1e-15)
                    .map(|(k, &v)| (v, -m[r][k]))
                    .collect();
                dependent[cols[j] as usize] = Some(expr);
            }
            cols.iter().for_each(|&v| used[v as usize] = true);
        }
        let mut index = vec![u32::MAX; nv];
        let mut free = 0u32;
        for v in 0..nv {
            if dependent[v].is_none() {
                index[v] = free;
                free += 1;
            }
        }
        let expand = (0..nv)
            .map(|v| match &dependent[v] {
                Some(d) => d.iter().map(|&(x, w)| (index[x as usize], w)).collect(),
                None => vec![(index[v], 1.0)],
            })
            .collect();
        Ok(Reduction {
            free: free as usize,
            expand,
        })
    }

    /// The control points of the free values `free` ([`Reduction::free`] of them): a net that is
    /// G¹ at every zero.
    pub fn expand(&self, free: &[[f64; 3]]) -> Vec<[f64; 3]> {
        self.reduction
            .expand
            .iter()
            .map(|comb| {
                let mut x = [0.0; 3];
                for &(f, w) in comb {
                    for d in 0..3 {
                        x[d] += w * free[f as usize][d];
                    }
                }
                x
            })
            .collect()
    }

    /// A combination of control points as a combination of the free values.
    pub fn reduce(&self, row: &[(u32, f64)]) -> Combination {
        let mut out = Combination::new();
        for &(v, w) in row {
            for &(f, c) in &self.reduction.expand[v as usize] {
                add(&mut out, f, w * c);
            }
        }
        out
    }
}
