//! `ricci info MESH [--json]`: validate a mesh file, report its topology per component and
//! its triangle quality (docs/DESIGN.md §4).
//!
//! A file that is not a valid oriented 2-manifold (non-manifold edge or vertex,
//! non-orientable, out-of-range index, …) is refused with one sentence naming the culprit
//! (exit code 1), so `orientable` and `manifold` are always `true` in a report.

use crate::util::print_json;
use crate::util::read_surface;
use ricci::mesh::quality::face_angles;
use ricci::mesh::topology;
use ricci::mesh::{BuildReport, Surface};
use serde_json::json;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (.obj, .off, .ply, .stl; ascii or binary PLY/STL).
    pub mesh: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The JSON report of `ricci info` for a validated surface (`file` names it); also written
/// by `ricci demo` as `info.json`.
pub fn info_json(file: &str, surface: &Surface, report: &BuildReport) -> serde_json::Value {
    let m = &surface.mesh;
    let t = topology(m);
    let nc = t.components.len();
    // Angles per component (degrees).
    let mut min_angle = vec![f64::INFINITY; nc];
    let mut max_angle = vec![0.0f64; nc];
    for f in 0..m.n_faces() as u32 {
        let c = t.face_component[f as usize] as usize;
        for x in face_angles(surface, f) {
            min_angle[c] = min_angle[c].min(x.to_degrees());
            max_angle[c] = max_angle[c].max(x.to_degrees());
        }
    }
    let global_min = min_angle.iter().copied().fold(f64::INFINITY, f64::min);
    let global_max = max_angle.iter().copied().fold(0.0, f64::max);
    // Boundary loop lengths (edges) per component.
    let mut loops: Vec<Vec<usize>> = vec![Vec::new(); nc];
    for l in m.boundary_loop_halfedges() {
        if let Some(&h) = l.first() {
            loops[t.face_component[m.he_face(h) as usize] as usize].push(l.len());
        }
    }
    let per_component: Vec<serde_json::Value> = t
        .components
        .iter()
        .enumerate()
        .map(|(i, c)| {
            json!({
                "vertices": c.vertices,
                "edges": c.edges,
                "faces": c.faces,
                "boundary_loops": c.boundary_loops,
                "boundary_loop_lengths": loops[i],
                "euler_characteristic": c.euler_characteristic,
                "genus": c.genus,
                "first_face": c.first_face,
                "min_angle_deg": min_angle[i],
                "max_angle_deg": max_angle[i],
            })
        })
        .collect();
    let (lo, hi) = surface.bounding_box();
    json!({
        "file": file,
        "vertices": m.n_vertices(),
        "edges": m.n_edges(),
        "faces": m.n_faces(),
        "components": nc,
        "boundary_loops": t.boundary_loops(),
        "euler_characteristic": t.euler_characteristic(),
        "genus": t.genus(),
        "orientable": true,
        "manifold": true,
        "min_angle_deg": global_min,
        "max_angle_deg": global_max,
        "bounding_box": { "min": lo, "max": hi },
        "has_uvs": surface.uvs.is_some(),
        "zero_area_faces": report.zero_area_faces.len(),
        "zero_area_face_ids": report.zero_area_faces.iter().take(10).map(|&f| report.face_origin[f as usize]).collect::<Vec<u32>>(),
        "dropped_vertices": report.dropped_vertices.len(),
        "reoriented_faces": report.reoriented_faces,
        "triangulated_polygons": report.triangulated_polygons,
        "per_component": per_component,
        "notes": report.notes,
    })
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let (surface, report) = read_surface(&a.mesh)?;
    let v = info_json(&a.mesh.display().to_string(), &surface, &report);
    let m = &surface.mesh;
    let t = topology(m);
    let nc = t.components.len();
    let global_min = v["min_angle_deg"].as_f64().unwrap_or(f64::NAN);
    let global_max = v["max_angle_deg"].as_f64().unwrap_or(f64::NAN);
    let (lo, hi) = surface.bounding_box();
    if a.json {
        print_json(&v);
        return Ok(());
    }
    println!("{}", a.mesh.display());
    println!(
        "  {} vertices, {} edges, {} faces, {} component{}",
        m.n_vertices(),
        m.n_edges(),
        m.n_faces(),
        nc,
        if nc == 1 { "" } else { "s" }
    );
    println!(
        "  χ = {}, genus {}, {} boundary loop{}; orientable manifold",
        t.euler_characteristic(),
        t.genus(),
        t.boundary_loops(),
        if t.boundary_loops() == 1 { "" } else { "s" }
    );
    if nc > 1 {
        for (i, c) in t.components.iter().enumerate() {
            println!(
                "  component {i}: V={} E={} F={} boundary loops={} χ={} genus={}",
                c.vertices, c.edges, c.faces, c.boundary_loops, c.euler_characteristic, c.genus
            );
        }
    }
    println!("  angles: min {global_min:.3}°, max {global_max:.3}°");
    println!(
        "  bounding box: [{:.6}, {:.6}, {:.6}] – [{:.6}, {:.6}, {:.6}]",
        lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
    );
    for n in &report.notes {
        println!("  note: {n}");
    }
    Ok(())
}
