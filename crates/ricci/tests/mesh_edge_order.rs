//! `Mesh::from_triangles` numbers the edges by their vertex pair `(lo, hi)` in increasing
//! order and pairs every interior half-edge with the one running the other way; the pairing
//! is found by a counting pass over the vertices, not one sort of all half-edges. Checked
//! against an independent construction written here (an ordered map of the pairs), on a
//! closed surface and one with boundary (genus 2, pair of pants), and on a random relabelling
//! of their vertices.

use ricci::mesh::generate::{genus, pair_of_pants};
use ricci::mesh::{Mesh, NONE};
use std::collections::BTreeMap;

fn check(n: usize, faces: Vec<[u32; 3]>) {
    // Every undirected pair with its half-edges (3f + i runs from corner i to i + 1).
    let mut pairs: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
    for (f, t) in faces.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            pairs
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push((3 * f + i) as u32);
        }
    }
    let m = Mesh::from_triangles(n, faces).unwrap();
    assert_eq!(m.n_edges(), pairs.len());
    for (e, (&(lo, hi), hs)) in pairs.iter().enumerate() {
        let [a, b] = m.edge_vertices(e as u32);
        assert_eq!((a.min(b), a.max(b)), (lo, hi), "edge {e}");
        for &h in hs {
            assert_eq!(m.he_edge(h), e as u32, "half-edge {h}");
        }
        match hs[..] {
            [h] => assert!(m.is_boundary_edge(e as u32), "{h}"),
            [h, g] => {
                assert_eq!(m.he_twin(h), g);
                assert_eq!(m.he_twin(g), h);
            }
            _ => panic!("non-manifold pair in a generated surface"),
        }
    }
    for h in 0..m.n_corners() as u32 {
        assert_ne!(m.he_edge(h), NONE);
    }
}

#[test]
fn edges_are_numbered_by_their_vertex_pairs() {
    for s in [genus(2, 12).unwrap(), pair_of_pants(16).unwrap()] {
        let n = s.mesh.n_vertices();
        let faces = s.mesh.faces().to_vec();
        check(n, faces.clone());
        // The vertices relabelled by a fixed pseudo-random permutation.
        let mut perm: Vec<u32> = (0..n as u32).collect();
        let mut x = 0x2545f4914f6cdd1du64;
        for i in (1..n).rev() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            perm.swap(i, (x % (i as u64 + 1)) as usize);
        }
        check(
            n,
            faces.iter().map(|t| t.map(|v| perm[v as usize])).collect(),
        );
    }
}
