//! `ricci spectrum` on a surface with boundary lists the closed geodesics of its double
//! (issue 17, paper 003 §2). Values from elsewhere:
//! - the round annulus `r₁ < |z| < r₂` is conformal to a cylinder of circumference `2π` and
//!   height `h = log(r₂/r₁)`; its double is the flat torus `ℝ²/(2πℤ × 2hℤ)`, whose closed
//!   geodesics have lengths `|m·2π + i n·2h|` (closed form);
//! - a hyperbolic surface with geodesic boundary is half of its double's hyperbolic metric, so
//!   the boundary loops are closed geodesics of the double: their lengths from the surface's
//!   own flow (`ricci flow --geometry hyperbolic`, geodesic boundary, sum of the boundary
//!   edges' lengths) appear in the double's spectrum (its flow, Fuchsian group and search).

use std::path::PathBuf;
use std::process::Command;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-spdouble-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn run(args: &[&str]) -> std::process::Output {
    let o = ricci().args(args).output().unwrap();
    assert!(
        o.status.success(),
        "ricci {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn run_json(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&run(args).stdout).expect("stdout is one JSON object")
}

fn lengths(v: &serde_json::Value, key: &str) -> Vec<f64> {
    v[key]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn annulus_double_is_the_flat_torus_of_its_modulus() {
    for (r1, r2) in [(0.3f64, 1.2f64), (0.5, 1.0)] {
        let mesh = scratch(&format!("annulus-{r1}-{r2}.off"));
        let m = mesh.to_str().unwrap();
        let (i, o) = (r1.to_string(), r2.to_string());
        run(&[
            "generate",
            "annulus",
            "--inner",
            &i,
            "--outer",
            &o,
            "--resolution",
            "96",
            "--out",
            m,
        ]);
        let count = 8;
        let v = run_json(&["spectrum", m, "--count", &count.to_string(), "--json"]);
        assert_eq!(v["spectrum_of"], "double");
        assert_eq!(v["genus"], 1);
        assert_eq!(v["double"]["surface_genus"], 0);
        assert_eq!(v["double"]["boundary_loops"], 2);
        // Closed form: |m·2π + i n·2h| over (m, n) ≠ 0 up to sign, normalized by the shortest.
        let h = (r2 / r1).ln();
        let mut want = Vec::new();
        for a in 0..=6i32 {
            for b in -30..=30i32 {
                if a > 0 || b > 0 {
                    want.push((a as f64 * 2.0 * std::f64::consts::PI).hypot(b as f64 * 2.0 * h));
                }
            }
        }
        want.sort_by(f64::total_cmp);
        let want: Vec<f64> = want[..count].iter().map(|x| x / want[0]).collect();
        let got = lengths(&v, "normalized");
        eprintln!("annulus {r1}/{r2}: spectrum {got:?}\n  closed form {want:?}");
        assert_eq!(got.len(), count);
        for (g, w) in got.iter().zip(&want) {
            let rel = (g - w).abs() / w;
            assert!(rel <= 5e-3, "annulus {r1}/{r2}: {g} vs {w} (rel {rel:.1e})");
        }
    }
}

#[test]
fn pants_double_contains_the_geodesic_boundary_lengths() {
    let mesh = scratch("pants.off");
    let metric = scratch("pants-h2.json");
    let m = mesh.to_str().unwrap();
    run(&["generate", "pants", "--resolution", "48", "--out", m]);
    run(&[
        "flow",
        m,
        "--geometry",
        "hyperbolic",
        "--out",
        metric.to_str().unwrap(),
    ]);
    // The surface's own hyperbolic metric with geodesic boundary: boundary loop lengths.
    let (s, _) = ricci::mesh::io::read_surface(&mesh).unwrap();
    let mf = ricci::metric::file::read_metric_file(&metric, &s.mesh).unwrap();
    assert_eq!(mf.converged, Some(true));
    let on = mf.mesh_or(&s.mesh);
    let boundary: Vec<f64> = on
        .boundary_loop_halfedges()
        .iter()
        .map(|l| l.iter().map(|&h| mf.lengths[on.he_edge(h) as usize]).sum())
        .collect();
    assert_eq!(boundary.len(), 3);
    // The outer loop (~6.0) comes after the powers of the shortest geodesics (~1.04): 60 lengths.
    let v = run_json(&["spectrum", m, "--count", "60", "--json"]);
    assert_eq!(v["spectrum_of"], "double");
    assert_eq!(v["genus"], 2);
    assert_eq!(v["geometry"], "hyperbolic");
    let sp = lengths(&v, "absolute_lengths");
    eprintln!("pants: boundary lengths {boundary:?}\n  double's spectrum {sp:?}");
    for b in &boundary {
        let rel = sp
            .iter()
            .map(|x| (x - b).abs() / b)
            .fold(f64::INFINITY, f64::min);
        // Measured 6e-15 (same discrete conformal class: no flip crosses the boundary here).
        assert!(
            rel <= 1e-8,
            "boundary length {b}: nearest in the spectrum rel {rel:.1e}"
        );
    }
}
