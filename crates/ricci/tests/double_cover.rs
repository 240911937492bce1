//! `mesh::double_cover`: the double of a surface with boundary (its mirror copy glued along
//! the boundary). Checked against topology computed independently (`mesh::topology` on the
//! result): closed, connected, `χ(D) = 2χ(M)`, genus `2g + b − 1`; `σ` an involution fixing
//! exactly the boundary vertices of `M`, mapping every face of `D` to a face with the opposite
//! orientation; every edge of `D` a copy of an edge of `M` (same endpoints up to `σ`).

use ricci::mesh::double::{double_edge_origin, double_vertex_origin};
use ricci::mesh::{double_cover, generate, topology, Mesh};
use std::collections::HashSet;

fn check_double(name: &str, m: &Mesh) {
    let (d, sigma) = double_cover(m).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (tm, td) = (topology(m), topology(&d));
    assert_eq!(tm.components.len(), 1, "{name}");
    let b = tm.boundary_loops() as i64;
    assert!(b > 0, "{name}");
    // Closed, connected, χ(D) = 2χ(M), genus 2g + b − 1.
    assert!(!d.has_boundary(), "{name}: the double has a boundary");
    assert_eq!(td.components.len(), 1, "{name}");
    assert_eq!(td.boundary_loops(), 0, "{name}");
    assert_eq!(
        td.euler_characteristic(),
        2 * tm.euler_characteristic(),
        "{name}"
    );
    assert_eq!(td.genus(), 2 * tm.genus() + b - 1, "{name}");
    // Counts: V_D = 2V − V_∂, F_D = 2F.
    let nb = (0..m.n_vertices() as u32)
        .filter(|&v| m.is_boundary_vertex(v))
        .count();
    assert_eq!(d.n_vertices(), 2 * m.n_vertices() - nb, "{name}");
    assert_eq!(d.n_faces(), 2 * m.n_faces(), "{name}");
    // σ is an involution fixing exactly the boundary vertices of M; M's vertices keep their ids.
    assert_eq!(sigma.len(), d.n_vertices(), "{name}");
    for v in 0..d.n_vertices() as u32 {
        let s = sigma[v as usize];
        assert_eq!(sigma[s as usize], v, "{name}: σ(σ({v})) ≠ {v}");
        let fixed = s == v;
        let on_boundary = (v as usize) < m.n_vertices() && m.is_boundary_vertex(v);
        assert_eq!(fixed, on_boundary, "{name}: vertex {v}");
        assert!((double_vertex_origin(&sigma, v) as usize) < m.n_vertices());
    }
    for f in 0..m.n_faces() as u32 {
        assert_eq!(d.face(f), m.face(f), "{name}: face {f}");
    }
    // σ maps faces to faces with the opposite orientation (as cyclic triples).
    let oriented: HashSet<[u32; 3]> = d.faces().iter().map(|&t| canonical(t)).collect();
    for &[a, b, c] in d.faces() {
        let s = |v: u32| sigma[v as usize];
        let mirrored = canonical([s(a), s(c), s(b)]);
        assert!(
            oriented.contains(&mirrored),
            "{name}: σ of face {a},{b},{c} reversed is not a face"
        );
        assert!(!oriented.contains(&canonical([s(a), s(b), s(c)])));
    }
    // Every edge of D is a copy of an edge of M with the same endpoints up to σ; boundary edges
    // of M appear once, interior edges twice.
    let origin = double_edge_origin(m, &d, &sigma).unwrap();
    let mut count = vec![0usize; m.n_edges()];
    for (e, &o) in origin.iter().enumerate() {
        let mut want = m.edge_vertices(o);
        let mut got = d
            .edge_vertices(e as u32)
            .map(|v| double_vertex_origin(&sigma, v));
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want, "{name}: edge {e}");
        count[o as usize] += 1;
    }
    for e in 0..m.n_edges() as u32 {
        let want = if m.is_boundary_edge(e) { 1 } else { 2 };
        assert_eq!(count[e as usize], want, "{name}: edge {e} of M");
    }
}

fn canonical(t: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&i| t[i]).unwrap();
    [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
}

#[test]
fn double_of_a_disk_is_a_sphere() {
    let s = generate::disk(16).unwrap();
    check_double("disk", &s.mesh);
}

#[test]
fn double_of_an_annulus_is_a_torus() {
    let s = generate::annulus(0.4, 1.0, 24).unwrap();
    check_double("annulus", &s.mesh);
}

#[test]
fn double_of_a_pair_of_pants_has_genus_two() {
    // The generator joins boundary vertices by interior edges: refused as it is, accepted
    // after a midpoint subdivision (which puts an interior vertex on every such edge).
    let s = generate::pair_of_pants(24).unwrap();
    assert!(double_cover(&s.mesh).is_err());
    let s = generate::midpoint_subdivision(&s).unwrap();
    check_double("pants", &s.mesh);
}

#[test]
fn double_of_a_disk_with_split_boundary_faces() {
    let s = generate::disk(16).unwrap();
    let s = generate::random_face_splits(&s, 0.5, 7).unwrap();
    check_double("split disk", &s.mesh);
}

/// A square cut by a diagonal: the diagonal joins two boundary vertices through the interior,
/// so the double would have two edges between them; refused with a sentence naming it.
#[test]
fn interior_edge_between_boundary_vertices_is_refused() {
    let m = Mesh::from_triangles(4, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
    let e = double_cover(&m).unwrap_err().to_string();
    assert!(
        e.contains("boundary vertices 0 and 2"),
        "unexpected message: {e}"
    );
    let closed = generate::icosphere(1).unwrap();
    assert!(double_cover(&closed.mesh).is_err());
}
