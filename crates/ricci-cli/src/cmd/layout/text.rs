//! The text report of `ricci layout` (without `--json`).

use super::Args;
use ricci::metric::Geometry;
use serde_json::Value;

/// The text report of `ricci layout` (without `--json`).
pub fn print_text(a: &Args, geometry: Geometry, out: &Value) {
    println!("{}: {} layout", a.mesh.display(), geometry.name());
    println!("  flipped faces: {}", out["flipped_faces"]);
    if let Some(w) = out.get("boundary_word") {
        println!("  boundary word: {}", w.as_str().unwrap_or(""));
    }
    if !out["relation_error"].is_null() {
        println!(
            "  relation error: {:.3e}",
            out["relation_error"].as_f64().unwrap_or(f64::NAN)
        );
        println!(
            "  max edge spread: {:.3e}",
            out["max_edge_spread"].as_f64().unwrap_or(f64::NAN)
        );
    }
    println!("  seconds: {:.3}", out["seconds"].as_f64().unwrap_or(0.0));
}
