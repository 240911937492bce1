//! Conformal maps of closed genus-0 surfaces onto the unit sphere (`ricci param --sphere`).
//!
//! The spherical uniformization metric comes from [`crate::flow`] with the default spherical
//! scheme (today Thurston circle packing through a puncture, [`crate::flow::sphere`]; the
//! conformal scheme on S² through a puncture replaces it when it lands — then the map is
//! still one point per input vertex, so nothing below changes), and is laid out on the
//! sphere ([`crate::layout::place::layout`]). The map is unique up to the Möbius group; it is
//! **Möbius-centred**: the area-weighted centroid of the vertices (weights: a third of the
//! incident 3D face areas) is moved to the origin by the hyperbolic isometries of the ball
//! `φ_c(x) = ((1 − |c|²)(x − c) − |x − c|² c) / |x − c|²` (`|x| = 1`), iterated from the
//! current centroid with step halving (Baden–Crane–Kazhdan 2018 §3.2 centre the same way).
//!
//! Distortion is measured from each 3D triangle to the chord triangle of its image, oriented by
//! the outward normal (a face turned inwards is flipped).

use crate::analysis::distortion::{face_distortion, stats, DistortionStats};
use crate::error::{Error, Result};
use crate::flow::{default_scheme, ricci_flow, FlowOptions, TargetSpec};
use crate::layout::place::layout;
use crate::mesh::{topology, Surface};
use crate::metric::{Geometry, Spherical};
use crate::numeric::vec3::{cross, dot, norm, sub};
use crate::progress::Progress;
use serde::Serialize;
use std::time::Instant;

/// The result of [`sphere_map`].
#[derive(Debug, Clone, Serialize)]
pub struct SphereMap {
    /// Image of every input vertex on the unit sphere.
    #[serde(skip)]
    pub positions: Vec<[f64; 3]>,
    pub scheme: String,
    pub route: String,
    pub flow_iterations: usize,
    pub max_curvature_error: f64,
    /// |area-weighted centroid| after centring.
    pub centroid_norm: f64,
    pub centring_steps: usize,
    pub stats: DistortionStats,
    pub seconds: f64,
}

fn mobius(c: [f64; 3], x: [f64; 3]) -> [f64; 3] {
    let c2 = dot(c, c);
    let d = sub(x, c);
    let d2 = dot(d, d).max(1e-300);
    let y = [
        ((1.0 - c2) * d[0] - d2 * c[0]) / d2,
        ((1.0 - c2) * d[1] - d2 * c[1]) / d2,
        ((1.0 - c2) * d[2] - d2 * c[2]) / d2,
    ];
    let n = norm(y);
    [y[0] / n, y[1] / n, y[2] / n]
}

/// See the module docs. The surface must be connected, closed and of genus 0.
pub fn sphere_map(surface: &Surface, progress: &mut dyn Progress) -> Result<SphereMap> {
    let t0 = Instant::now();
    let mesh = &surface.mesh;
    let t = topology(mesh);
    if t.components.len() != 1 || t.components[0].genus != 0 || t.components[0].boundary_loops != 0
    {
        return Err(Error::topology(
            "--sphere needs a connected closed surface of genus 0",
        ));
    }
    let fo = FlowOptions {
        geometry: Geometry::Spherical,
        scheme: default_scheme(Geometry::Spherical),
        target: TargetSpec::Uniform,
        tolerance: 1e-10,
        ..FlowOptions::default()
    };
    progress.report("flow", None, "spherical uniformization");
    let r = ricci_flow(mesh, &surface.edge_lengths(), &fo, progress)?;
    if !r.converged {
        return Err(Error::numerical(format!(
            "the spherical flow did not converge (max |K − K̄| = {:.3e})",
            r.max_curvature_error
        )));
    }
    let work = r
        .triangulation
        .as_ref()
        .map(|t| &t.simplicial.mesh)
        .unwrap_or(mesh);
    progress.report("layout", None, "layout on the sphere");
    let l = layout::<Spherical>(work, &r.lengths, None)?;
    let n = mesh.n_vertices();
    let mut x: Vec<[f64; 3]> = l.positions[..n].to_vec();
    // Vertex weights: a third of the incident 3D face areas.
    let mut w = vec![0.0; n];
    for tri in mesh.faces() {
        let p = |i: usize| surface.positions[tri[i] as usize];
        let a = 0.5 * norm(cross(sub(p(1), p(0)), sub(p(2), p(0))));
        for &v in tri {
            w[v as usize] += a / 3.0;
        }
    }
    let wsum: f64 = w.iter().sum();
    let centroid = |x: &[[f64; 3]]| -> [f64; 3] {
        let mut g = [0.0; 3];
        for (p, &wi) in x.iter().zip(&w) {
            for k in 0..3 {
                g[k] += wi * p[k] / wsum;
            }
        }
        g
    };
    let mut g = centroid(&x);
    let mut steps = 0;
    let mut step = 1.0;
    while norm(g) > 1e-12 && steps < 200 {
        steps += 1;
        let c = [step * g[0], step * g[1], step * g[2]];
        let y: Vec<[f64; 3]> = x.iter().map(|&p| mobius(c, p)).collect();
        let gy = centroid(&y);
        if norm(gy) < norm(g) {
            x = y;
            g = gy;
            step = (step * 1.5).min(1.0);
        } else {
            step *= 0.5;
            if step < 1e-6 {
                break;
            }
        }
    }
    let d: Vec<_> = mesh
        .faces()
        .iter()
        .map(|tri| {
            let p = [
                surface.positions[tri[0] as usize],
                surface.positions[tri[1] as usize],
                surface.positions[tri[2] as usize],
            ];
            let q = [x[tri[0] as usize], x[tri[1] as usize], x[tri[2] as usize]];
            let e1 = sub(q[1], q[0]);
            let l1 = norm(e1).max(1e-300);
            let e1 = [e1[0] / l1, e1[1] / l1, e1[2] / l1];
            let out = [
                q[0][0] + q[1][0] + q[2][0],
                q[0][1] + q[1][1] + q[2][1],
                q[0][2] + q[1][2] + q[2][2],
            ];
            let e2 = cross(out, e1);
            let l2 = norm(e2).max(1e-300);
            let e2 = [e2[0] / l2, e2[1] / l2, e2[2] / l2];
            let flat = |v: [f64; 3]| [dot(sub(v, q[0]), e1), dot(sub(v, q[0]), e2)];
            face_distortion(p, [[0.0, 0.0], flat(q[1]), flat(q[2])])
        })
        .collect();
    Ok(SphereMap {
        positions: x,
        scheme: r.scheme.to_string(),
        route: r.route.clone(),
        flow_iterations: r.iterations,
        max_curvature_error: r.max_curvature_error,
        centroid_norm: norm(g),
        centring_steps: steps,
        stats: stats(&d),
        seconds: t0.elapsed().as_secs_f64(),
    })
}
