//! Triangle meshes: connectivity, positions, validation, topology, file formats, generators.
//!
//! A [`Surface`] is what a mesh file describes: [`Mesh`] connectivity plus vertex positions in
//! R³. Algorithms that only need connectivity take a `&Mesh`; intrinsic algorithms (Ricci flow)
//! take a `&Mesh` and edge lengths and never look at positions (docs/DESIGN.md §2).

pub mod build;
pub(crate) mod connectivity;
pub mod double;
pub mod generate;
pub mod io;
pub mod quality;
pub mod topology;

pub use build::{build_surface, BuildReport, PolygonSoup};
pub use connectivity::{Mesh, NONE};
pub use double::double_cover;
pub use topology::{topology, Component, Topology};

/// A mesh embedded in R³: connectivity plus one position per vertex (and optional UVs).
#[derive(Debug, Clone)]
pub struct Surface {
    pub mesh: Mesh,
    pub positions: Vec<[f64; 3]>,
    /// Per-vertex texture coordinates, when known.
    pub uvs: Option<Vec<[f64; 2]>>,
}

impl Surface {
    /// Build from triangles, validating connectivity (see [`build_surface`] for soups).
    pub fn new(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> crate::Result<Surface> {
        let mesh = Mesh::from_triangles(positions.len(), faces)?;
        Ok(Surface {
            mesh,
            positions,
            uvs: None,
        })
    }

    /// Euclidean length of every edge, indexed by edge id.
    pub fn edge_lengths(&self) -> Vec<f64> {
        (0..self.mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = self.mesh.edge_vertices(e);
                dist(self.positions[a as usize], self.positions[b as usize])
            })
            .collect()
    }

    /// Axis-aligned bounding box (min, max).
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Length of the bounding-box diagonal.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        dist(lo, hi)
    }

    /// Area of the embedded surface: Σ |(b − a) × (c − a)| / 2 over its faces.
    pub fn area(&self) -> f64 {
        use crate::numeric::vec3::{cross, norm, sub};
        self.mesh
            .faces()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.positions[v as usize]);
                0.5 * norm(cross(sub(b, a), sub(c, a)))
            })
            .sum()
    }
}

pub(crate) use crate::numeric::vec3::dist;
