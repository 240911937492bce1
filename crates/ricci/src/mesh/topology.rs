//! Topology of a mesh: connected components, boundary loops, Euler characteristic, genus.
//!
//! For a connected orientable surface with `b` boundary loops, `χ = V − E + F = 2 − 2g − b`.

use super::connectivity::{Mesh, NONE};
use serde::Serialize;

/// Topology of one connected component.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Component {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub boundary_loops: usize,
    pub euler_characteristic: i64,
    pub genus: i64,
    /// Smallest face id of the component (a handle to find it again).
    pub first_face: u32,
}

/// Topology of a whole mesh.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Topology {
    /// Face id → component id.
    #[serde(skip)]
    pub face_component: Vec<u32>,
    pub components: Vec<Component>,
}

impl Topology {
    pub fn euler_characteristic(&self) -> i64 {
        self.components.iter().map(|c| c.euler_characteristic).sum()
    }
    pub fn boundary_loops(&self) -> usize {
        self.components.iter().map(|c| c.boundary_loops).sum()
    }
    /// Sum of the genera of the components.
    pub fn genus(&self) -> i64 {
        self.components.iter().map(|c| c.genus).sum()
    }
}

/// Components (by face adjacency) with their counts, χ and genus.
pub fn topology(mesh: &Mesh) -> Topology {
    let nf = mesh.n_faces();
    let mut comp = vec![NONE; nf];
    let mut components = Vec::new();
    let mut stack = Vec::new();
    for seed in 0..nf as u32 {
        if comp[seed as usize] != NONE {
            continue;
        }
        let c = components.len() as u32;
        comp[seed as usize] = c;
        stack.push(seed);
        let mut faces = 0usize;
        while let Some(f) = stack.pop() {
            faces += 1;
            for h in mesh.face_halfedges(f) {
                let g = mesh.he_face(mesh.he_twin(h));
                if g != NONE && comp[g as usize] == NONE {
                    comp[g as usize] = c;
                    stack.push(g);
                }
            }
        }
        components.push(Component {
            vertices: 0,
            edges: 0,
            faces,
            boundary_loops: 0,
            euler_characteristic: 0,
            genus: 0,
            first_face: seed,
        });
    }
    let mut vseen = vec![false; mesh.n_vertices()];
    for (f, t) in mesh.faces().iter().enumerate() {
        for &v in t {
            if !vseen[v as usize] {
                vseen[v as usize] = true;
                components[comp[f] as usize].vertices += 1;
            }
        }
    }
    for e in 0..mesh.n_edges() as u32 {
        let f = mesh.he_face(mesh.edge_halfedge(e));
        components[comp[f as usize] as usize].edges += 1;
    }
    for l in mesh.boundary_loop_halfedges() {
        let f = mesh.he_face(l[0]);
        components[comp[f as usize] as usize].boundary_loops += 1;
    }
    for c in &mut components {
        c.euler_characteristic = c.vertices as i64 - c.edges as i64 + c.faces as i64;
        c.genus = (2 - c.euler_characteristic - c.boundary_loops as i64) / 2;
    }
    Topology {
        face_component: comp,
        components,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_tetrahedra_and_a_triangle() {
        let mut faces = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        faces.extend([[4, 6, 5], [4, 5, 7], [5, 6, 7], [6, 4, 7]]);
        faces.push([8, 9, 10]);
        let m = Mesh::from_triangles(11, faces).unwrap();
        let t = topology(&m);
        assert_eq!(t.components.len(), 3);
        assert_eq!(t.components[0].euler_characteristic, 2);
        assert_eq!(t.components[0].genus, 0);
        assert_eq!(t.components[2].boundary_loops, 1);
        assert_eq!(t.components[2].euler_characteristic, 1);
        assert_eq!(t.euler_characteristic(), 5);
    }
}
