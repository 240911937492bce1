//! The overview of an [`AffineAtlas`] (paper 000 §4): every cut or local chart's home faces
//! mapped into the central chart (chart 0) by the transition on one face the two charts
//! share. Across the cut the mapped faces appear displaced by the deck motion. Pictures of it
//! are drawn by `ricci_render::atlas`.

use super::{AffineAtlas, ChartId, Corners, FlatCharts};
use crate::layout::isometry::Isometry;

impl AffineAtlas {
    /// For every chart `c ≥ 1` that shares a face with the central chart: `c` and its home
    /// faces' corners in the central chart's coordinates, mapped by the transition on the
    /// first of its faces (in its own order) that also lies in chart 0.
    pub fn overview(&self) -> Vec<(ChartId, Vec<Corners>)> {
        let mut out = Vec::new();
        for c in 1..self.n_charts() as ChartId {
            let Some((faces, coords)) = self.chart_faces(c) else {
                continue;
            };
            let Some((m, _)) = faces.iter().find_map(|&f| self.transition(c, 0, f)) else {
                continue;
            };
            let mut tris = Vec::new();
            for (k, &f) in faces.iter().enumerate() {
                if self.home_chart(f) == Some(c) {
                    tris.push(coords[k].map(|p| {
                        let z = m.apply(num_complex::Complex64::new(p[0], p[1]));
                        [z.re, z.im]
                    }));
                }
            }
            out.push((c, tris));
        }
        out
    }
}
