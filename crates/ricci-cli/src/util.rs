//! Small helpers shared by the subcommands: atomic file output, JSON printing, exit codes.

use std::io::Write;
use std::path::Path;

/// Error raised for bad command-line arguments that clap cannot check (exit code 2).
#[derive(Debug)]
pub struct UsageError(pub String);
impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for UsageError {}

/// 2 for usage errors, 1 for everything else (bad input data, I/O).
pub fn exit_code(e: &anyhow::Error) -> i32 {
    if e.downcast_ref::<UsageError>().is_some() {
        2
    } else {
        1
    }
}

/// The error chain as one sentence.
pub fn sentence(e: &anyhow::Error) -> String {
    let mut s = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !s.contains(&c) {
            s.push_str(": ");
            s.push_str(&c);
        }
    }
    s
}

/// Write a file atomically: to a temporary file next to it, then rename. Nothing
/// half-written is left behind if writing fails.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let res = (|| -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = res {
        let _ = std::fs::remove_file(&tmp);
        anyhow::bail!("{}: {e}", path.display());
    }
    Ok(())
}

/// Set once a command has printed its JSON object, so that a failure after it (e.g. the demo
/// exiting 1 after writing the report of its other stages) does not print a second one.
static PRINTED_JSON: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Print one JSON object on stdout.
pub fn print_json(v: &serde_json::Value) {
    PRINTED_JSON.store(true, std::sync::atomic::Ordering::SeqCst);
    println!(
        "{}",
        serde_json::to_string_pretty(v).unwrap_or_else(|_| "{}".into())
    );
}

/// Print `{"error": sentence}` on stdout (a failed command run with `--json`).
/// Nothing is printed if the command printed its own JSON object already.
pub fn print_error_json(sentence: &str) {
    if PRINTED_JSON.swap(true, std::sync::atomic::Ordering::SeqCst) {
        return;
    }
    println!("{}", serde_json::json!({ "error": sentence }));
}
