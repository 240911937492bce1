//! [`AffineAtlas::build`], stage by stage (paper 000 §4 Steps 1–5; see the module docs of
//! [`super`]): the cones (Step 1), the connectivity modification around them and the
//! canonical cut (Step 2, Step 4's cut), the flat metric (Step 3), the segmentation into a
//! disk with its central chart (Step 4–5), then the cover ([`super::cover`]).

use super::error::AtlasError;
use super::valence::{flip_ring_valence, raise_ring_valence, rings_around, RingValenceWork};
use super::{
    area_distortion, flat_flow, placement, AffineAtlas, AtlasOptions, AtlasReport, Chart,
    Placement, RefinementReport, Singularity,
};
use crate::cut::{canonical_cut, CanonicalCut, CutOptions};
use crate::error::{Error, Result};
use crate::flow::{FlowError, FlowResult, TargetSpec};
use crate::layout::place::layout;
use crate::mesh::{topology, Mesh, Surface, NONE};
use crate::metric::refine::{Refined, Refiner};
use crate::metric::{Euclidean, Geometry, IntrinsicMetric, Scheme};
use crate::progress::Progress;
use std::collections::HashSet;
use std::f64::consts::PI;
use std::time::Instant;

/// Step 1's outcome: the cones `(vertex, K̄)`, the name of the target and the automatic
/// placement when there was one.
struct Cones {
    cones: Vec<(u32, f64)>,
    target_name: &'static str,
    placement: Option<Placement>,
}

/// Step 2's outcome (with the canonical cut, which grades the mesh around its base): the
/// refined surface on which the flow runs.
struct Connectivity {
    cut: CanonicalCut,
    refined: Refined,
    /// For every refined face, the input face it lies in.
    face_origin: Vec<u32>,
    positions: Vec<[f64; 3]>,
    report: RefinementReport,
    /// Whether splits or flips after the cut changed the connectivity (the cut mesh must then
    /// be sliced again).
    reconnected: bool,
}

/// Step 3's outcome.
struct FlatMetric {
    flow: FlowResult,
    scheme: Scheme,
    notes: Vec<String>,
}

impl AffineAtlas {
    /// Build the atlas of a connected surface (see the module docs).
    pub fn build(
        surface: &Surface,
        options: &AtlasOptions,
        progress: &mut dyn Progress,
    ) -> Result<AffineAtlas> {
        let t0 = Instant::now();
        let mesh = &surface.mesh;
        let (genus, nb) = connected_topology(mesh)?;
        let lengths0 = IntrinsicMetric::euclidean(surface.edge_lengths());
        // Step 1: the cones.
        let Cones {
            cones,
            target_name,
            placement,
        } = choose_cones(surface, &lengths0, genus, nb, options, progress)?;
        // Step 2: valences around the cones, and the canonical cut.
        let conn = modify_connectivity(surface, &lengths0, &cones, options, progress)?;
        let rmesh = conn.refined.mesh.clone();
        // Step 3: the flat metric.
        let FlatMetric {
            flow,
            scheme: scheme_used,
            notes,
        } = flat_metric(
            &rmesh,
            &IntrinsicMetric::euclidean(conn.refined.lengths.clone()),
            &cones,
            target_name,
            options,
            progress,
        )?;
        let lengths = flow.lengths.clone();
        let area_distortion = area_distortion(
            &rmesh,
            &conn.refined.lengths,
            &lengths,
            &conn.face_origin,
            mesh.n_faces(),
        );
        // Segmentation and the central chart.
        let coords = central_chart(&rmesh, &lengths, &conn, &cones, progress)?;
        let singular: Vec<u32> = cones.iter().map(|c| c.0).collect();
        let Connectivity {
            cut,
            refined,
            face_origin,
            positions,
            report: rep,
            ..
        } = conn;
        let mut atlas = AffineAtlas {
            mesh: rmesh,
            lengths,
            positions,
            singular,
            charts: Vec::new(),
            face_charts: Vec::new(),
            home: Vec::new(),
            input_lengths: refined.lengths,
            original_vertices: mesh.n_vertices(),
            face_origin,
            report: AtlasReport {
                genus,
                boundary_loops: nb,
                target: target_name.to_string(),
                singular_vertices: cones.iter().map(|c| c.0).collect(),
                placement,
                refinement: rep,
                scheme: scheme_used.name().to_string(),
                flow_converged: flow.converged,
                flow_iterations: flow.iterations,
                max_curvature_error: flow.max_curvature_error,
                gauss_bonnet_error: flow.gauss_bonnet_error,
                area_distortion,
                charts: Vec::new(),
                flipped_faces: 0,
                max_length_error: 0.0,
                max_transition_error: 0.0,
                max_relative_transition_error: 0.0,
                local_charts: 0,
                max_home_conditioning: 0.0,
                seconds_local_charts: 0.0,
                faces_without_home: 0,
                boundary_word: cut.boundary_word.clone(),
                seconds: 0.0,
                notes,
            },
        };
        let nf = atlas.mesh.n_faces();
        atlas.face_charts = vec![Vec::new(); nf];
        atlas.home = vec![NONE; nf];
        atlas.push_chart(
            Chart {
                faces: (0..nf as u32).collect(),
                coords,
            },
            "central",
            0,
        );
        atlas.cover(progress)?;
        atlas.finish_report();
        atlas.report.seconds = t0.elapsed().as_secs_f64();
        progress.report("atlas", Some(1.0), "done");
        Ok(atlas)
    }
}

/// The genus and the number of boundary loops of a connected mesh without unused vertices.
fn connected_topology(mesh: &Mesh) -> Result<(i64, usize)> {
    let topo = topology(mesh);
    if topo.components.len() != 1 {
        return Err(Error::topology(format!(
            "an atlas needs a connected surface; this one has {} components",
            topo.components.len()
        )));
    }
    let comp = &topo.components[0];
    if comp.vertices != mesh.n_vertices() {
        return Err(Error::topology(format!(
            "the mesh has {} vertices not used by any face; remove them first",
            mesh.n_vertices() - comp.vertices
        )));
    }
    Ok((comp.genus, comp.boundary_loops))
}

/// Step 1: the cones of the flat target: the user's (checked against Gauss–Bonnet), none for
/// open surfaces and tori, one carrying `2πχ` for closed genus ≥ 2 (given or placed
/// automatically, [`placement`]).
fn choose_cones(
    surface: &Surface,
    lengths0: &IntrinsicMetric,
    genus: i64,
    nb: usize,
    options: &AtlasOptions,
    progress: &mut dyn Progress,
) -> Result<Cones> {
    let mesh = &surface.mesh;
    let chi = 2 - 2 * genus - nb as i64;
    let check_vertex = |vertex: u32, role: &'static str| -> Result<()> {
        if vertex as usize >= mesh.n_vertices() {
            let n_vertices = mesh.n_vertices();
            return Err(AtlasError::VertexMissing {
                role,
                vertex,
                n_vertices,
            }
            .into());
        }
        if mesh.is_boundary_vertex(vertex) {
            return Err(AtlasError::VertexOnBoundary { role, vertex }.into());
        }
        Ok(())
    };
    let mut placement = None;
    let (cones, target_name): (Vec<(u32, f64)>, &str) = if let Some(list) = &options.cones {
        if nb > 0 {
            return Err(Error::input(
                "cones are supported on closed surfaces only; an open surface gets the \
                 free-boundary flat metric with no singular point",
            ));
        }
        for &(v, k) in list {
            check_vertex(v, "cone")?;
            if !(k.is_finite() && k < 2.0 * PI) {
                let (vertex, curvature) = (v, k);
                return Err(AtlasError::NoConeAngle { vertex, curvature }.into());
            }
        }
        let sum: f64 = list.iter().map(|c| c.1).sum();
        if (sum - 2.0 * PI * chi as f64).abs() > 1e-9 {
            let euler_characteristic = chi;
            return Err(AtlasError::GaussBonnet {
                sum,
                euler_characteristic,
            }
            .into());
        }
        let mut seen = HashSet::new();
        for &(v, _) in list {
            if !seen.insert(v) {
                return Err(AtlasError::ConeListedTwice { vertex: v }.into());
            }
        }
        let l: Vec<(u32, f64)> = list.iter().copied().filter(|c| c.1 != 0.0).collect();
        (l, "cones")
    } else if nb > 0 {
        if let Singularity::Vertex(vertex) = options.singularity {
            let genus_one = false;
            return Err(AtlasError::SingularVertexNotNeeded { vertex, genus_one }.into());
        }
        (Vec::new(), "free-boundary")
    } else if genus == 1 {
        if let Singularity::Vertex(vertex) = options.singularity {
            let genus_one = true;
            return Err(AtlasError::SingularVertexNotNeeded { vertex, genus_one }.into());
        }
        (Vec::new(), "uniform")
    } else if genus == 0 {
        return Err(Error::topology(
            "a closed genus-0 surface has no flat metric with a single cone (it would need \
             K̄ = 4π > 2π); give several cones with --cones (e.g. eight of π/2)",
        ));
    } else {
        let kappa = 2.0 * PI * chi as f64;
        let v = match options.singularity {
            Singularity::Vertex(v) => {
                check_vertex(v, "singular")?;
                v
            }
            Singularity::Auto => {
                progress.report("placement", Some(0.0), "ranking candidate vertices");
                let p = placement::place(surface, lengths0, options, progress)?;
                let v = p.chosen;
                placement = Some(p);
                v
            }
        };
        (vec![(v, kappa)], "single-cone")
    };
    Ok(Cones {
        cones,
        target_name,
        placement,
    })
}

/// Step 2 with the canonical cut: raise the cones' valences to `⌈4 − 2K̄/π⌉`, cut (which
/// grades the cut's base), then give the vertices within `options.rings` rings of a cone
/// valence ≥ 6 (splits of the one-ring's outer links, then flips and splits,
/// [`raise_ring_valence`], [`flip_ring_valence`]) off the cut loops.
fn modify_connectivity(
    surface: &Surface,
    lengths0: &[f64],
    cones: &[(u32, f64)],
    options: &AtlasOptions,
    progress: &mut dyn Progress,
) -> Result<Connectivity> {
    let mesh = &surface.mesh;
    progress.report("refine", Some(0.0), "connectivity modification");
    let mut rep = RefinementReport {
        vertices_before: mesh.n_vertices(),
        ..RefinementReport::default()
    };
    let mut r = Refiner::new(
        mesh,
        lengths0,
        Geometry::Euclidean,
        Some(&surface.positions),
    )?;
    rep.low_valence_before = rings_around(mesh, cones, options.rings)
        .iter()
        .filter(|&&w| mesh.valence(w) < 6)
        .count();
    for &(v, k) in cones {
        let need = (4.0 - 2.0 * k / PI - 1e-9).ceil().max(3.0) as usize;
        let before = mesh.valence(v);
        r.raise_valence(v, need)?;
        rep.cone_valence.push((v, before, need, 0));
    }
    rep.splits_step2 = r.splits();
    let step2 = r.finish()?;
    // Step 4 (cut) before Step 3 (flow): the cut only needs connectivity, and refines
    // around its base; the flow then runs once on the final mesh.
    progress.report("cut", Some(0.0), "canonical cut");
    let cut = canonical_cut(
        &step2.mesh,
        &IntrinsicMetric::euclidean(step2.lengths.clone()),
        step2.positions.as_deref(),
        &CutOptions {
            base: cones.first().map(|c| c.0),
            ..CutOptions::default()
        },
        progress,
    )?;
    rep.splits_cut = cut.refined.splits();
    // Step 2 (ii) after the cut's grading (which splits link edges of the cone, creating
    // valence-4 neighbours): the one-ring neighbours of every cone get valence ≥ 6 by
    // splitting their outer link edges off the cut, so the loops stay edge paths.
    let mut on_cut = HashSet::new();
    for l in &cut.loops {
        for w in l.vertices.windows(2) {
            on_cut.insert((w[0].min(w[1]), w[0].max(w[1])));
        }
    }
    let (refined, ring_splits) = if options.rings > 0 && !cones.is_empty() {
        raise_ring_valence(cut.refined.clone(), cones, 6, &on_cut)?
    } else {
        (cut.refined.clone(), 0)
    };
    rep.splits_ring = ring_splits;
    // Step 2 (ii) within `rings` rings: intrinsic flips, and splits to make room.
    let (refined, ring_work) = if options.rings > 0 && !cones.is_empty() {
        let around = rings_around(&refined.mesh, cones, options.rings).len();
        flip_ring_valence(refined, cones, options.rings, &on_cut, 40 * around + 1000)?
    } else {
        (refined, RingValenceWork::default())
    };
    rep.flips_ring = ring_work.flips;
    rep.splits_ring_room = ring_work.splits;
    let rmesh = &refined.mesh;
    rep.vertices_after = rmesh.n_vertices();
    for (k, c) in cones.iter().enumerate() {
        rep.cone_valence[k].3 = rmesh.valence(c.0);
    }
    rep.low_valence_after = rings_around(rmesh, cones, options.rings)
        .iter()
        .filter(|&&w| rmesh.valence(w) < 6)
        .count();
    rep.low_valence_ring1_after = rings_around(rmesh, cones, 1)
        .iter()
        .filter(|&&w| rmesh.valence(w) < 6)
        .count();
    let positions = refined
        .positions
        .clone()
        .ok_or_else(|| Error::numerical("internal error: the cut lost the positions"))?;
    // Face origin in the input mesh: compose the two refinements.
    let face_origin: Vec<u32> = refined
        .face_origin
        .iter()
        .map(|&f| step2.face_origin[f as usize])
        .collect();
    Ok(Connectivity {
        cut,
        refined,
        face_origin,
        positions,
        report: rep,
        reconnected: ring_splits + ring_work.flips + ring_work.splits > 0,
    })
}

/// Step 3: the flat metric of the cone target on the refined mesh (`input` its R³ lengths),
/// with the scheme fallback of [`flat_flow`]; Thurston's refusal of a Chow–Luo bound is
/// retried with inversive distance.
fn flat_metric(
    rmesh: &Mesh,
    input: &IntrinsicMetric,
    cones: &[(u32, f64)],
    target_name: &str,
    options: &AtlasOptions,
    progress: &mut dyn Progress,
) -> Result<FlatMetric> {
    progress.report("flow", Some(0.0), "Euclidean Ricci flow");
    let target = match target_name {
        "free-boundary" => TargetSpec::FreeBoundary,
        "uniform" => TargetSpec::Uniform,
        _ => TargetSpec::Cones(cones.to_vec()),
    };
    let (flow, scheme, flow_notes) = match flat_flow(
        rmesh,
        input,
        target.clone(),
        options.scheme,
        options.tolerance,
    ) {
        // Thurston's Chow–Luo bound uses its clamped intersection angles φ ≤ π/2, so it
        // can refuse at a valence-4 vertex made by the refinement (all four φ = π/2, by
        // exactly 0) what the φ = 0 bound of inversive distance admits.
        // (The refusal is a `FlowError::ChowLuo` since the stage enums; matching the former
        // `Error::InvalidInput` left this fallback dead.)
        Err(e)
            if options.scheme == Scheme::Thurston
                && matches!(
                    e.stage_error::<FlowError>(),
                    Some(FlowError::ChowLuo { .. })
                ) =>
        {
            let message = e.to_string();
            let (f, s, mut n) =
                flat_flow(rmesh, input, target, Scheme::Inversive, options.tolerance)?;
            n.insert(
                0,
                format!(
                    "the thurston scheme refused the target ({message}); the metric comes \
                     from the {} scheme",
                    s.name()
                ),
            );
            (f, s, n)
        }
        other => other?,
    };
    let mut notes = flow_notes;
    if !flow.converged {
        notes.push(format!(
            "the Ricci flow did not converge: max |K − K̄| = {:.3e} > {:.1e} after {} \
             iterations; the charts are built from the metric reached",
            flow.max_curvature_error, options.tolerance, flow.iterations
        ));
    }
    Ok(FlatMetric {
        flow,
        scheme,
        notes,
    })
}

/// Steps 4–5: the segmentation (the canonical cut plus slits to the other cones) slices the
/// surface into a disk whose layout ([`layout`]) is the central chart; returns its corner
/// coordinates per face of `rmesh`.
fn central_chart(
    rmesh: &Mesh,
    lengths: &[f64],
    conn: &Connectivity,
    cones: &[(u32, f64)],
    progress: &mut dyn Progress,
) -> Result<Vec<[[f64; 2]; 3]>> {
    let cut = &conn.cut;
    let mut cut_edge = vec![false; rmesh.n_edges()];
    for l in &cut.loops {
        for w in l.vertices.windows(2) {
            let h = rmesh.halfedge_between(w[0], w[1]).ok_or_else(|| {
                Error::numerical(format!(
                    "internal error: loop {} lost its edge {}–{}",
                    l.label, w[0], w[1]
                ))
            })?;
            cut_edge[rmesh.he_edge(h) as usize] = true;
        }
    }
    if cones.len() > 1 {
        add_slits(rmesh, lengths, &mut cut_edge, &cones[1..])?;
    }
    let (disk, origin) = if cones.len() > 1 || conn.reconnected {
        crate::cut::slice(rmesh, &cut_edge)?
    } else {
        (cut.cut_mesh.clone(), cut.cut_vertex_origin.clone())
    };
    let mut dl = vec![0.0; disk.n_edges()];
    for h in 0..disk.n_corners() as u32 {
        dl[disk.he_edge(h) as usize] = lengths[rmesh.he_edge(h) as usize];
    }
    for f in 0..rmesh.n_faces() as u32 {
        let a = rmesh.face(f);
        let b = disk.face(f);
        if (0..3).any(|i| origin[b[i] as usize] != a[i]) {
            return Err(Error::numerical(format!(
                "internal error: face {f} of the cut mesh does not match the surface"
            )));
        }
    }
    progress.report("layout", Some(0.0), "central chart");
    let central = layout::<Euclidean>(&disk, &IntrinsicMetric::euclidean(dl), None)?;
    Ok((0..rmesh.n_faces() as u32)
        .map(|f| {
            let v = disk.face(f);
            let mut c = [[0.0; 2]; 3];
            for i in 0..3 {
                let p = central.positions[v[i] as usize];
                c[i] = [p.re, p.im];
            }
            c
        })
        .collect())
}

/// Add to `cut_edge` a shortest path (in `lengths`) from the current cut graph to every cone
/// in `others`, through vertices off the cut graph and off the boundary.
fn add_slits(
    mesh: &Mesh,
    lengths: &[f64],
    cut_edge: &mut [bool],
    others: &[(u32, f64)],
) -> Result<()> {
    use crate::numeric::dijkstra::{Dijkstra, NO_PRED};
    for &(target, _) in others {
        let nv = mesh.n_vertices();
        let mut on_cut = vec![false; nv];
        for (e, _) in cut_edge.iter().enumerate().filter(|x| *x.1) {
            {
                let [a, b] = mesh.edge_vertices(e as u32);
                on_cut[a as usize] = true;
                on_cut[b as usize] = true;
            }
        }
        if on_cut[target as usize] {
            continue;
        }
        let on_cut = &on_cut;
        let mut search = Dijkstra::new(nv);
        search.offer(target, 0.0, NO_PRED);
        let hit = search.run(
            |v| {
                mesh.outgoing(v).filter_map(move |h| {
                    let w = mesh.he_tip(h);
                    (!mesh.is_boundary_vertex(w) || on_cut[w as usize])
                        .then(|| (w, lengths[mesh.he_edge(h) as usize]))
                })
            },
            |_, v| on_cut[v as usize],
        );
        let Some(hit) = hit else {
            return Err(AtlasError::ConeNotJoined { vertex: target }.into());
        };
        let mut v = hit;
        while v != target {
            let p = search.pred(v);
            let h = mesh
                .halfedge_between(p, v)
                .ok_or_else(|| Error::numerical("internal error: slit path without an edge"))?;
            cut_edge[mesh.he_edge(h) as usize] = true;
            v = p;
        }
    }
    Ok(())
}
