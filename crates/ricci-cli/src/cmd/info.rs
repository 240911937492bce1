//! `ricci info MESH [--json]`: validate, topology per component, triangle quality.

use crate::util::print_json;
use ricci::mesh::{io::read_surface, quality::angle_stats, topology};
use serde_json::json;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let (surface, report) = read_surface(&a.mesh)?;
    let m = &surface.mesh;
    let t = topology(m);
    let q = angle_stats(&surface);
    let genus = if t.components.len() == 1 {
        json!(t.components[0].genus)
    } else {
        json!(t.genus())
    };
    let v = json!({
        "file": a.mesh.display().to_string(),
        "vertices": m.n_vertices(),
        "edges": m.n_edges(),
        "faces": m.n_faces(),
        "components": t.components.len(),
        "boundary_loops": t.boundary_loops(),
        "euler_characteristic": t.euler_characteristic(),
        "genus": genus,
        "orientable": true,
        "manifold": true,
        "min_angle_deg": q.min_angle_deg,
        "max_angle_deg": q.max_angle_deg,
        "zero_area_faces": report.zero_area_faces.len(),
        "dropped_vertices": report.dropped_vertices.len(),
        "reoriented_faces": report.reoriented_faces,
        "triangulated_polygons": report.triangulated_polygons,
        "per_component": t.components,
        "notes": report.notes,
    });
    if a.json {
        print_json(&v);
    } else {
        println!("{}", a.mesh.display());
        println!(
            "  {} vertices, {} edges, {} faces, {} component(s)",
            m.n_vertices(),
            m.n_edges(),
            m.n_faces(),
            t.components.len()
        );
        for (i, c) in t.components.iter().enumerate() {
            println!(
                "  component {i}: V={} E={} F={} boundary loops={} χ={} genus={}",
                c.vertices, c.edges, c.faces, c.boundary_loops, c.euler_characteristic, c.genus
            );
        }
        println!(
            "  angles: min {:.3}°, max {:.3}°",
            q.min_angle_deg, q.max_angle_deg
        );
        for n in &report.notes {
            println!("  note: {n}");
        }
    }
    Ok(())
}
