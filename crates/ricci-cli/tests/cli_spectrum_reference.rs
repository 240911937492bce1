//! Issue 15's must-show spectra, through the CLI with no options beyond the mesh
//! (`ricci spectrum MESH --json`), against values from outside this code: the issue's reference
//! column (harmonic 1-forms: kitten 2.1790, bob_tri 1.7960, rocker-arm 1.2869; the smooth
//! torus of revolution R = 1, r = 0.25: √15), paper 002's Table 4 (Eight1: 1.121486, 1.142314)
//! and Table 3 (Holes3, the first ten lengths). Needs `RICCI_MESHES`.

use serde_json::Value;
use std::process::Command;

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;

fn spectrum(mesh: &str, count: usize) -> Option<Vec<f64>> {
    let dir = ricci_meshes::ricci_meshes().filter(|d| d.is_dir())?;
    let out = Command::new(env!("CARGO_BIN_EXE_ricci"))
        .arg("spectrum")
        .arg(dir.join(mesh))
        .args(["--json", "--count", &count.to_string()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{mesh}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    Some(
        v["lengths"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect(),
    )
}

fn rel(x: f64, want: f64) -> f64 {
    (x / want - 1.0).abs()
}

/// Genus 1: the normalized lattice's first length that is not a multiple of the shortest.
fn second_length(sp: &[f64]) -> f64 {
    *sp.iter()
        .find(|&&x| (x - x.round()).abs() > 1e-3)
        .expect("a length that is not a multiple of the shortest")
}

#[test]
fn genus_one_spectra_match_the_issue_references() {
    for (mesh, want, tol) in [
        ("kitten.nf20k.off", 2.1790, 3e-3),
        ("bob_tri.obj", 1.7960, 3e-3),
        ("rocker-arm.off", 1.2869, 3e-3),
        // The coarse polyhedral torus (1200 vertices) is not the smooth one: +0.41 % with
        // every scheme, also plain vertex scaling without flips (docs/notes/wave2-dce.md).
        ("torus.off", 15f64.sqrt(), 5e-3),
    ] {
        let Some(sp) = spectrum(mesh, 8) else {
            eprintln!("RICCI_MESHES unset: skipping");
            return;
        };
        let x = second_length(&sp);
        eprintln!(
            "{mesh}: {x:.5} against {want:.5} ({:+.3} %)",
            100.0 * (x / want - 1.0)
        );
        assert!(rel(x, want) <= tol, "{mesh}: {x} against {want}");
    }
}

#[test]
fn eight_and_3holes_match_paper_002() {
    let Some(eight) = spectrum("eight.off", 4) else {
        eprintln!("RICCI_MESHES unset: skipping");
        return;
    };
    // Eight1's two shortest (Table 4); ours, a symmetric model, has one length twice.
    for (x, want) in eight.iter().zip([1.121486, 1.142314]) {
        eprintln!(
            "eight: {x:.6} against {want} ({:+.3} %)",
            100.0 * (x / want - 1.0)
        );
        assert!(rel(*x, want) <= 1.5e-2, "eight: {x} against {want}");
    }
    let holes = spectrum("3holes.off", 10).unwrap();
    let table3 = [
        2.349592, 2.354404, 2.358875, 2.376324, 2.702315, 3.588764, 3.605088, 3.614748, 3.675990,
        3.698398,
    ];
    for (x, want) in holes.iter().zip(table3) {
        eprintln!(
            "3holes: {x:.6} against {want} ({:+.3} %)",
            100.0 * (x / want - 1.0)
        );
        assert!(rel(*x, want) <= 2e-2, "3holes: {x} against {want}");
    }
    assert_eq!(holes.len(), 10);
}
