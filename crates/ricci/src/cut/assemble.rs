//! The canonical cut assembled from its raw paths (paper 001 App. A, 002 §6.2.2.1): slice the
//! refined mesh along them into a disk, read the fundamental polygon's sides from the cut
//! mesh, find the rotation of the side sequence that reads canonically
//! (`a₁ b₁ a₁⁻¹ b₁⁻¹ … c₁ d₁ c₁⁻¹ …`), label the loops and sides, and check the intersection
//! matrix of the loops against the standard symplectic one.

use super::slice::{self, slice, RawSide};
use super::system::{RawKind, RawPath};
use super::{halfedge_path, Side};
use super::{paths, standard_symplectic, CanonicalCut, CutReport, Generator, Loop, SearchStats};
use crate::error::{Error, Result};
use crate::mesh::{topology, Mesh, NONE};
use crate::metric::refine::Refined;
use crate::metric::Geometry;

/// Slice along the raw paths, read the polygon from the cut mesh, label and check it.
pub(super) fn assemble(
    refined: Refined,
    raw: Vec<RawPath>,
    base: u32,
    genus: usize,
    geometry: Geometry,
) -> Result<CanonicalCut> {
    let mesh = &refined.mesh;
    let np = raw.len() as u32;
    let cuts = cut_edges(mesh, &raw, base)?;
    let (cut_mesh, origin) = slice(mesh, &cuts.cut)?;
    let ct = topology(&cut_mesh);
    if !(ct.components.len() == 1 && ct.euler_characteristic() == 1 && ct.boundary_loops() == 1) {
        return Err(Error::numerical(format!(
            "internal error: the cut mesh is not a disk (χ = {}, {} boundary loops, {} components)",
            ct.euler_characteristic(),
            ct.boundary_loops(),
            ct.components.len()
        )));
    }
    let raw_sides = slice::read_sides(mesh, &cut_mesh, &origin, &cuts.corner, &cuts.edge_source)?;
    let src_dir = side_directions(&raw_sides, &raw, np)?;
    let parsed = parse_word(&src_dir, &raw, np).ok_or_else(|| {
        let w: Vec<String> = src_dir
            .iter()
            .map(|&(s, f)| format!("{s}{}", if f { "" } else { "'" }))
            .collect();
        Error::numerical(format!(
            "internal error: the cut polygon is not canonical (sides by path: {})",
            w.join(" ")
        ))
    })?;
    let (loops, loop_of_path) = labelled_loops(&refined, &raw, &parsed)?;
    let polygon = polygon_sides(mesh, &cut_mesh, &raw_sides, &parsed, &loop_of_path, np);
    let boundary_word = polygon
        .iter()
        .map(|s| s.label.as_str())
        .collect::<Vec<_>>()
        .join(" ");
    let mut side_of_halfedge = vec![NONE; cut_mesh.n_corners()];
    for (i, s) in polygon.iter().enumerate() {
        for &h in &s.halfedges {
            side_of_halfedge[h as usize] = i as u32;
        }
    }
    let gens: Vec<Vec<u32>> = loops[..2 * genus]
        .iter()
        .map(|l| l.halfedges.clone())
        .collect();
    let intersection_matrix = paths::intersection_matrix(mesh, &gens)?;
    if intersection_matrix != standard_symplectic(genus) {
        return Err(Error::numerical(format!(
            "internal error: the intersection matrix of the loops is not the standard symplectic one: {intersection_matrix:?}"
        )));
    }
    Ok(CanonicalCut {
        geometry,
        genus,
        boundary_loops: cuts.boundary_loops,
        base,
        refined,
        loops,
        cut_mesh,
        cut_vertex_origin: origin,
        polygon,
        boundary_word,
        intersection_matrix,
        report: CutReport {
            base_vertex: base,
            base_automatic: false,
            valence_before: 0,
            valence_after: 0,
            min_valence: 0,
            refinement_splits: 0,
            attempts: 0,
            failed_attempts: Vec::new(),
            search: SearchStats::default(),
            seconds: 0.0,
        },
        side_of_halfedge,
    })
}

/// The edges cut along the raw paths and what the polygon's sides are read from.
struct Cuts {
    /// Whether each edge is cut (each is used by one path at most).
    cut: Vec<bool>,
    /// The path every cut edge lies on (from `np` on: the boundary loop of a boundary edge).
    edge_source: Vec<u32>,
    /// The corners of the polygon: ends of the paths and the base vertex.
    corner: Vec<bool>,
    boundary_loops: usize,
}

fn cut_edges(mesh: &Mesh, raw: &[RawPath], base: u32) -> Result<Cuts> {
    let np = raw.len() as u32;
    let mut edge_source = vec![NONE; mesh.n_edges()];
    let mut cut = vec![false; mesh.n_edges()];
    let mut corner = vec![false; mesh.n_vertices()];
    for (p, r) in raw.iter().enumerate() {
        for h in halfedge_path(mesh, &r.vertices)? {
            let e = mesh.he_edge(h) as usize;
            if cut[e] {
                return Err(Error::numerical(format!(
                    "internal error: cut edge {e} is used twice"
                )));
            }
            cut[e] = true;
            edge_source[e] = p as u32;
        }
        corner[r.vertices[0] as usize] = true;
        corner[*r.vertices.last().unwrap_or(&base) as usize] = true;
    }
    corner[base as usize] = true;
    let bloops = mesh.boundary_loop_halfedges();
    for (k, l) in bloops.iter().enumerate() {
        for &h in l {
            edge_source[mesh.he_edge(h) as usize] = np + k as u32;
        }
    }
    Ok(Cuts {
        cut,
        edge_source,
        corner,
        boundary_loops: bloops.len(),
    })
}

/// The path of every side and whether the side runs along it (boundary loops: forward).
fn side_directions(raw_sides: &[RawSide], raw: &[RawPath], np: u32) -> Result<Vec<(u32, bool)>> {
    let mut src_dir: Vec<(u32, bool)> = Vec::with_capacity(raw_sides.len());
    for s in raw_sides {
        if s.source >= np {
            src_dir.push((s.source, true));
            continue;
        }
        let pv = &raw[s.source as usize].vertices;
        let fwd = s.vertices == *pv;
        let bwd = s.vertices.iter().rev().eq(pv.iter());
        if !(fwd || bwd) {
            return Err(Error::numerical(format!(
                "internal error: a side of the cut polygon covers only part of path {}",
                s.source
            )));
        }
        src_dir.push((s.source, fwd));
    }
    Ok(src_dir)
}

/// The loops in the order `a₁ b₁ … a_g b_g c₁ … c_b`, and the loop index of every path.
fn labelled_loops(
    refined: &Refined,
    raw: &[RawPath],
    parsed: &Parsed,
) -> Result<(Vec<Loop>, Vec<usize>)> {
    let mesh = &refined.mesh;
    let mut loops: Vec<Loop> = Vec::new();
    let mut loop_of_path = vec![usize::MAX; raw.len()];
    for &(path, gen, fwd) in &parsed.loops {
        let mut vertices = raw[path as usize].vertices.clone();
        if !fwd {
            vertices.reverse();
        }
        let halfedges = halfedge_path(mesh, &vertices)?;
        let length = halfedges
            .iter()
            .map(|&h| refined.lengths[mesh.he_edge(h) as usize])
            .sum();
        loop_of_path[path as usize] = loops.len();
        loops.push(Loop {
            label: gen.name(),
            generator: gen,
            vertices,
            halfedges,
            length,
        });
    }
    Ok((loops, loop_of_path))
}

/// The labelled sides in boundary order from the canonical rotation, with their partners.
fn polygon_sides(
    mesh: &Mesh,
    cut_mesh: &Mesh,
    raw_sides: &[RawSide],
    parsed: &Parsed,
    loop_of_path: &[usize],
    np: u32,
) -> Vec<Side> {
    let n = raw_sides.len();
    let mut polygon: Vec<Side> = Vec::with_capacity(n);
    for k in 0..n {
        let i = (parsed.rotation + k) % n;
        let s = &raw_sides[i];
        let (gen, inverse) = parsed.side_labels[i];
        let label = if inverse {
            format!("{}^-1", gen.name())
        } else {
            gen.name()
        };
        let vertices = s
            .halfedges
            .iter()
            .map(|&h| cut_mesh.he_origin(h))
            .chain(s.halfedges.last().map(|&h| cut_mesh.he_tip(h)))
            .collect();
        polygon.push(Side {
            label,
            generator: gen,
            inverse,
            edges: s.halfedges.iter().map(|&h| mesh.he_edge(h)).collect(),
            halfedges: s.halfedges.clone(),
            vertices,
            partner: None,
            loop_index: if s.source < np {
                Some(loop_of_path[s.source as usize])
            } else {
                None
            },
        });
    }
    for i in 0..n {
        if let Some(l) = polygon[i].loop_index {
            polygon[i].partner = (0..n).find(|&j| j != i && polygon[j].loop_index == Some(l));
        }
    }
    polygon
}

struct Parsed {
    /// Index of the side that becomes `polygon[0]`.
    rotation: usize,
    /// Label of every raw side.
    side_labels: Vec<(Generator, bool)>,
    /// (path, generator, path read forward) in output order.
    loops: Vec<(u32, Generator, bool)>,
}

/// Find the rotation of the side sequence that reads canonically and label it.
fn parse_word(sides: &[(u32, bool)], raw: &[RawPath], np: u32) -> Option<Parsed> {
    let n = sides.len();
    'rot: for r in 0..n {
        let at = |k: usize| sides[(r + k) % n];
        let mut labels = vec![(Generator::Slit, false); n];
        let mut loops = Vec::new();
        let mut k = 0;
        let (mut handles, mut conns) = (0usize, 0usize);
        while k < n {
            let (s0, f0) = at(k);
            if s0 >= np {
                // A bare boundary side: only a disk without cuts reads like that.
                if n == 1 {
                    labels[(r + k) % n] = (Generator::D { boundary: 1 }, false);
                    k += 1;
                    continue;
                }
                continue 'rot;
            }
            match raw[s0 as usize].kind {
                RawKind::Handle { .. } => {
                    if conns > 0 || k + 4 > n {
                        continue 'rot;
                    }
                    let (s1, f1) = at(k + 1);
                    let (s2, f2) = at(k + 2);
                    let (s3, f3) = at(k + 3);
                    if s1 >= np || !matches!(raw[s1 as usize].kind, RawKind::Handle { .. }) {
                        continue 'rot;
                    }
                    if !(s1 != s0 && s2 == s0 && s3 == s1 && f2 != f0 && f3 != f1) {
                        continue 'rot;
                    }
                    handles += 1;
                    let (ga, gb) = (
                        Generator::A { handle: handles },
                        Generator::B { handle: handles },
                    );
                    labels[(r + k) % n] = (ga, false);
                    labels[(r + k + 1) % n] = (gb, false);
                    labels[(r + k + 2) % n] = (ga, true);
                    labels[(r + k + 3) % n] = (gb, true);
                    loops.push((s0, ga, f0));
                    loops.push((s1, gb, f1));
                    k += 4;
                }
                RawKind::Connector { .. } => {
                    if k + 3 > n {
                        continue 'rot;
                    }
                    let (s1, _) = at(k + 1);
                    let (s2, f2) = at(k + 2);
                    if !(s1 >= np && s2 == s0 && f2 != f0) {
                        continue 'rot;
                    }
                    conns += 1;
                    let gc = Generator::C { boundary: conns };
                    labels[(r + k) % n] = (gc, false);
                    labels[(r + k + 1) % n] = (Generator::D { boundary: conns }, false);
                    labels[(r + k + 2) % n] = (gc, true);
                    loops.push((s0, gc, f0));
                    k += 3;
                }
                RawKind::Slit => {
                    if n != 2 {
                        continue 'rot;
                    }
                    let (s1, f1) = at(1);
                    if !(s1 == s0 && f1 != f0) {
                        continue 'rot;
                    }
                    labels[r % n] = (Generator::Slit, false);
                    labels[(r + 1) % n] = (Generator::Slit, true);
                    loops.push((s0, Generator::Slit, f0));
                    k += 2;
                }
            }
        }
        return Some(Parsed {
            rotation: r,
            side_labels: labels,
            loops,
        });
    }
    None
}
