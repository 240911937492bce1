//! Independent checks of a `CanonicalCut`, shared by the cut tests (`#[path]`-included).
//! Everything is recomputed from the cut mesh and the loops' half-edges, not taken from the
//! polygon the library reports.
#![allow(dead_code)]

use ricci::cut::{intersection_matrix, CanonicalCut};
use ricci::mesh::{topology, Mesh};
use std::collections::HashMap;

pub fn meshes_dir() -> Option<std::path::PathBuf> {
    let p = ricci_meshes()?;
    if p.is_dir() {
        Some(p)
    } else {
        None
    }
}

/// The standard symplectic matrix, written out here independently of the library.
pub fn symplectic(g: usize) -> Vec<Vec<i64>> {
    (0..2 * g)
        .map(|i| {
            (0..2 * g)
                .map(|j| {
                    if i / 2 != j / 2 {
                        0
                    } else if i % 2 == 0 && j == i + 1 {
                        1
                    } else if i % 2 == 1 && j + 1 == i {
                        -1
                    } else {
                        0
                    }
                })
                .collect()
        })
        .collect()
}

/// The expected canonical word.
pub fn canonical_word(g: usize, nb: usize, closed_genus0: bool) -> String {
    let mut w = Vec::new();
    for i in 1..=g {
        w.push(format!("a{i} b{i} a{i}^-1 b{i}^-1"));
    }
    for k in 1..=nb {
        w.push(format!("c{k} d{k} c{k}^-1"));
    }
    if closed_genus0 {
        w.push("c1 c1^-1".into());
    }
    w.join(" ")
}

/// Read the boundary word of the cut mesh from scratch: walk its single boundary loop, map
/// every half-edge to the loop (by its edge in the refined mesh) and its direction, split at
/// changes of loop and at copies of the base vertex.
pub fn read_word(c: &CanonicalCut) -> Vec<String> {
    let m: &Mesh = &c.refined.mesh;
    let cm = &c.cut_mesh;
    let mut edge_loop: HashMap<u32, (usize, u32)> = HashMap::new(); // edge → (loop, direction he)
    for (i, l) in c.loops.iter().enumerate() {
        for &h in &l.halfedges {
            let prev = edge_loop.insert(m.he_edge(h), (i, h));
            assert!(prev.is_none(), "loops share edge {}", m.he_edge(h));
        }
    }
    let loops = cm.boundary_loop_halfedges();
    assert_eq!(loops.len(), 1);
    let lp = &loops[0];
    // Start right after a copy of the base vertex (or anywhere if none).
    let start = lp
        .iter()
        .position(|&h| c.cut_vertex_origin[cm.he_origin(h) as usize] == c.base)
        .unwrap_or(0);
    let mut out: Vec<String> = Vec::new();
    let mut cur: Option<(String, bool)> = None;
    let n = lp.len();
    for k in 0..n {
        let h = lp[(start + k) % n];
        let e = m.he_edge(h);
        let from = c.cut_vertex_origin[cm.he_origin(h) as usize];
        let at_corner = from == c.base
            || c.loops.iter().any(|l| {
                *l.vertices.last().unwrap() == from && *l.vertices.first().unwrap() != from
            });
        let (name, fwd) = match edge_loop.get(&e) {
            Some(&(i, lh)) => {
                // Same direction as the loop iff the cut-mesh half-edge starts where the
                // loop's half-edge starts.
                (c.loops[i].label.clone(), m.he_origin(lh) == from)
            }
            None => {
                assert!(
                    m.is_boundary_edge(e),
                    "boundary of the cut mesh on uncut edge {e}"
                );
                ("d".to_string(), true)
            }
        };
        let new_side = match &cur {
            None => true,
            Some((cn, cf)) => at_corner || *cn != name || *cf != fwd,
        };
        if new_side {
            if let Some((cn, cf)) = cur.take() {
                out.push(if cf { cn } else { format!("{cn}^-1") });
            }
            cur = Some((name, fwd));
        }
    }
    if let Some((cn, cf)) = cur {
        out.push(if cf { cn } else { format!("{cn}^-1") });
    }
    out
}

/// All the acceptance checks for a cut of a surface of genus `g` with `nb` boundary loops.
pub fn verify(c: &CanonicalCut, g: usize, nb: usize, what: &str) {
    assert_eq!(c.genus, g, "{what}: genus");
    // The cut mesh is a disk.
    let t = topology(&c.cut_mesh);
    assert_eq!(t.components.len(), 1, "{what}: components");
    assert_eq!(t.euler_characteristic(), 1, "{what}: χ of the cut mesh");
    assert_eq!(
        t.boundary_loops(),
        1,
        "{what}: boundary loops of the cut mesh"
    );
    // Faces of the cut mesh are the refined faces with copied vertices.
    for f in 0..c.cut_mesh.n_faces() as u32 {
        let cf = c.cut_mesh.face(f).map(|v| c.cut_vertex_origin[v as usize]);
        assert_eq!(cf, c.refined.mesh.face(f), "{what}: face {f}");
    }
    // Loops: simple, through the base vertex, meeting only there.
    let mut owner: HashMap<u32, usize> = HashMap::new();
    for (i, l) in c.loops.iter().enumerate() {
        assert_eq!(
            l.vertices[0], c.base,
            "{what}: {} starts at the base",
            l.label
        );
        let inner: &[u32] = if i < 2 * g {
            assert_eq!(
                *l.vertices.last().unwrap(),
                c.base,
                "{what}: {} is closed",
                l.label
            );
            &l.vertices[1..l.vertices.len() - 1]
        } else {
            &l.vertices[1..]
        };
        for &v in inner {
            assert!(
                owner.insert(v, i).is_none(),
                "{what}: vertex {v} is on two loops"
            );
        }
    }
    // The word read from the cut mesh is canonical, and so is the reported one.
    let closed0 = g == 0 && nb == 0;
    let word = read_word(c).join(" ");
    let expected = if g == 0 && nb == 1 {
        "d".to_string()
    } else {
        canonical_word(g, if g > 0 || nb >= 2 { nb } else { 0 }, closed0)
    };
    let normalized: String = if g == 0 && nb == 1 {
        word.clone()
    } else {
        // Boundary pieces are read as "d"; number them as in the expected word.
        let mut k = 0;
        word.split(' ')
            .map(|s| {
                if s == "d" {
                    k += 1;
                    format!("d{k}")
                } else {
                    s.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    // The read word may start at any corner: compare cyclically.
    let ws: Vec<&str> = normalized.split(' ').collect();
    let es: Vec<&str> = expected.split(' ').collect();
    assert_eq!(
        ws.len(),
        es.len(),
        "{what}: word {normalized} vs {expected}"
    );
    let ok = (0..ws.len()).any(|r| (0..ws.len()).all(|i| ws[(r + i) % ws.len()] == es[i]));
    assert!(
        ok,
        "{what}: word read from the cut mesh {normalized}, expected {expected}"
    );
    let reported = if g == 0 && nb == 1 {
        "d1".to_string()
    } else {
        expected.clone()
    };
    assert_eq!(c.boundary_word, reported, "{what}: reported word");
    assert_eq!(c.polygon.len(), es.len(), "{what}: polygon sides");
    // Intersection matrix by the push-off formula.
    let gens: Vec<Vec<u32>> = c.loops[..2 * g]
        .iter()
        .map(|l| l.halfedges.clone())
        .collect();
    let j = intersection_matrix(&c.refined.mesh, &gens).unwrap();
    assert_eq!(j, symplectic(g), "{what}: intersection matrix");
}

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;
use ricci_meshes::ricci_meshes;
