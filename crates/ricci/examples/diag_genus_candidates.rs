//! Diagnostic for the genus ≥ 2 domain (issue 18): per candidate form `Im ω = Σ n_k ζ_k`, the
//! cylinders, whether they cover the net's area, the poorest cylinder's data, the thinnest
//! band, and whether the strips glue ([`ricci::spline::tspline::glue::gluing`]) or why not.
//!
//! `cargo run --release -p ricci --example diag_genus_candidates -- MESH`
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use ricci::spline::tspline::genus_domain::{candidates, genus_domain};
use ricci::spline::tspline::glue::gluing;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: diag_genus_candidates MESH");
        std::process::exit(2);
    };
    let (s, _) = ricci::mesh::io::read_surface(std::path::Path::new(path))?;
    let h = holomorphic_forms(
        &s.mesh,
        &IntrinsicMetric::euclidean(s.edge_lengths()),
        Some(&s.positions),
        &FormsOptions::default(),
        &mut NoProgress,
    )?;
    for n in candidates(2 * h.genus) {
        match genus_domain(&h, &n, s.positions.len()) {
            Ok(d) => {
                let area: f64 = d.cylinders.iter().map(|c| c.circumference * c.height).sum();
                let net = d.decomposition.area;
                let poorest = d.cylinders.iter().map(|c| c.data_points).min().unwrap_or(0);
                let thin = d.cylinders.iter().filter(|c| c.thin).count();
                let thinnest = d
                    .cylinders
                    .iter()
                    .map(|c| c.height)
                    .fold(f64::INFINITY, f64::min);
                let glue = match gluing(&d) {
                    Ok(g) => format!(
                        "glued: {} added points, lines' largest slope {:.2}",
                        g.added_points, g.max_slope
                    ),
                    Err(e) => e,
                };
                println!(
                    "{n:?}: {} cylinders ({thin} thin), area defect {:.2e}, poorest {poorest}, thinnest {thinnest:.4}; {glue}",
                    d.cylinders.len(),
                    (area - net).abs() / net.abs()
                );
            }
            Err(e) => println!("{n:?}: {e}"),
        }
    }
    Ok(())
}
