//! The sphere of the conformal scheme (discrete conformal equivalence with intrinsic Delaunay
//! flips): [`conformal_sphere`] — the flat metric of the surface with one vertex at infinity,
//! stereographic projection and Möbius centring ([`mobius_centre`]); see the docs of
//! [`conformal_sphere`] for the algorithm (Gillespie–Springborn–Crane 2021 §4.3).

use super::solve3;
use crate::error::{Error, Result};
use crate::flow::target::Target;
use crate::mesh::{Mesh, NONE};
use crate::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use crate::metric::Geometry;
use crate::progress::Progress;
use std::f64::consts::PI;

/// What [`conformal_sphere`] produced: the final Delaunay triangulation (= the convex hull of
/// `positions`) with spherical log Penner coordinates, the points on the unit sphere and the
/// diagnostics of the construction.
#[derive(Debug, Clone)]
pub struct ConformalSphere {
    /// The final triangulation: the input's vertices, `flip_log` from the input mesh
    /// (isometric flips first, then Ptolemy flips), `lambda = 2 log sin(d/2) = 2 log(c/2)` of
    /// the spherical edge lengths `d` (chords `c` of the unit sphere).
    pub triangulation: IntrinsicTriangulation,
    /// Base log Penner coordinates (Euclidean, `2 log l`) of the input metric on the same
    /// (flipped) triangulation: `lambda − base_lambda = u_i + u_j` edge by edge.
    pub base_lambda: Vec<f64>,
    /// Points on the unit sphere per input vertex (Möbius-centred: the vertex-area centroid
    /// is the origin).
    pub positions: Vec<[f64; 3]>,
    /// The log scale factors: `sin(d_ij/2) = e^{(u_i+u_j)/2} l_ij` (`l` the input metric on the
    /// same edge, `d` the spherical length).
    pub u: Vec<f64>,
    /// `max_e |2 log(|x_i − x_j|/2) − λ_e|` — how well the points carry the metric (the
    /// metric itself is `λ = λ⁰ + u_i + u_j` by construction; this residual grows where the
    /// map shrinks parts of the surface to chords near double-precision resolution).
    pub conformal_residual: f64,
    /// The removed vertex (at the north pole before the Möbius centring).
    pub puncture: u32,
    /// Isometric flips to the input's intrinsic Delaunay triangulation.
    pub initial_flips: usize,
    /// Ptolemy flips of the planar solves (line-search trials included) and of the changes
    /// of the puncture's link.
    pub flips: usize,
    /// Newton iterations over all planar solves.
    pub iterations: usize,
    /// Planar solves (one per change of the link of the puncture).
    pub rounds: usize,
    /// Vertices of the final link of the puncture (the convex hull of the planar picture).
    pub link_vertices: usize,
    /// Largest `|K|` of the interior vertices of the flat picture.
    pub flat_error: f64,
    /// Largest boundary angle of the flat picture minus π (≤ 0: the hull is convex).
    pub convexity_excess: f64,
    /// Faces whose three points are not positively oriented (counter-clockwise seen from
    /// outside) on the sphere.
    pub inverted_faces: usize,
    pub history: Vec<crate::flow::IterationRecord>,
    pub notes: Vec<String>,
}

/// The disk of `t` without the star of `inf`: faces not incident to `inf`, the same vertex
/// ids, `lambda` scaled by `u` (baked in), boundary where a face of the star was; with the map
/// from its edge ids to those of `t`.
fn punctured_disk(
    t: &IntrinsicTriangulation,
    inf: u32,
    u: &[f64],
) -> (IntrinsicTriangulation, Vec<u32>) {
    let nf = t.n_faces();
    let mut face_new = vec![NONE; nf];
    let mut kept = 0u32;
    for f in 0..nf as u32 {
        if !t.face(f).contains(&inf) {
            face_new[f as usize] = kept;
            kept += 1;
        }
    }
    let mut edge_new = vec![NONE; t.n_edges()];
    let mut d2t = Vec::new();
    let nh = 3 * kept as usize;
    let mut origin = vec![0u32; nh];
    let mut twin = vec![NONE; nh];
    let mut edge = vec![0u32; nh];
    for f in 0..nf {
        let g = face_new[f];
        if g == NONE {
            continue;
        }
        for i in 0..3 {
            let h = 3 * f + i;
            let hn = 3 * g as usize + i;
            origin[hn] = t.origin[h];
            let tw = t.twin[h];
            if tw != NONE && face_new[tw as usize / 3] != NONE {
                twin[hn] = 3 * face_new[tw as usize / 3] + tw % 3;
            }
            let e = t.edge[h] as usize;
            if edge_new[e] == NONE {
                edge_new[e] = d2t.len() as u32;
                d2t.push(e as u32);
            }
            edge[hn] = edge_new[e];
        }
    }
    let mut edge_he = vec![NONE; d2t.len()];
    for h in 0..nh {
        if edge_he[edge[h] as usize] == NONE {
            edge_he[edge[h] as usize] = h as u32;
        }
    }
    let mut boundary_vertex = vec![false; t.n_vertices];
    for h in 0..nh {
        if twin[h] == NONE {
            boundary_vertex[origin[h] as usize] = true;
        }
    }
    let lambda: Vec<f64> = d2t
        .iter()
        .map(|&e| {
            let [a, b] = t.edge_vertices(e);
            t.lambda[e as usize] + u[a as usize] + u[b as usize]
        })
        .collect();
    let disk = IntrinsicTriangulation {
        n_vertices: t.n_vertices,
        origin,
        twin,
        edge,
        edge_he,
        lambda,
        boundary_vertex,
        flip_log: Vec::new(),
    };
    (disk, d2t)
}

/// The edges of `t` joining `inf` to `j` (`j ≠ inf`).
fn edges_between(t: &IntrinsicTriangulation, inf: u32, j: u32) -> Vec<u32> {
    let mut out = Vec::new();
    for h in 0..t.n_halfedges() as u32 {
        if t.origin[h as usize] == inf && t.tip(h) == j {
            let e = t.edge[h as usize];
            if !out.contains(&e) {
                out.push(e);
            }
        }
    }
    out
}

/// The link of `inf` in `t`: its neighbours, and whether it is simple (no self-loop at
/// `inf`, every neighbour joined by one edge).
fn link_of(t: &IntrinsicTriangulation, inf: u32) -> (Vec<u32>, bool) {
    let mut link = Vec::new();
    let mut simple = true;
    for h in 0..t.n_halfedges() as u32 {
        if t.origin[h as usize] == inf {
            let j = t.tip(h);
            if j == inf || link.contains(&j) {
                simple = false;
            } else {
                link.push(j);
            }
        }
    }
    (link, simple)
}

/// For every vertex, whether its link in `t` is simple (as [`link_of`], for all vertices at
/// once: the pairs (origin, tip) of all half-edges, sorted, have no repeat and no loop).
fn simple_links(t: &IntrinsicTriangulation, n: usize) -> Vec<bool> {
    let mut simple = vec![true; n];
    let mut pairs: Vec<(u32, u32)> = (0..t.n_halfedges() as u32)
        .map(|h| (t.origin[h as usize], t.tip(h)))
        .collect();
    pairs.sort_unstable();
    for (k, &(v, j)) in pairs.iter().enumerate() {
        if v == j || (k > 0 && pairs[k - 1] == (v, j)) {
            simple[v as usize] = false;
        }
    }
    simple
}

/// Discrete uniformization of a closed genus-0 surface with Euclidean `lengths` (by edge id
/// of `mesh`) to the unit sphere, in the discrete conformal class of vertex scaling with
/// intrinsic Delaunay flips (Bobenko–Pinkall–Springborn 2015 §§5–6, Springborn 2020 §7,
/// Gillespie–Springborn–Crane 2021 §4.3; the solver is [`crate::flow::conformal`]).
///
/// **The puncture.** A vertex `∞` goes to infinity. With log Penner coordinates `λ` on the
/// input's intrinsic Delaunay triangulation, the Euclidean metric of the rest with `∞` at
/// infinity is the limit `u_∞ → +∞` of vertex scaling: a face `(∞, j, k)` has sides
/// `e^{(λ_∞j+u_∞+u_j)/2}`, `e^{(λ_∞k+u_∞+u_k)/2}` and `l_jk`; it stays a triangle in the
/// limit only if `λ_∞j + u_j = λ_∞k + u_k`. So on the link `L` of `∞` (the vertices joined to
/// it) **`u_j = −λ_∞j`** (a constant fixes the scale). A Ptolemy flip of the edge between a
/// finite face `(i, w, k)` and `(∞, k, i)` gives `e^{(λ_∞w+u_w)/2} = (l_iw + l_wk)/l_ik ≥ 1`
/// (with equality iff `w` lies on the segment `ik`): **every other vertex has
/// `u_w ≥ −λ_∞w`** for any arc to `∞` — the bound constraint of CEPS (`u ≥ −d`), active
/// exactly on the link. The flat picture is: interior vertices flat (`Θ_w = 2π`), link
/// vertices at `u_j = −λ_∞j` with boundary angle **`Θ_j ≤ π`** (the link is the boundary of
/// the convex hull of the planar points, the faces at `∞` are the half-planes outside its
/// edges; a reflex link vertex leaves the link by the Ptolemy flip of its edge to `∞`, which
/// creates the finite face `(i, j, k)`). These are the KKT conditions of the convex problem
/// "minimize the flat energy subject to `u_w ≥ −λ_∞w`".
///
/// **Algorithm.** (1) isometric flips to the input's intrinsic Delaunay triangulation;
/// (2) `∞`: the vertex of largest angle deficit among those of valence ≥ 5 with a simple link
/// (a convex, rounded neighbourhood gives a nearly convex hull at once); (3) rounds: the
/// disk without the star of `∞`, link values fixed, interior `K̄ = 0`, solved by
/// [`crate::flow::conformal::solve`] (Newton with Ptolemy flips; start `u_w = −2 log dist(∞, w)`
/// along edges, the inversion about `∞`); flips replayed on the sphere's triangulation; link
/// vertices with `Θ_j > π` flipped off the link, vertices pressing against a hull edge
/// (opposite angle near π) flipped onto it; rounds of at most 12 Newton steps, each starting
/// where the last one stopped (budget 100 rounds); (4) planar layout
/// of the flat disk, scaled so the link lies near the unit circle; (5) stereographic
/// projection, `∞` at the north pole; (6) Möbius centring: the boost
/// `x ↦ (1−|c|²)(x+c)/|x+c|² + c` by Newton's method until the vertex-area centroid (areas of
/// the input mesh) is the origin to 1e-13; (7) spherical lengths `d = 2 asin(|x_i − x_j|/2)`
/// on the final triangulation (the convex hull of the points: Delaunay for the chord
/// coordinates, which are Möbius invariant up to vertex scaling).
pub fn conformal_sphere(
    mesh: &Mesh,
    lengths: &[f64],
    tolerance: f64,
    max_iterations: usize,
    progress: &mut dyn Progress,
) -> Result<ConformalSphere> {
    let n = mesh.n_vertices();
    if mesh.has_boundary() || crate::metric::euler_characteristic(mesh) != 2 {
        return Err(Error::topology(
            "the sphere needs a closed genus-0 surface (Euler characteristic 2, no boundary)",
        ));
    }
    let mut t = IntrinsicTriangulation::from_mesh(mesh, Geometry::Euclidean, lengths)?;
    let flip_budget = 200 * mesh.n_edges() + 10_000;
    let init = t.make_delaunay_isometric(Geometry::Euclidean, flip_budget);
    if !init.delaunay {
        return Err(Error::numerical(format!(
            "the input metric did not become Delaunay within {flip_budget} flips"
        )));
    }
    let base_flips = t.flip_log.len();
    // 2. The puncture, and the start u_w = −2 log dist(∞, w), the inversion about ∞.
    let inf = choose_puncture(&t, n)?;
    let mut big_u = inversion_start(&t, n, inf);
    // 3. Rounds of the flat solve with the link of ∞ fixed.
    let fr = flat_rounds(
        &mut t,
        inf,
        &mut big_u,
        tolerance,
        max_iterations,
        flip_budget,
        progress,
    )?;
    let mut notes = fr.notes;
    // 4–5. Planar layout and stereographic projection.
    let (mut x, mut u_sph, link_vertices) = project_to_sphere(mesh, &t, inf, &big_u)?;
    // 6. Möbius centring with the input's vertex areas.
    let area = vertex_areas(mesh, lengths);
    let centring = mobius_centre(&mut x, &area, &mut u_sph, 100);
    if centring > 1e-12 {
        notes.push(format!(
            "Möbius centring stopped with the area centroid at distance {centring:.2e} from the \
             origin"
        ));
    }
    // 7. The final triangulation: λ = λ⁰ + u_i + u_j; the points' chords as a check.
    let base_lambda = t.lambda.clone();
    let mut fin = t.clone();
    let mut conformal_residual: f64 = 0.0;
    for e in 0..t.n_edges() as u32 {
        let [a, b] = t.edge_vertices(e);
        fin.lambda[e as usize] = base_lambda[e as usize] + u_sph[a as usize] + u_sph[b as usize];
        let (p, q) = (x[a as usize], x[b as usize]);
        let ch = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
        let from_points = 2.0 * (0.5 * ch).ln();
        let d = (from_points - fin.lambda[e as usize]).abs();
        conformal_residual = conformal_residual.max(if d.is_nan() { f64::INFINITY } else { d });
    }
    if fin.lambda.iter().any(|l| !l.is_finite()) {
        return Err(Error::numerical(
            "the spherical metric has a non-finite edge (the flat picture degenerated)",
        ));
    }
    // Orientation on the sphere.
    let inverted_faces = (0..fin.n_faces() as u32)
        .filter(|&f| {
            let [a, b, cc] = fin.face(f).map(|v| x[v as usize]);
            let d = a[0] * (b[1] * cc[2] - b[2] * cc[1]) - a[1] * (b[0] * cc[2] - b[2] * cc[0])
                + a[2] * (b[0] * cc[1] - b[1] * cc[0]);
            d <= 0.0
        })
        .count();
    Ok(ConformalSphere {
        triangulation: fin,
        base_lambda,
        positions: x,
        u: u_sph,
        conformal_residual,
        puncture: inf,
        initial_flips: base_flips,
        flips: fr.flips,
        iterations: fr.iterations,
        rounds: fr.rounds,
        link_vertices,
        flat_error: fr.flat_error,
        convexity_excess: fr.convexity_excess,
        inverted_faces,
        history: fr.history,
        notes,
    })
}

/// Vertex areas of the input metric (a third of the incident face areas), normalized to sum 1.
fn vertex_areas(mesh: &Mesh, lengths: &[f64]) -> Vec<f64> {
    let mut area = vec![0.0; mesh.n_vertices()];
    for f in 0..mesh.n_faces() as u32 {
        let es = mesh.face_edges_opposite(f);
        let l = es.map(|e| lengths[e as usize]);
        let s = 0.5 * (l[0] + l[1] + l[2]);
        let a = (s * (s - l[0]) * (s - l[1]) * (s - l[2])).max(0.0).sqrt();
        for v in mesh.face(f) {
            area[v as usize] += a / 3.0;
        }
    }
    let total: f64 = area.iter().sum();
    area.iter().map(|a| a / total).collect()
}

/// The vertex at infinity: the largest angle deficit among vertices with a simple link,
/// valence ≥ 5 preferred (a convex, rounded neighbourhood gives a nearly convex hull at once).
fn choose_puncture(t: &IntrinsicTriangulation, n: usize) -> Result<u32> {
    let mut deficit = vec![2.0 * PI; n];
    let mut valence = vec![0usize; n];
    for f in 0..t.n_faces() as u32 {
        let vs = t.face(f);
        let l: [f64; 3] = std::array::from_fn(|m| {
            let h = 3 * f + (m as u32 + 1) % 3;
            length_of_lambda(Geometry::Euclidean, t.lambda[t.edge[h as usize] as usize])
        });
        let (th, _, _) = crate::metric::kernel::triangle_angles::<crate::metric::Euclidean>(l);
        for m in 0..3 {
            deficit[vs[m] as usize] -= th[m];
            valence[vs[m] as usize] += 1;
        }
    }
    let simple = simple_links(t, n);
    (0..n as u32)
        .filter(|&v| valence[v as usize] >= 3 && simple[v as usize])
        .max_by(|&a, &b| {
            let ka = (valence[a as usize] >= 5, deficit[a as usize]);
            let kb = (valence[b as usize] >= 5, deficit[b as usize]);
            ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(b.cmp(&a))
        })
        .ok_or_else(|| {
            Error::topology("no vertex of the intrinsic Delaunay triangulation has a simple link")
        })
}

/// `u_w = −2 log dist(∞, w)` (Dijkstra along edges), the inversion about `∞`; exact on the
/// link; `u_∞ = 0`.
fn inversion_start(t: &IntrinsicTriangulation, n: usize, inf: u32) -> Vec<f64> {
    let mut adj: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    for e in 0..t.n_edges() as u32 {
        let [a, b] = t.edge_vertices(e);
        let l = length_of_lambda(Geometry::Euclidean, t.lambda[e as usize]);
        adj[a as usize].push((b, l));
        adj[b as usize].push((a, l));
    }
    let mut dist = vec![f64::INFINITY; n];
    dist[inf as usize] = 0.0;
    let mut heap = std::collections::BinaryHeap::new();
    heap.push((std::cmp::Reverse(OrdF64(0.0)), inf));
    while let Some((std::cmp::Reverse(OrdF64(d)), v)) = heap.pop() {
        if d > dist[v as usize] {
            continue;
        }
        for &(w, l) in &adj[v as usize] {
            if d + l < dist[w as usize] {
                dist[w as usize] = d + l;
                heap.push((std::cmp::Reverse(OrdF64(d + l)), w));
            }
        }
    }
    let mut big_u: Vec<f64> = dist
        .iter()
        .map(|&d| {
            if d.is_finite() && d > 0.0 {
                -2.0 * d.ln()
            } else {
                0.0
            }
        })
        .collect();
    big_u[inf as usize] = 0.0;
    big_u
}

/// What [`flat_rounds`] reached.
struct FlatRounds {
    notes: Vec<String>,
    history: Vec<crate::flow::IterationRecord>,
    iterations: usize,
    flips: usize,
    rounds: usize,
    flat_error: f64,
    convexity_excess: f64,
}

/// Step 3 of [`conformal_sphere`]: rounds of the flat solve of the disk without the star of
/// `inf` (link values fixed, interior flat), each followed by changes of the link; the flips
/// are replayed on `t`, the solution accumulates in `big_u`. An error when no round converged.
fn flat_rounds(
    t: &mut IntrinsicTriangulation,
    inf: u32,
    big_u: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
    flip_budget: usize,
    progress: &mut dyn Progress,
) -> Result<FlatRounds> {
    use crate::flow::conformal::{self, ConformalSettings};
    let n = big_u.len();
    let mut fr = FlatRounds {
        notes: Vec::new(),
        history: Vec::new(),
        iterations: 0,
        flips: 0,
        rounds: 0,
        flat_error: f64::INFINITY,
        convexity_excess: f64::INFINITY,
    };
    let mut converged = false;
    let t_start = std::time::Instant::now();
    // Short rounds: a vertex pressing against the hull makes the Newton steps crawl, and the
    // next round starts from where this one stopped (the u accumulate in big_u).
    let round_iterations = max_iterations.clamp(1, 12);
    let mut last_error = f64::INFINITY;
    while fr.rounds < 100 {
        fr.rounds += 1;
        let rounds = fr.rounds;
        let (link, simple) = link_of(t, inf);
        if !simple {
            return Err(Error::numerical(format!(
                "the link of the puncture vertex {inf} stopped being simple"
            )));
        }
        for &j in &link {
            let e = edges_between(t, inf, j)[0];
            big_u[j as usize] = -t.lambda[e as usize];
        }
        let (mut disk, d2t) = punctured_disk(t, inf, big_u);
        let mut target = Target {
            curvature: vec![0.0; n],
            fixed: vec![false; n],
            round_loops: Vec::new(),
            description: "flat, the puncture at infinity".into(),
        };
        target.fixed[inf as usize] = true;
        for &j in &link {
            target.fixed[j as usize] = true;
        }
        let settings = ConformalSettings {
            geometry: Geometry::Euclidean,
            tolerance,
            max_iterations: round_iterations,
            flip_budget,
            pinned: Vec::new(),
        };
        let out = {
            let mut sub = |stage: &str, f: Option<f64>, m: &str| {
                progress.report(&format!("sphere/{stage}"), f, m)
            };
            conformal::solve(&mut disk, &mut target, &settings, &mut sub)?
        };
        for rec in &out.history {
            let mut r = *rec;
            r.iteration += fr.iterations;
            r.seconds = t_start.elapsed().as_secs_f64();
            fr.history.push(r);
        }
        fr.iterations += out.iterations;
        fr.flips += out.flips;
        for &e in &disk.flip_log {
            t.flip(d2t[e as usize]);
        }
        for (w, x) in out.u.iter().enumerate() {
            if !target.fixed[w] {
                big_u[w] += x;
            }
        }
        fr.flat_error = out.max_error;
        // Boundary angles of the link.
        let mut theta = vec![0.0; n];
        for (c, &a) in out.state.angles.iter().enumerate() {
            theta[disk.origin[c] as usize] += a;
        }
        fr.convexity_excess = link
            .iter()
            .map(|&j| theta[j as usize] - PI)
            .fold(f64::NEG_INFINITY, f64::max);
        let solved = out.converged && out.state.degenerate_faces == 0;
        let change = change_link(t, inf, &link, &theta, &disk, &d2t, &out, solved, last_error);
        if solved && change.reflex == 0 {
            converged = true;
            break;
        }
        fr.flips += change.changed;
        let changed = change.changed;
        progress.report(
            "sphere",
            None,
            &format!(
                "round {rounds}: link {} vertices, flat solve {} (max |K| = {:.2e}, {} steps), \
                 largest boundary angle − π = {:.2e}, {} reflex, {changed} link change(s)",
                link.len(),
                if solved { "converged" } else { "stalled" },
                out.max_error,
                out.iterations,
                fr.convexity_excess,
                change.reflex
            ),
        );
        if changed == 0 && !solved && out.max_error < 0.5 * last_error {
            // Still progressing: another round from here.
            last_error = out.max_error;
            continue;
        }
        last_error = out.max_error;
        if changed == 0 {
            fr.notes.extend(out.notes.iter().cloned());
            fr.notes.push(format!(
                "round {rounds}: the flat disk {} (max |K| = {:.3e}) and no link vertex could \
                 change",
                if solved {
                    "converged"
                } else {
                    "did not converge"
                },
                out.max_error
            ));
            break;
        }
    }
    if !converged {
        return Err(Error::numerical(format!(
            "the flat picture with vertex {inf} at infinity did not converge after {} \
             round(s) (max |K| = {:.3e}, largest boundary angle − π = {:.3e}){}",
            fr.rounds,
            fr.flat_error,
            fr.convexity_excess,
            fr.notes
                .last()
                .map(|s| format!("; {s}"))
                .unwrap_or_default()
        )));
    }
    Ok(fr)
}

/// Link changes after a round of [`flat_rounds`]: reflex link vertices and flips made.
struct LinkChange {
    reflex: usize,
    changed: usize,
}

/// Reflex link vertices leave the link (Ptolemy flip of their edge to ∞), the most reflex
/// first; a vertex whose neighbours on the link were just changed waits. When the solve
/// stalled, a vertex pressing against a hull edge (the angle opposite the boundary edge near
/// π: its constraint `u_w ≥ −λ_∞w` about to become active) joins the link by the Ptolemy flip
/// of that hull edge. (When the solve converged and no vertex is reflex, nothing changes.)
#[allow(clippy::too_many_arguments)]
fn change_link(
    t: &mut IntrinsicTriangulation,
    inf: u32,
    link: &[u32],
    theta: &[f64],
    disk: &IntrinsicTriangulation,
    d2t: &[u32],
    out: &crate::flow::conformal::ConformalOutcome,
    solved: bool,
    last_error: f64,
) -> LinkChange {
    let n = theta.len();
    let tol_angle = 1e-9;
    let mut reflex: Vec<u32> = link
        .iter()
        .copied()
        .filter(|&j| theta[j as usize] > PI + tol_angle)
        .collect();
    reflex.sort_by(|&a, &b| theta[b as usize].total_cmp(&theta[a as usize]));
    let mut change = LinkChange {
        reflex: reflex.len(),
        changed: 0,
    };
    if solved && reflex.is_empty() {
        return change;
    }
    let mut touched = vec![false; n];
    for &j in &reflex {
        if touched[j as usize] {
            continue;
        }
        let es = edges_between(t, inf, j);
        if es.len() != 1 || !t.is_flippable(es[0]) {
            continue;
        }
        let h = t.edge_he[es[0] as usize];
        let tw = t.twin[h as usize];
        let i = t.origin[IntrinsicTriangulation::prev(h) as usize];
        let k = t.origin[IntrinsicTriangulation::prev(tw) as usize];
        if t.flip(es[0]) {
            change.changed += 1;
            touched[i as usize] = true;
            touched[k as usize] = true;
            touched[j as usize] = true;
        }
    }
    if solved {
        return change;
    }
    let mut escape: Vec<(f64, u32)> = Vec::new();
    let mut widest = (0.0, NONE);
    for h in 0..disk.n_halfedges() {
        if disk.twin[h] == NONE {
            let c = IntrinsicTriangulation::prev(h as u32) as usize;
            let a = out.state.angles[c];
            if a > 0.99 * PI {
                escape.push((a, d2t[disk.edge[h] as usize]));
            }
            if a > widest.0 {
                widest = (a, d2t[disk.edge[h] as usize]);
            }
        }
    }
    let progressing = out.max_error < 0.5 * last_error;
    if escape.is_empty() && change.changed == 0 && !progressing && widest.0 > 0.75 * PI {
        // Stalled with a vertex near a hull edge: let it join the link.
        escape.push(widest);
    }
    escape.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, e) in escape {
        let [a, b] = t.edge_vertices(e);
        if touched[a as usize] || touched[b as usize] || !t.is_flippable(e) {
            continue;
        }
        let h = t.edge_he[e as usize];
        let w = [
            t.origin[IntrinsicTriangulation::prev(h) as usize],
            t.origin[IntrinsicTriangulation::prev(t.twin[h as usize]) as usize],
        ];
        if !w.contains(&inf) {
            continue;
        }
        if t.flip(e) {
            change.changed += 1;
            for v in [a, b, w[0], w[1]] {
                touched[v as usize] = true;
            }
        }
    }
    change
}

/// Steps 4–5 of [`conformal_sphere`]: the planar layout of the flat disk (lengths from `t` and
/// `big_u`), scaled so the link lies within the unit circle, and the stereographic projection
/// with `∞` at the north pole. Returns the points, the log scale factors `u` of the spherical
/// metric, and the size of the link.
fn project_to_sphere(
    mesh: &Mesh,
    t: &IntrinsicTriangulation,
    inf: u32,
    big_u: &[f64],
) -> Result<(Vec<[f64; 3]>, Vec<f64>, usize)> {
    let n = mesh.n_vertices();
    let plane = layout_delta_disk(t, inf, big_u)?;
    let (link, _) = link_of(t, inf);
    let mut c = [0.0; 2];
    for &j in &link {
        c[0] += plane[j as usize][0] / link.len() as f64;
        c[1] += plane[j as usize][1] / link.len() as f64;
    }
    let r = link
        .iter()
        .map(|&j| {
            ((plane[j as usize][0] - c[0]).powi(2) + (plane[j as usize][1] - c[1]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max);
    if !(r > 0.0 && r.is_finite()) {
        return Err(Error::numerical(
            "the flat picture has a degenerate convex hull",
        ));
    }
    // The chords of the projection are a vertex scaling of the flat metric:
    // |σ(a) − σ(b)| = 2|a − b|/√((1+|a|²)(1+|b|²)), |σ(a) − N| = 2/√(1+|a|²), so with
    // λ = 2 log(chord/2): u_w = U_w − log r − log(1+|a_w|²) and u_∞ = log r (the link has
    // λ_∞j + U_j = 0). The metric is carried by these u (exact), the points by x.
    let mut x = vec![[0.0, 0.0, 1.0]; n];
    let mut u_sph = vec![0.0; n];
    u_sph[inf as usize] = r.ln();
    for w in 0..n {
        if w as u32 == inf || mesh.is_isolated(w as u32) {
            continue;
        }
        // Mirrored (an isometry of the flat picture) so that the faces, counter-clockwise in
        // the plane, are counter-clockwise seen from outside the sphere.
        let a = (plane[w][0] - c[0]) / r;
        let b = -(plane[w][1] - c[1]) / r;
        let d = 1.0 + a * a + b * b;
        x[w] = [2.0 * a / d, 2.0 * b / d, (a * a + b * b - 1.0) / d];
        u_sph[w] = big_u[w] - r.ln() - d.ln();
    }
    Ok((x, u_sph, link.len()))
}

/// A total order on finite floats for the Dijkstra heap.
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrdF64(f64);
impl Eq for OrdF64 {}
impl PartialOrd for OrdF64 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for OrdF64 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Breadth-first planar layout of the faces of `t` not incident to `inf` with the Euclidean
/// metric `λ + u_i + u_j` (one position per vertex; the flat disk has no holonomy).
fn layout_delta_disk(t: &IntrinsicTriangulation, inf: u32, u: &[f64]) -> Result<Vec<[f64; 2]>> {
    let n = t.n_vertices;
    let len = |h: u32| {
        let e = t.edge[h as usize];
        length_of_lambda(Geometry::Euclidean, t.scaled_lambda(e, u))
    };
    let nf = t.n_faces();
    let finite = |f: u32| !t.face(f).contains(&inf);
    let f0 = (0..nf as u32)
        .find(|&f| finite(f))
        .ok_or_else(|| Error::topology("every face touches the puncture"))?;
    let mut p = vec![[f64::NAN; 2]; n];
    let mut placed = vec![false; n];
    let mut corner = vec![[f64::NAN; 2]; 3 * nf];
    let mut done = vec![false; nf];
    let b = 3 * f0;
    let (l01, l12, l20) = (len(b), len(b + 1), len(b + 2));
    let xx = (l01 * l01 + l20 * l20 - l12 * l12) / (2.0 * l01);
    corner[b as usize] = [0.0, 0.0];
    corner[b as usize + 1] = [l01, 0.0];
    corner[b as usize + 2] = [xx, (l20 * l20 - xx * xx).max(0.0).sqrt()];
    done[f0 as usize] = true;
    let mut queue = std::collections::VecDeque::from([f0]);
    while let Some(f) = queue.pop_front() {
        for i in 0..3u32 {
            let h = 3 * f + i;
            let tw = t.twin[h as usize];
            if tw == NONE {
                continue;
            }
            let g = tw / 3;
            if done[g as usize] || !finite(g) {
                continue;
            }
            done[g as usize] = true;
            // tw goes tip(h) → origin(h); the third corner of g lies to its left.
            let pa = corner[IntrinsicTriangulation::next(h) as usize];
            let pb = corner[h as usize];
            let e = [pb[0] - pa[0], pb[1] - pa[1]];
            let dd = (e[0] * e[0] + e[1] * e[1]).sqrt();
            let t1 = IntrinsicTriangulation::next(tw);
            let t2 = IntrinsicTriangulation::prev(tw);
            let (lbc, lca) = (len(t1), len(t2));
            let x = (lca * lca - lbc * lbc + dd * dd) / (2.0 * dd);
            let y = (lca * lca - x * x).max(0.0).sqrt();
            let (ex, ey) = (e[0] / dd, e[1] / dd);
            corner[tw as usize] = pa;
            corner[t1 as usize] = pb;
            corner[t2 as usize] = [pa[0] + x * ex - y * ey, pa[1] + x * ey + y * ex];
            queue.push_back(g);
        }
    }
    for h in 0..3 * nf {
        if done[h / 3] {
            let v = t.origin[h] as usize;
            if !placed[v] {
                p[v] = corner[h];
                placed[v] = true;
            }
        }
    }
    let mut used = vec![false; n];
    for &o in &t.origin {
        used[o as usize] = true;
    }
    if (0..n).any(|v| v as u32 != inf && !placed[v] && used[v]) {
        return Err(Error::topology("the punctured sphere is not connected"));
    }
    Ok(p)
}

/// Move points on the unit sphere by Möbius boosts `x ↦ (1−|c|²)(x+c)/|x+c|² + c` until the
/// `weights`-centroid is the origin (Newton's method on `c`; the derivative of the centroid at
/// `c = 0` is `Σ w (2I − 2xxᵀ)`). `log_scale` accumulates the log conformal factor
/// `log M'(x) = log(1−|c|²) − 2 log|x+c|` of each point (chords scale by `√(M'(x)M'(y))`, so
/// `2 log chord` gains `log M'(x) + log M'(y)`). Returns the final centroid's norm.
pub fn mobius_centre(
    x: &mut [[f64; 3]],
    weights: &[f64],
    log_scale: &mut [f64],
    budget: usize,
) -> f64 {
    let centroid = |x: &[[f64; 3]]| {
        let mut m = [0.0; 3];
        for (p, &w) in x.iter().zip(weights) {
            for k in 0..3 {
                m[k] += w * p[k];
            }
        }
        m
    };
    let mut m = centroid(x);
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    for _ in 0..budget {
        if norm(m) <= 1e-14 {
            break;
        }
        let mut j = [[0.0; 3]; 3];
        for (p, &w) in x.iter().zip(weights) {
            for a in 0..3 {
                for b in 0..3 {
                    let id = if a == b { 1.0 } else { 0.0 };
                    j[a][b] += 2.0 * w * (id - p[a] * p[b]);
                }
            }
        }
        let mut c = solve3(j, m.map(|t| -t));
        let cn = norm(c);
        if !cn.is_finite() {
            break;
        }
        if cn > 0.5 {
            c = c.map(|t| t * 0.5 / cn);
        }
        let c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        for (p, s) in x.iter_mut().zip(log_scale.iter_mut()) {
            let d = [p[0] + c[0], p[1] + c[1], p[2] + c[2]];
            let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            // The boost scales chords by √(M'(x)M'(y)), M'(x) = (1−|c|²)/|x+c|².
            *s += (1.0 - c2).ln() - dd.ln();
            let y = [
                (1.0 - c2) * d[0] / dd + c[0],
                (1.0 - c2) * d[1] / dd + c[1],
                (1.0 - c2) * d[2] / dd + c[2],
            ];
            let ny = norm(y);
            *p = [y[0] / ny, y[1] / ny, y[2] / ny];
        }
        let m_new = centroid(x);
        m = m_new;
    }
    norm(m)
}
