//! The T-mesh's T-junctions and its analysis suitability (Li, Zheng, Sederberg, Hughes, Scott
//! 2012 §3–4), found by walking the full mesh cell to cell — across the strip gluings by the
//! translations — with the T-mesh's lines ([`DomainMesh::on_line_u`], [`DomainMesh::on_line_v`]).
//! A **T-junction** is a vertex of the T-mesh with three of its four edges. Its **extension**
//! (cubic) runs from it two crossings of the T-mesh's lines ahead, into the faces where the
//! edge is missing, and one crossing back along its line. The T-mesh is **analysis-suitable**
//! when no extension along `u` meets one along `v`: then the blending functions are linearly
//! independent and sum to one (Theorems 4.8 and 6.2 there).

use super::*;

impl DomainMesh {
    /// Whether the T-mesh has the edge along `axis` (forward or back) from the vertex at the
    /// lower-left of cell `c` to the next vertex of the full mesh.
    fn edge(&self, c: u32, axis: Axis, forward: bool) -> bool {
        let (back, ahead) = axis.sides();
        let next = self.nb(c, if forward { ahead } else { back });
        self.crossed(c, axis.other()) && self.crossed(next, axis.other())
    }

    /// If the vertex at the lower-left of cell `c` is a T-junction: whether the line that ends
    /// there runs along `v`.
    pub(super) fn t_junction(&self, c: u32) -> Option<bool> {
        if self.is_zero(self.corners[c as usize][0]) {
            return None;
        }
        let e = [
            self.edge(c, Axis::U, true),
            self.edge(c, Axis::U, false),
            self.edge(c, Axis::V, true),
            self.edge(c, Axis::V, false),
        ];
        (e.iter().filter(|&&x| x).count() == 3).then_some(!(e[2] && e[3]))
    }

    /// The vertices of the extension of the T-junction at the lower-left of cell `c` whose
    /// line runs along `axis` (module doc; it stops at a zero).
    fn extension(&self, c: u32, axis: Axis) -> Result<Vec<u32>, String> {
        let ahead_missing = !self.edge(c, axis, true);
        let (back, ahead) = axis.sides();
        let mut out = vec![self.corners[c as usize][0]];
        for (forward, count) in [(ahead_missing, 2), (!ahead_missing, 1)] {
            let (mut cell, mut seen, mut steps) = (c, 0, 0);
            while seen < count {
                cell = self.nb(cell, if forward { ahead } else { back });
                let v = self.corners[cell as usize][0];
                out.push(v);
                if self.is_zero(v) {
                    break;
                }
                if self.crossed(cell, axis) {
                    seen += 1;
                }
                steps += 1;
                if steps > self.n_cells() {
                    return Err(format!(
                        "the extension of the T-junction at the vertex of cell {c} does not end"
                    ));
                }
            }
        }
        Ok(out)
    }

    /// `None` if the T-mesh is analysis-suitable (module doc), else a vertex where an extension
    /// along `u` meets one along `v`; or why it cannot be said.
    pub fn extensions_meet(&self) -> Result<Option<u32>, String> {
        let Some(t) = &self.tjunctions else {
            return Ok(None);
        };
        let mut mark = vec![0u8; self.n_vertices()];
        for &(r, i, j, along_v) in &t.junctions {
            let rc = &self.rects[r as usize];
            let c = (rc.first_cell + j as usize * rc.m + i as usize) as u32;
            let (axis, bit) = if along_v { (Axis::V, 2) } else { (Axis::U, 1) };
            for v in self.extension(c, axis)? {
                mark[v as usize] |= bit;
                if mark[v as usize] == 3 {
                    return Ok(Some(v));
                }
            }
        }
        Ok(None)
    }
}
