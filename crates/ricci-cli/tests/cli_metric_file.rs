//! `ricci layout --metric M.json` / `ricci spectrum --metric M.json` with a metric whose flow
//! did not converge (issue 15, "fix on the way"): refused when the file says so; when the file
//! does not say (its flags removed, as a hand-made file would be), the metric's own curvature
//! at the interior vertices, recomputed from its lengths, makes `layout` warn on stderr and in
//! the JSON and `spectrum` refuse with one sentence. A converged metric passes both silently.

use ricci::mesh::{generate, io::write_surface};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-cli-metric-file-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn ricci(args: &[&str], mesh: &Path, metric: Option<&Path>) -> (Output, Value) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ricci"));
    c.arg(args[0]).arg(mesh).args(&args[1..]);
    if let Some(m) = metric {
        c.arg("--metric").arg(m);
    }
    let out = c.output().unwrap();
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out, v)
}

#[test]
fn metric_files_that_did_not_converge_are_refused_or_warned_about() {
    let s = generate::torus(1.0, 0.4, 12).unwrap();
    let mesh = tmp("torus.obj");
    write_surface(&mesh, &s).unwrap();
    let (good, partial, stripped) = (tmp("good.json"), tmp("partial.json"), tmp("stripped.json"));
    let gs = good.display().to_string();
    let ps = partial.display().to_string();
    // A converged metric, and one stopped after one Newton step.
    let (o, _) = ricci(&["flow", "--json", "-o", &gs], &mesh, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (o, _) = ricci(
        &["flow", "--json", "--max-iterations", "1", "-o", &ps],
        &mesh,
        None,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut m: Value = serde_json::from_str(&std::fs::read_to_string(&partial).unwrap()).unwrap();
    assert_eq!(
        m["converged"].as_bool(),
        Some(false),
        "precondition: one step does not converge"
    );
    // The file says it did not converge: both refuse (exit 1, one sentence, {"error"}).
    for cmd in ["layout", "spectrum"] {
        let (o, v) = ricci(&[cmd, "--json"], &mesh, Some(&partial));
        assert_eq!(o.status.code(), Some(1), "{cmd}");
        let e = v["error"].as_str().unwrap_or("");
        assert!(e.contains("did not converge"), "{cmd}: {e}");
    }
    // The same lengths without the flags.
    for k in ["converged", "max_curvature_error", "degenerate_faces"] {
        m.as_object_mut().unwrap().remove(k);
    }
    std::fs::write(&stripped, m.to_string()).unwrap();
    let (o, v) = ricci(&["layout", "--json"], &mesh, Some(&stripped));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning") && err.contains("interior vertex"),
        "layout: no warning on stderr: {err}"
    );
    let w = v["metric"]["warning"].as_str().unwrap_or("");
    assert!(w.contains("curvature"), "layout: no warning in the JSON");
    // The recomputed curvature: above the threshold, and a real vertex.
    let k = v["metric"]["max_interior_curvature"].as_f64().unwrap();
    assert!(k > 1e-6, "max |K| {k}");
    assert!(
        v["metric"]["max_interior_curvature_vertex"]
            .as_u64()
            .unwrap()
            < 10_000
    );
    let (o, v) = ricci(&["spectrum", "--json"], &mesh, Some(&stripped));
    assert_eq!(o.status.code(), Some(1));
    let e = v["error"].as_str().unwrap_or("");
    assert!(
        e.contains("curvature") && e.contains("interior vertex"),
        "spectrum: {e}"
    );
    // The converged metric: no warning, a spectrum.
    for cmd in ["layout", "spectrum"] {
        let (o, v) = ricci(&[cmd, "--json"], &mesh, Some(&good));
        assert!(
            o.status.success(),
            "{cmd}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            !String::from_utf8_lossy(&o.stderr).contains("warning"),
            "{cmd}: a warning for a converged metric"
        );
        assert!(v["metric"]["warning"].is_null(), "{cmd}");
        assert!(v["metric"]["max_interior_curvature"].as_f64().unwrap() <= 1e-8);
    }
}
