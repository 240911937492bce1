//! Holomorphic 1-forms on the shared meshes: time of `holomorphic_forms` (cut, harmonic
//! basis, period matrix), of the zeros and of the uniform combination, and the quality
//! numbers (star defect, raw asymmetry of Ω, zero count, spurious singularities per basis form).
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example bench_forms [MESH...]`

use ricci::analysis::forms::uniform::uniform_combination;
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;
use std::time::Instant;

fn main() {
    let dir = std::env::var("RICCI_MESHES").unwrap_or_else(|_| "/work/shared/meshes".into());
    let args: Vec<String> = std::env::args().skip(1).collect();
    let names: Vec<String> = if args.is_empty() {
        [
            "eight.off",
            "3holes.off",
            "genus3.off",
            "fertility.off",
            "botijo.off",
            "kitten.nf20k.off",
            "rocker-arm.off",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    } else {
        args
    };
    println!("| mesh | g | vertices | forms s | zeros s | uniform s | star defect | raw asym | zeros of ω_i (spurious) |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---|");
    for name in names {
        let path = std::path::Path::new(&dir).join(&name);
        let (s, _) = match ricci::mesh::io::read_surface(&path) {
            Ok(x) => x,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let t0 = Instant::now();
        let h = match holomorphic_forms(
            &s.mesh,
            &IntrinsicMetric::euclidean(s.edge_lengths()),
            Some(&s.positions),
            &FormsOptions::default(),
            &mut NoProgress,
        ) {
            Ok(h) => h,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let t_forms = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let zs: Vec<String> = h
            .basis
            .iter()
            .map(|w| match h.zeros(w) {
                Ok(z) => format!("{} ({})", z.count, z.spurious.len()),
                Err(e) => format!("error: {e}"),
            })
            .collect();
        let t_zeros = t1.elapsed().as_secs_f64() / h.genus as f64;
        let t2 = Instant::now();
        let uni = uniform_combination(&h, 200);
        let t_uni = t2.elapsed().as_secs_f64();
        let uni_s = match uni {
            Ok((u, _)) => format!(
                "{t_uni:.2} (E {:.3} vs ω1 {:.3})",
                u.energy, u.energy_first_form
            ),
            Err(e) => format!("error: {e}"),
        };
        println!(
            "| {name} | {} | {} | {t_forms:.2} | {t_zeros:.3} | {uni_s} | {:.1e} | {:.1e} | {} |",
            h.genus,
            h.report.vertices,
            h.report.star_defect,
            h.report.raw_asymmetry,
            zs.join(", ")
        );
    }
}
