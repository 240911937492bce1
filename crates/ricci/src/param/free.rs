//! Free homology seams (`ricci param --seams free`, module docs of [`super`]): a closed
//! component of genus ≥ 1 is cut along a system of `2g` loops through the homology generators
//! (the cut graph of [`super::seams`] with no cones) into a disk, and the disk is flattened with
//! `u = 0` on its boundary — the "minimal area distortion" boundary of Boundary First
//! Flattening (Sawhney–Crane 2017 §4.3) — and cones inside, placed by the greedy of
//! [`super::cones`] with the boundary held (Ben-Chen–Gotsman–Bunin 2008: BFF's cone positions
//! on such surfaces), with the curvatures of least linearised σ(2u) at those positions
//! ([`super::cones::free_boundary_least_squares`]; [`super::ParamOptions::free_cone_rule`]
//! `Dirichlet` keeps the greedy's own, `u = 0` at the cones, BFF's rule). The flat metric is flat at every interior vertex of the disk
//! except the cones; the seam vertices keep whatever curvature the boundary condition leaves, so
//! the transition across a homology seam is not a rigid motion (the two sides have equal edge
//! lengths, `u = 0` on both, but different turning). Cone seams (cut from each cone to the
//! disk's boundary for the layout) stay rigid. The sum of the cone curvatures is then free
//! (no Gauss–Bonnet constraint on the cones alone); the disk's boundary turns by
//! `2π − Σ K̄_cones` in total.

use super::cones::{free_boundary_cones, ConeBudget};
use super::{ConeSpec, ParamOptions, Piece};
use crate::error::{Error, Result};
use crate::flow::TargetSpec;
use crate::mesh::{topology, Surface, NONE};
use crate::metric::IntrinsicMetric;
use crate::progress::Progress;
use std::collections::HashMap;
use std::f64::consts::PI;

/// A closed component cut open along its homology generators.
pub(super) struct HomologyDisk {
    /// The disk as a piece: `vertices` map disk vertices to **input** vertices; disk vertex
    /// `i < n` is a copy of piece vertex `i` (the seam's extra copies follow); faces are the
    /// piece's faces in the same order.
    pub piece: Piece,
    /// Disk vertex → piece vertex.
    pub to_piece: Vec<u32>,
}

/// Cut `piece` (closed, genus ≥ 1) along the shortest system of homology loops into a disk.
pub(super) fn homology_disk(piece: &Piece, component: usize) -> Result<HomologyDisk> {
    let s = &piece.surface;
    let mesh = &s.mesh;
    let n = mesh.n_vertices();
    let lengths = s.edge_lengths();
    let cut = super::seams::cut_graph(mesh, &lengths, &vec![true; mesh.n_edges()], &[])?;
    let mut on_cut = vec![false; n];
    for e in 0..mesh.n_edges() as u32 {
        if cut[e as usize] {
            let [a, b] = mesh.edge_vertices(e);
            on_cut[a as usize] = true;
            on_cut[b as usize] = true;
        }
    }
    let mut first_key = vec![NONE; n];
    let mut copies: HashMap<(u32, u32), u32> = HashMap::new();
    let mut to_piece: Vec<u32> = (0..n as u32).collect();
    let mut tris = Vec::with_capacity(mesh.n_faces());
    for f in 0..mesh.n_faces() as u32 {
        let t = mesh.face(f);
        let hs = mesh.face_halfedges(f);
        let mut o = t;
        for i in 0..3 {
            let v = t[i];
            if !on_cut[v as usize] {
                continue;
            }
            // Half-edge 3f + i leaves t[i] inside face f: the corner's wedge.
            let key = super::seams::wedge_key(mesh, hs[i], &cut);
            if first_key[v as usize] == NONE || first_key[v as usize] == key {
                first_key[v as usize] = key;
                continue;
            }
            let id = *copies.entry((v, key)).or_insert_with(|| {
                to_piece.push(v);
                (to_piece.len() - 1) as u32
            });
            o[i] = id;
        }
        tris.push(o);
    }
    let positions = to_piece.iter().map(|&v| s.positions[v as usize]).collect();
    let surface = Surface::new(positions, tris)?;
    let topo = topology(&surface.mesh);
    if topo.components.len() != 1
        || topo.components[0].genus != 0
        || topo.components[0].boundary_loops != 1
    {
        return Err(Error::numerical(format!(
            "component {component}: cutting along the homology generators did not leave a disk"
        )));
    }
    Ok(HomologyDisk {
        piece: Piece {
            surface,
            vertices: to_piece
                .iter()
                .map(|&v| piece.vertices[v as usize])
                .collect(),
            faces: piece.faces.clone(),
        },
        to_piece,
    })
}

/// Cones of a chart (chart vertex ids), how they were chosen and the greedy's history.
pub(super) type FreePlan = (TargetSpec, Vec<(u32, f64)>, String, Vec<f64>);

/// Cones of the disk (disk vertex ids): given cones by input vertex (refused on a seam), or
/// the greedy with the seams held at `u = 0` ([`held_boundary_cones`]).
pub(super) fn free_seam_target(
    disk: &HomologyDisk,
    component: usize,
    genus: i64,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
) -> Result<FreePlan> {
    let spec = match &opts.cones {
        ConeSpec::Default if genus == 1 => ConeSpec::None,
        ConeSpec::Default => ConeSpec::Auto {
            max_area_distortion: 1.0,
        },
        c => c.clone(),
    };
    let on_seam = |v: u32| {
        Error::input(format!(
            "cone vertex {v} lies on a homology seam of component {component}; with \
             --seams free cones must lie off the seams (or use --seams rigid)"
        ))
    };
    held_boundary_cones(
        &disk.piece,
        disk.first_copy(),
        &spec,
        opts,
        progress,
        &on_seam,
        None,
    )
}

/// Cones inside a surface whose boundary is held at `u = 0` (`piece`: the disk of free seams,
/// or a component with boundary flattened with the free boundary, Sawhney–Crane 2017 §4.3 with
/// cones): given cones by input vertex among the piece's first `named` vertices (`on_boundary`
/// names the error of one on the boundary), or the greedy of Ben-Chen–Gotsman–Bunin with the
/// boundary held ([`free_boundary_cones`]) and the curvatures of
/// [`ParamOptions::free_cone_rule`] (least squares: the cones' linearised log scale at most
/// `ceiling` standard deviations above its mean when given,
/// [`super::cones::CONE_SCALE_CEILING`]). The target is `FreeBoundaryCones`; the source
/// `given`, `greedy` or `none`.
pub(super) fn held_boundary_cones(
    piece: &Piece,
    named: usize,
    spec: &ConeSpec,
    opts: &ParamOptions,
    progress: &mut dyn Progress,
    on_boundary: &dyn Fn(u32) -> Error,
    ceiling: Option<f64>,
) -> Result<FreePlan> {
    let mesh = &piece.surface.mesh;
    let budget = match spec {
        ConeSpec::Count(0) | ConeSpec::None | ConeSpec::Default => None,
        ConeSpec::Count(k) => Some(ConeBudget::Count(*k)),
        ConeSpec::Auto {
            max_area_distortion,
        } => Some(ConeBudget::AreaDistortion {
            bound: *max_area_distortion,
            max_cones: opts.max_cones,
        }),
        ConeSpec::Given(list) => {
            let mut cones = Vec::new();
            for &(v, k) in list {
                // Piece vertex l < named is the one of input vertex v.
                let Some(l) = piece.vertices[..named].iter().position(|&w| w == v) else {
                    continue;
                };
                if k.is_nan() || k >= 2.0 * PI {
                    return Err(Error::input(format!(
                        "cone at vertex {v}: curvature {k:.6} leaves no cone angle (it must be \
                         below 2π = {:.6})",
                        2.0 * PI
                    )));
                }
                if mesh.is_boundary_vertex(l as u32) {
                    return Err(on_boundary(v));
                }
                cones.push((l as u32, k));
            }
            let target = TargetSpec::FreeBoundaryCones(cones.clone());
            return Ok((target, cones, "given".into(), Vec::new()));
        }
    };
    let (cones, history) = match budget {
        Some(b) => {
            progress.report("cones", None, "greedy cone placement, boundary held");
            let lengths = piece.surface.edge_lengths();
            let metric = IntrinsicMetric::euclidean(lengths);
            // The greedy's positions; curvatures for the least linearised σ(2u) by default
            // (the greedy's own, u = 0 at the cones, are one candidate of that least-squares
            // problem, so this is never worse in the linear model).
            let p = free_boundary_cones(mesh, &metric, b, opts.free_cone_rule, ceiling)?;
            (p.cones, p.distortion_history)
        }
        None => (Vec::new(), Vec::new()),
    };
    let source = if budget.is_some() { "greedy" } else { "none" };
    Ok((
        TargetSpec::FreeBoundaryCones(cones.clone()),
        cones,
        source.into(),
        history,
    ))
}

impl HomologyDisk {
    /// Number of piece vertices (the disk's first copies).
    fn first_copy(&self) -> usize {
        self.to_piece
            .iter()
            .enumerate()
            .take_while(|&(i, &v)| i as u32 == v)
            .count()
    }

    /// The cut of the piece: the homology seams (the disk's boundary) and the disk's own cut
    /// edges (`cut`, from the cones to the boundary), as piece edges.
    pub fn lift_cut(&self, piece: &Piece, cut: &[bool]) -> Vec<bool> {
        let dm = &self.piece.surface.mesh;
        let pm = &piece.surface.mesh;
        let mut out = vec![false; pm.n_edges()];
        for e in 0..dm.n_edges() as u32 {
            if cut[e as usize] || dm.is_boundary_edge(e) {
                let [a, b] = dm.edge_vertices(e);
                let (a, b) = (self.to_piece[a as usize], self.to_piece[b as usize]);
                if let Some(h) = pm.halfedge_between(a, b) {
                    out[pm.he_edge(h) as usize] = true;
                }
            }
        }
        out
    }
}
