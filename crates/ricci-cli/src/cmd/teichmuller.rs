//! `ricci teichmuller MESH... [--base V] [--json]`: Teichmüller coordinates of closed surfaces
//! of genus ≥ 2 (paper 002 §6.3.4, `ricci::analysis::teichmuller`): per mesh the
//! Fenchel–Nielsen coordinates (lengths and twists of the pants decomposition `a_k`,
//! `s_k = [a₁,b₁]⋯[a_k,b_k]`, `t_k = [a_k,b_k]` of the canonical cut's basis) and, for genus 2,
//! the 7 length coordinates; then the matrix of distances between the meshes: the Euclidean
//! distance of the coordinate vectors (length coordinates for genus 2, Fenchel–Nielsen
//! vectors otherwise), as paper 002 Tables 6–8 do — an approximation that compares the
//! markings the cuts chose, not the Teichmüller metric. Meshes of different genera have no
//! distance (`null`). Progress on stderr, one line per mesh.

use crate::util::{print_json, read_surface, Reporter, UsageError};
use ricci::analysis::teichmuller::{
    coordinate_distance, surface_teichmuller, SurfaceTeichmuller, TeichmullerOptions,
};
use ricci::metric::IntrinsicMetric;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh files (closed surfaces of genus ≥ 2).
    #[arg(required = true)]
    pub meshes: Vec<PathBuf>,
    /// Base vertex of the canonical cut (the same id on every mesh; default: the cut's choice).
    #[arg(long)]
    pub base: Option<u32>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let mut rep = Reporter::new(a.json);
    let mut results: Vec<SurfaceTeichmuller> = Vec::new();
    let n = a.meshes.len();
    for (i, path) in a.meshes.iter().enumerate() {
        rep.line(&format!("teichmuller: {} ({}/{n})", path.display(), i + 1));
        let (surface, _) = read_surface(path)?; // its errors name the file
        if let Some(b) = a.base {
            crate::util::check_vertex("--base", b, surface.mesh.n_vertices())?;
        }
        let opts = TeichmullerOptions {
            base: a.base,
            ..Default::default()
        };
        let r = surface_teichmuller(
            &surface.mesh,
            &IntrinsicMetric::euclidean(surface.edge_lengths()),
            &opts,
            &mut rep,
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        if r.coordinates.misplaced_seams > 0 {
            eprintln!(
                "ricci teichmuller: {}: {} seam(s) were not on the expected side of their curve; \
                 the twists may be wrong",
                path.display(),
                r.coordinates.misplaced_seams
            );
        }
        results.push(r);
    }
    rep.bar.0.finish_and_clear();
    let distances: Vec<Vec<Option<f64>>> = results
        .iter()
        .map(|x| {
            results
                .iter()
                .map(|y| coordinate_distance(&x.coordinates, &y.coordinates))
                .collect()
        })
        .collect();
    let names: Vec<String> = a.meshes.iter().map(|p| p.display().to_string()).collect();
    if a.json {
        let coords: Vec<_> = results
            .iter()
            .zip(&names)
            .map(|(r, name)| {
                let c = &r.coordinates;
                json!({
                    "file": name,
                    "genus": c.genus,
                    "curves": c.curves,
                    "fenchel_nielsen": c.fenchel_nielsen,
                    "length_coordinates": c.length_coordinates,
                    "length_curves": c.length_curves,
                    "relation_error": r.deck_relation_error,
                    "misplaced_seams": c.misplaced_seams,
                    "max_curvature_error": r.max_curvature_error,
                    "flipped_faces": r.flipped_faces,
                    "base": r.base,
                    "seconds": r.seconds,
                })
            })
            .collect();
        print_json(&json!({
            "meshes": names,
            "coordinates": coords,
            "distances": distances,
            "distance": "Euclidean distance of the coordinate vectors (genus 2: the 7 length coordinates; otherwise the Fenchel–Nielsen vector), as paper 002 Tables 6–8",
            "seconds": t0.elapsed().as_secs_f64(),
        }));
        return Ok(());
    }
    for (r, name) in results.iter().zip(&names) {
        let c = &r.coordinates;
        println!("{name}: genus {}", c.genus);
        println!("  {:<6} {:>10} {:>10}  word", "curve", "length", "twist");
        for cv in &c.curves {
            println!(
                "  {:<6} {:>10.6} {:>10.6}  {}",
                cv.name, cv.length, cv.twist, cv.word
            );
        }
        if !c.length_coordinates.is_empty() {
            let v: Vec<String> = c
                .length_coordinates
                .iter()
                .map(|x| format!("{x:.6}"))
                .collect();
            println!("  length coordinates: {}", v.join(" "));
        }
    }
    if n > 1 {
        println!("distances (Euclidean, coordinate vectors):");
        for (i, row) in distances.iter().enumerate() {
            let cells: Vec<String> = row
                .iter()
                .map(|d| d.map_or("     -".into(), |d| format!("{d:8.4}")))
                .collect();
            println!("  {:>3}  {}", i + 1, cells.join(" "));
        }
    }
    if results.is_empty() {
        return Err(UsageError("no meshes given".into()).into());
    }
    Ok(())
}
