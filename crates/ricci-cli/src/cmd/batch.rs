//! `ricci batch MANIFEST --out DIR [--jobs N] [--timeout S] [--retry-failed] [--json] --
//! COMMAND [ARGS]`: one subcommand over many meshes, in parallel, resumable (docs/DESIGN.md §4).
//!
//! MANIFEST is a text file with one mesh path a line (blank lines and `#` comments skipped;
//! relative paths are relative to the manifest's folder), or a folder: every mesh file in it
//! (`.obj .off .ply .stl`), sorted by name.
//!
//! Every mesh runs in its own process — this binary, `ricci COMMAND MESH ARGS --json` — so a
//! crash, an abort or a runaway on one mesh cannot take the batch down (`--timeout` kills a
//! runaway). In ARGS, `{stem}` is replaced by the mesh's result name (its file stem and a
//! hash of its path, unique in the batch), `{mesh}` by its path and `{out}` by DIR, so
//! per-mesh output files can be asked for: `-- flow --out {out}/metrics/{stem}.json`.
//!
//! Results: `DIR/results/<stem>.json` per mesh, one JSON object with `mesh` (the path given to
//! the command), `status` (`ok`, `error` — the command refused the mesh, `timeout` or
//! `crashed`), `error` (the command's one sentence, else null), `result` (the command's JSON
//! report, else null), `exit_code` and `seconds` (wall clock). Each is written atomically
//! (temporary file, then rename), so a batch killed at any moment leaves only whole results;
//! a rerun skips every mesh whose result exists (`--retry-failed`: except those whose status
//! is not `ok`) and so completes the rest. `DIR/results.jsonl` is rebuilt at the end from the
//! per-mesh files, one line per mesh in manifest order, also atomically.

use crate::util::{print_json, write_atomic, UsageError};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{json, Value};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct Args {
    /// A text file with one mesh path a line, or a folder of mesh files.
    pub manifest: PathBuf,
    /// Output folder: results/<stem>.json per mesh and results.jsonl.
    #[arg(long)]
    pub out: PathBuf,
    /// Meshes processed at the same time (default: the number of cores).
    #[arg(long, short = 'j')]
    pub jobs: Option<usize>,
    /// Kill a mesh's command after this many seconds (status `timeout`).
    #[arg(long)]
    pub timeout: Option<f64>,
    /// Run again the meshes whose recorded status is not `ok`.
    #[arg(long)]
    pub retry_failed: bool,
    /// Print one JSON object (the batch's summary) on stdout.
    #[arg(long)]
    pub json: bool,
    /// The subcommand and its arguments, after `--` (the mesh path is put after COMMAND).
    #[arg(last = true, required = true, value_name = "COMMAND [ARGS]")]
    pub command: Vec<String>,
}

/// Mesh file extensions a folder manifest picks up.
const MESH_EXTENSIONS: [&str; 4] = ["obj", "off", "ply", "stl"];

/// The meshes of a manifest file or folder, in order.
fn manifest_meshes(manifest: &Path) -> anyhow::Result<Vec<PathBuf>> {
    if manifest.is_dir() {
        let mut out: Vec<PathBuf> = std::fs::read_dir(manifest)
            .map_err(|e| anyhow::anyhow!("{}: {e}", manifest.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.is_file()
                    && p.extension()
                        .map(|x| x.to_string_lossy().to_lowercase())
                        .is_some_and(|x| MESH_EXTENSIONS.contains(&x.as_str()))
            })
            .collect();
        out.sort();
        return Ok(out);
    }
    let text = std::fs::read_to_string(manifest)
        .map_err(|e| anyhow::anyhow!("{}: {e}", manifest.display()))?;
    let base = manifest.parent().unwrap_or(Path::new(""));
    Ok(text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| {
            let p = PathBuf::from(l);
            if p.is_absolute() {
                p
            } else {
                base.join(p)
            }
        })
        .collect())
}

/// 64-bit FNV-1a of a string (a stable name for a path, not a security hash).
fn fnv1a(s: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in s.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Result name of a mesh: file stem plus 8 hex digits of its path's hash.
fn result_stem(mesh: &Path) -> String {
    let stem: String = mesh
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into())
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!(
        "{stem}-{:08x}",
        fnv1a(&mesh.display().to_string()) & 0xffff_ffff
    )
}

/// The one-sentence error of a failed command: its `error: …` line on stderr (or `{"error"}`
/// on stdout), else the last line of stderr.
fn error_sentence(stdout: &str, stderr: &str) -> Option<String> {
    if let Ok(v) = serde_json::from_str::<Value>(stdout) {
        if let Some(e) = v.get("error").and_then(|e| e.as_str()) {
            return Some(e.to_string());
        }
    }
    let lines: Vec<&str> = stderr.lines().map(str::trim).collect();
    lines
        .iter()
        .rev()
        .find_map(|l| l.strip_prefix("error: "))
        .or_else(|| lines.iter().rev().find(|l| !l.is_empty()).copied())
        .map(str::to_string)
}

/// Run one mesh's command; the JSON line of its result.
fn run_one(exe: &Path, mesh: &Path, args: &[String], timeout: Option<f64>) -> Value {
    let t0 = Instant::now();
    let mesh_name = mesh.display().to_string();
    let mut cmd = Command::new(exe);
    cmd.arg(&args[0])
        .arg(mesh)
        .args(&args[1..])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if !args.iter().any(|a| a == "--json") {
        cmd.arg("--json");
    }
    let line = |status: &str, error: Option<String>, result: Value, code: Option<i32>| {
        json!({
            "mesh": mesh_name,
            "status": status,
            "error": error,
            "result": result,
            "exit_code": code,
            "seconds": t0.elapsed().as_secs_f64(),
        })
    };
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            return line(
                "crashed",
                Some(format!("could not start {}: {e}", exe.display())),
                Value::Null,
                None,
            )
        }
    };
    // Read both pipes on their own threads, so a chatty command cannot block on a full pipe.
    let reader = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut buf);
            }
            String::from_utf8_lossy(&buf).into_owned()
        })
    };
    let out_thread = reader(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let err_thread = reader(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let mut timed_out = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break Ok(s),
            Ok(None) => {}
            Err(e) => break Err(e),
        }
        if timeout.is_some_and(|t| t0.elapsed().as_secs_f64() > t) {
            let _ = child.kill();
            timed_out = true;
            break child.wait();
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let stdout = out_thread.join().unwrap_or_default();
    let stderr = err_thread.join().unwrap_or_default();
    let status = match status {
        Ok(s) => s,
        Err(e) => return line("crashed", Some(format!("wait: {e}")), Value::Null, None),
    };
    let code = status.code();
    if timed_out {
        return line(
            "timeout",
            Some(format!(
                "killed after the time limit of {} s",
                timeout.unwrap_or(0.0)
            )),
            Value::Null,
            code,
        );
    }
    match code {
        Some(0) => match serde_json::from_str::<Value>(&stdout) {
            Ok(v) => line("ok", None, v, code),
            Err(e) => line(
                "error",
                Some(format!("the command's output is not one JSON object ({e})")),
                Value::Null,
                code,
            ),
        },
        Some(1) | Some(2) => line(
            "error",
            error_sentence(&stdout, &stderr)
                .or_else(|| Some(format!("exit code {}", code.unwrap_or(-1)))),
            Value::Null,
            code,
        ),
        _ => {
            let what = match code {
                Some(c) => format!("exit code {c}"),
                None => {
                    #[cfg(unix)]
                    {
                        use std::os::unix::process::ExitStatusExt;
                        format!("killed by signal {}", status.signal().unwrap_or(0))
                    }
                    #[cfg(not(unix))]
                    {
                        "killed".to_string()
                    }
                }
            };
            let detail = error_sentence("", &stderr)
                .map(|s| format!(": {s}"))
                .unwrap_or_default();
            line(
                "crashed",
                Some(format!("{what}{detail}")),
                Value::Null,
                code,
            )
        }
    }
}

/// Replace `{stem}`, `{mesh}` and `{out}` in the command's arguments.
fn substitute(args: &[String], stem: &str, mesh: &Path, out: &Path) -> Vec<String> {
    args.iter()
        .map(|a| {
            a.replace("{stem}", stem)
                .replace("{mesh}", &mesh.display().to_string())
                .replace("{out}", &out.display().to_string())
        })
        .collect()
}

/// Temporary files of `write_atomic` left by a batch that was killed.
fn remove_stale_temporaries(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') && name.contains(".tmp") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let Some(command) = a.command.first() else {
        return Err(UsageError(
            "give the command after `--`: ricci batch MANIFEST --out DIR -- flow".into(),
        )
        .into());
    };
    if command == "batch" {
        return Err(UsageError("a batch cannot run `batch`".into()).into());
    }
    if a.jobs == Some(0) {
        return Err(UsageError("--jobs must be at least 1".into()).into());
    }
    if a.timeout.is_some_and(|t| t.is_nan() || t <= 0.0) {
        return Err(UsageError("--timeout must be a positive number of seconds".into()).into());
    }
    let meshes = manifest_meshes(&a.manifest)?;
    let stems: Vec<String> = meshes.iter().map(|m| result_stem(m)).collect();
    let results_dir = a.out.join("results");
    std::fs::create_dir_all(&results_dir)
        .map_err(|e| anyhow::anyhow!("{}: {e}", results_dir.display()))?;
    remove_stale_temporaries(&results_dir);
    let result_path = |i: usize| results_dir.join(format!("{}.json", stems[i]));
    let recorded_ok = |i: usize| -> Option<bool> {
        let text = std::fs::read_to_string(result_path(i)).ok()?;
        let v: Value = serde_json::from_str(&text).ok()?;
        Some(v["status"] == "ok")
    };
    let pending: Vec<usize> = (0..meshes.len())
        .filter(|&i| match recorded_ok(i) {
            None => true,
            Some(ok) => a.retry_failed && !ok,
        })
        .collect();
    let skipped = meshes.len() - pending.len();
    let exe = std::env::current_exe()
        .map_err(|e| anyhow::anyhow!("cannot find the ricci binary: {e}"))?;
    let jobs = a
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .min(pending.len().max(1));

    let bar = ProgressBar::new(pending.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let (mut done, mut failed) = (0usize, 0usize);
    let message = |done: usize, failed: usize| {
        format!(
            "done {done}, failed {failed}, remaining {}",
            pending.len() - done - failed
        )
    };
    bar.set_message(message(0, 0));
    let next = AtomicUsize::new(0);
    let (tx, rx) = mpsc::channel::<anyhow::Result<bool>>();
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            let tx = tx.clone();
            let (next, pending, meshes, stems) = (&next, &pending, &meshes, &stems);
            let (exe, a, result_path) = (&exe, &a, &result_path);
            scope.spawn(move || loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&i) = pending.get(k) else { break };
                let args = substitute(&a.command, &stems[i], &meshes[i], &a.out);
                let v = run_one(exe, &meshes[i], &args, a.timeout);
                let ok = v["status"] == "ok";
                let written = serde_json::to_string(&v)
                    .map_err(anyhow::Error::from)
                    .and_then(|s| write_atomic(&result_path(i), s.as_bytes()));
                if tx.send(written.map(|_| ok)).is_err() {
                    break;
                }
            });
        }
        drop(tx);
        let mut first_error = None;
        for r in rx {
            match r {
                Ok(true) => done += 1,
                Ok(false) => failed += 1,
                Err(e) => {
                    failed += 1;
                    first_error.get_or_insert(e);
                }
            }
            bar.set_message(message(done, failed));
            bar.inc(1);
        }
        bar.finish_and_clear();
        first_error.map_or(Ok(()), Err)
    })?;

    // results.jsonl from the per-mesh files, in manifest order.
    let mut jsonl = String::new();
    let (mut ok_total, mut failed_total, mut missing) = (0usize, 0usize, 0usize);
    for i in 0..meshes.len() {
        let v = std::fs::read_to_string(result_path(i))
            .ok()
            .and_then(|t| serde_json::from_str::<Value>(&t).ok());
        match v {
            Some(v) => {
                if v["status"] == "ok" {
                    ok_total += 1;
                } else {
                    failed_total += 1;
                }
                jsonl.push_str(&serde_json::to_string(&v)?);
                jsonl.push('\n');
            }
            None => missing += 1,
        }
    }
    let jsonl_path = a.out.join("results.jsonl");
    write_atomic(&jsonl_path, jsonl.as_bytes())?;
    let summary = json!({
        "manifest": a.manifest.display().to_string(),
        "command": a.command,
        "meshes": meshes.len(),
        "ran": done + failed,
        "skipped": skipped,
        "ok": ok_total,
        "failed": failed_total,
        "missing": missing,
        "jobs": jobs,
        "results": jsonl_path.display().to_string(),
        "seconds": t0.elapsed().as_secs_f64(),
    });
    if a.json {
        print_json(&summary);
    } else {
        println!(
            "{} meshes: {} ok, {} failed ({} run now, {} already done); {}",
            meshes.len(),
            ok_total,
            failed_total,
            done + failed,
            skipped,
            jsonl_path.display()
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_sentence_prefers_the_error_line() {
        let e = error_sentence("", "warning: x\nerror: vertex 3 is non-manifold\n");
        assert_eq!(e.as_deref(), Some("vertex 3 is non-manifold"));
        let e = error_sentence("{\"error\": \"bad\"}", "error: other");
        assert_eq!(e.as_deref(), Some("bad"));
    }

    #[test]
    fn result_stems_differ_for_equal_file_names() {
        let a = result_stem(Path::new("a/kitten.off"));
        let b = result_stem(Path::new("b/kitten.off"));
        assert!(a.starts_with("kitten-") && b.starts_with("kitten-"));
        assert_ne!(a, b);
    }
}
