//! `ricci flow`: one JSON object on stdout with the contract's keys, METRIC.json that other
//! tools can use (its lengths really have the reported curvature), exit codes 1 (bad input) and
//! 2 (bad arguments) with nothing written.

use ricci::mesh::io::read_surface;
use ricci::metric::{self, Geometry};
use std::path::PathBuf;
use std::process::Command;

#[path = "../../ricci/tests/ricci_meshes/mod.rs"]
mod ricci_meshes;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-flow-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn generate(kind: &str, file: &str) -> PathBuf {
    let out = scratch(file);
    let o = ricci()
        .args(["generate", kind, "-n", "16", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

#[test]
fn hyperbolic_flow_writes_a_usable_metric() {
    let mesh = generate("genus2", "g2.off");
    let metric_file = scratch("g2-metric.json");
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args([
            "--geometry",
            "hyperbolic",
            "--tolerance",
            "1e-11",
            "--json",
            "--out",
        ])
        .arg(&metric_file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("stdout is one JSON object");
    for key in [
        "geometry",
        "scheme",
        "solver",
        "iterations",
        "max_curvature_error",
        "gauss_bonnet_error",
        "converged",
        "seconds",
        "route",
        "history",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(v["geometry"], "hyperbolic");
    // The default scheme: discrete conformal equivalence with intrinsic Delaunay flips.
    assert_eq!(v["scheme"], "conformal");
    assert!(v["flips"].as_u64().is_some(), "flips reported");
    assert_eq!(v["converged"], true);
    assert!(v["max_curvature_error"].as_f64().unwrap() <= 1e-11);
    assert_eq!(
        v["history"].as_array().unwrap().len(),
        v["iterations"].as_u64().unwrap() as usize + 1
    );
    // The metric file: per-vertex u, K, K̄; per-edge lengths with their vertices.
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&metric_file).unwrap()).unwrap();
    let (s, _) = read_surface(&mesh).unwrap();
    let n = s.mesh.n_vertices();
    assert_eq!(m["u"].as_array().unwrap().len(), n);
    assert_eq!(m["curvature"].as_array().unwrap().len(), n);
    assert_eq!(m["target_curvature"].as_array().unwrap().len(), n);
    // The metric lives on its intrinsic triangulation, written as `faces` (input vertices
    // keep their ids): rebuild that mesh and check the edges against it.
    assert_eq!(m["triangulation"], "intrinsic");
    let faces: Vec<[u32; 3]> = m["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            let t = t.as_array().unwrap();
            [0, 1, 2].map(|k| t[k].as_u64().unwrap() as u32)
        })
        .collect();
    let nv = faces
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap()
        .max(n);
    let tm = ricci::mesh::Mesh::from_triangles(nv, faces).unwrap();
    let chi =
        |m: &ricci::mesh::Mesh| m.n_vertices() as i64 - m.n_edges() as i64 + m.n_faces() as i64;
    assert_eq!(chi(&tm), chi(&s.mesh), "the same surface");
    let ev = m["edge_vertices"].as_array().unwrap();
    let lengths: Vec<f64> = m["lengths"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(lengths.len(), tm.n_edges());
    for (e, pair) in ev.iter().enumerate() {
        let a = pair[0].as_u64().unwrap() as u32;
        let b = pair[1].as_u64().unwrap() as u32;
        let mut want = tm.edge_vertices(e as u32);
        want.sort();
        let mut got = [a, b];
        got.sort();
        assert_eq!(got, want, "edge {e}");
    }
    // Recompute the curvature of the written lengths on that triangulation: zero everywhere
    // (uniform H² target; vertices added by splits are flat).
    let k = metric::curvature(&tm, Geometry::Hyperbolic, &lengths);
    assert!(
        k.iter().all(|x| x.abs() < 1e-9),
        "written metric is not hyperbolic"
    );
    let area = metric::total_area(&tm, Geometry::Hyperbolic, &lengths);
    assert!(
        (area - 4.0 * std::f64::consts::PI).abs() < 1e-8,
        "area {area}"
    );
}

#[test]
fn free_boundary_marks_fixed_vertices_with_null_targets() {
    let mesh = generate("disk", "disk.obj");
    let metric_file = scratch("disk-metric.json");
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args(["--target", "free-boundary", "--scheme", "yamabe", "--out"])
        .arg(&metric_file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("converged"), "{text}");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&metric_file).unwrap()).unwrap();
    let (s, _) = read_surface(&mesh).unwrap();
    for v in 0..s.mesh.n_vertices() {
        let t = &m["target_curvature"][v];
        assert_eq!(
            t.is_null(),
            s.mesh.is_boundary_vertex(v as u32),
            "vertex {v}"
        );
        if s.mesh.is_boundary_vertex(v as u32) {
            assert_eq!(m["u"][v].as_f64().unwrap(), 0.0, "boundary u stays 0");
        }
    }
}

#[test]
fn refusals_exit_with_the_right_code_and_write_nothing() {
    let mesh = generate("torus", "torus.off");
    let metric_file = scratch("refused.json");
    // Bad argument: exit 2.
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args(["--scheme", "banana", "--out"])
        .arg(&metric_file)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    // The same with --json: exit 2 and `{"error": …}` naming the argument.
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args(["--scheme", "banana", "--json"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    assert!(
        v["error"].as_str().is_some_and(|e| e.contains("banana")),
        "{v}"
    );
    // Inadmissible target (Gauss–Bonnet): exit 1, one sentence naming the problem.
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args(["--target", "cone:0=pi", "--json", "--out"])
        .arg(&metric_file)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    // With --json, stdout holds exactly `{"error": sentence}`, the sentence of stderr.
    let v: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("with --json, a failure prints one JSON object");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        v.as_object().map(|m| m.len()),
        Some(1),
        "only the error key: {v}"
    );
    assert_eq!(
        format!("error: {}", v["error"].as_str().unwrap_or("")),
        err.trim(),
        "the JSON error is the stderr sentence"
    );
    assert!(
        err.contains("Gauss–Bonnet") && err.contains("off by"),
        "{err}"
    );
    // A target file with a bad line: exit 1, the file and line named.
    let tf = scratch("targets.txt");
    std::fs::write(&tf, "0\n0\nnot-a-number\n").unwrap();
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .arg(format!("--target=file:{}", tf.display()))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 3"), "{err}");
    assert!(!metric_file.exists(), "no metric written on refusal");
}

/// `--widen-boundary N` refines the mesh, so it needs `--refined-out` (exit 2 without); with
/// it, the refined mesh is written and the metric file matches it vertex for vertex.
#[test]
fn widen_boundary_writes_the_refined_mesh() {
    let mesh = generate("disk", "disk.off");
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args(["--widen-boundary", "3"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let refined = scratch("disk-refined.off");
    let metric_file = scratch("disk-metric.json");
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args([
            "--target",
            "round-boundary",
            "--widen-boundary",
            "3",
            "--json",
            "--refined-out",
        ])
        .arg(&refined)
        .arg("--out")
        .arg(&metric_file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (r, _) = read_surface(&refined).unwrap();
    let (s, _) = read_surface(&mesh).unwrap();
    assert_eq!(
        j["refinement"]["vertices"].as_u64().unwrap() as usize,
        r.mesh.n_vertices()
    );
    assert_eq!(
        r.mesh.n_vertices(),
        s.mesh.n_vertices() + j["refinement"]["splits"].as_u64().unwrap() as usize
    );
    for v in r.mesh.boundary_loops().into_iter().flatten() {
        assert!(r.mesh.vertex_faces(v).count() >= 3);
    }
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&metric_file).unwrap()).unwrap();
    assert_eq!(
        m["vertices"].as_u64().unwrap() as usize,
        r.mesh.n_vertices()
    );
    assert_eq!(j["converged"], true);
}

/// `--refine-degenerate N` also needs `--refined-out` (exit 2 without); with it, the mesh
/// the metric lives on is written, input vertices first and unmoved.
#[test]
fn refine_degenerate_writes_the_refined_mesh() {
    let mesh = generate("disk", "disk-rd.off");
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args(["--refine-degenerate", "5"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let refined = scratch("disk-rd-refined.off");
    let metric_file = scratch("disk-rd-metric.json");
    let o = ricci()
        .arg("flow")
        .arg(&mesh)
        .args([
            "--target",
            "round-boundary",
            "--scheme",
            "yamabe",
            "--widen-boundary",
            "3",
            "--refine-degenerate",
            "5",
            "--json",
            "--refined-out",
        ])
        .arg(&refined)
        .arg("--out")
        .arg(&metric_file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["converged"], true);
    let (r, _) = read_surface(&refined).unwrap();
    let (s, _) = read_surface(&mesh).unwrap();
    assert_eq!(
        r.mesh.n_vertices(),
        s.mesh.n_vertices() + j["refinement"]["splits"].as_u64().unwrap() as usize
    );
    for v in 0..s.mesh.n_vertices() {
        for i in 0..3 {
            assert!((r.positions[v][i] - s.positions[v][i]).abs() <= 1e-9);
        }
    }
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&metric_file).unwrap()).unwrap();
    assert_eq!(
        m["vertices"].as_u64().unwrap() as usize,
        r.mesh.n_vertices()
    );
}

/// `--refine-degenerate` with the default conformal scheme (the README's face.off example):
/// that flow's lengths belong to its intrinsic triangulation, so there is nothing of the input
/// to bisect. The refined mesh must be the one `--widen-boundary 3` alone writes, and the flow
/// converged. (Read as lengths of the input's edges, they flagged thousands of faces: 2 rounds
/// added 3 788 vertices and reported "not converged"; 40 rounds doubled the mesh until it
/// ran out of time.)
#[test]
fn refine_degenerate_with_the_conformal_scheme_bisects_nothing() {
    let Some(meshes) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set: skipped");
        return;
    };
    let face = meshes.join("face.off");
    let run = |extra: &[&str], refined: &PathBuf| {
        let o = ricci()
            .arg("flow")
            .arg(&face)
            .args(["--target", "round-boundary", "--widen-boundary", "3"])
            .args(extra)
            .args(["--json", "--refined-out"])
            .arg(refined)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(j["scheme"], "conformal");
        assert_eq!(j["converged"], true, "{j}");
        assert_eq!(j["degenerate_faces"], 0);
        read_surface(refined).unwrap().0.mesh
    };
    let widened = run(&[], &scratch("face-widened.off"));
    let refined = run(&["--refine-degenerate", "3"], &scratch("face-refined.off"));
    assert_eq!(refined.n_vertices(), widened.n_vertices());
    assert_eq!(refined.faces(), widened.faces());
}
