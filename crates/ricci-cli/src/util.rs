//! Small helpers shared by the subcommands: atomic file output, JSON printing, exit codes,
//! reading the input mesh.
//!
//! The Python package (`crates/ricci-py`) runs the subcommands' own `run` functions so that
//! its results are the CLI's JSON to the last digit. For that, three of these helpers have an
//! in-memory mode on the calling thread ([`Capture`]): [`read_surface`] can be handed an
//! already validated surface (numpy arrays) under a name, [`print_json`] keeps the report
//! instead of printing it, and [`write_atomic`] keeps files whose path starts with
//! [`MEMORY_PREFIX`] instead of writing them. Without a capture they do what the CLI does.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use ricci::mesh::{BuildReport, Surface};

/// CPU time of this process so far (user + system, all threads) in seconds, from
/// `/proc/self/stat` (Linux; clock ticks of 1/100 s, the kernel's `USER_HZ`); `None` elsewhere.
/// The demo reports it per stage, so that stage costs can be compared on a busy machine, where
/// wall times mostly measure the other processes.
pub fn process_cpu_seconds() -> Option<f64> {
    stat_cpu_seconds("/proc/self/stat")
}

/// CPU time (user + system) of one thread of this process, by its kernel thread id (see
/// [`current_thread_id`]), from `/proc/self/task/ID/stat`; `None` elsewhere or when the thread
/// has ended.
pub fn thread_cpu_seconds(tid: u32) -> Option<f64> {
    stat_cpu_seconds(&format!("/proc/self/task/{tid}/stat"))
}

/// The kernel's id of the calling thread (the first field of `/proc/thread-self/stat`);
/// `None` where there is no such file.
pub fn current_thread_id() -> Option<u32> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    stat.split_whitespace().next()?.parse().ok()
}

/// utime + stime of a `stat` file of `/proc`, in seconds.
fn stat_cpu_seconds(path: &str) -> Option<f64> {
    let stat = std::fs::read_to_string(path).ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces): state
    // is field 3, utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace().skip(11);
    let utime: f64 = fields.next()?.parse().ok()?;
    let stime: f64 = fields.next()?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// Output paths starting with this are kept in memory by an active [`Capture`].
pub const MEMORY_PREFIX: &str = "<memory>/";

/// What one subcommand run produced, kept on its thread instead of printed or written.
#[derive(Default)]
pub struct Capture {
    /// A surface to return from [`read_surface`] for the path `input.0` (instead of reading).
    pub input: Option<(PathBuf, Surface, BuildReport)>,
    /// The JSON report [`print_json`] was given.
    pub json: Option<serde_json::Value>,
    /// Files written to paths under [`MEMORY_PREFIX`], by path.
    pub files: BTreeMap<String, Vec<u8>>,
    /// JSON files given to [`write_json_atomic`] under [`MEMORY_PREFIX`], by path, unprinted.
    pub json_files: BTreeMap<String, serde_json::Value>,
}

thread_local! {
    static CAPTURE: RefCell<Option<Capture>> = const { RefCell::new(None) };
}

/// Run `f` with `capture` active on this thread; returns `f`'s result and what was captured.
/// The capture is removed again even when `f` panics.
pub fn with_capture<T>(capture: Capture, f: impl FnOnce() -> T) -> (T, Capture) {
    struct Reset;
    impl Drop for Reset {
        fn drop(&mut self) {
            CAPTURE.with(|c| c.borrow_mut().take());
        }
    }
    CAPTURE.with(|c| *c.borrow_mut() = Some(capture));
    let reset = Reset;
    let out = f();
    let captured = CAPTURE.with(|c| c.borrow_mut().take()).unwrap_or_default();
    drop(reset);
    (out, captured)
}

/// Read and validate the input mesh (`ricci::mesh::io::read_surface`), or return the surface
/// an active [`Capture`] holds under this path.
pub fn read_surface(path: &Path) -> ricci::Result<(Surface, BuildReport)> {
    let given = CAPTURE.with(|c| {
        c.borrow().as_ref().and_then(|c| {
            c.input
                .as_ref()
                .filter(|(p, _, _)| p == path)
                .map(|(_, s, r)| (s.clone(), r.clone()))
        })
    });
    match given {
        Some(x) => Ok(x),
        None if path.is_dir() => Err(ricci::Error::input(format!(
            "{}: this is a folder, not a mesh file (.obj, .off, .ply or .stl); to run a \
             subcommand on every mesh of a folder, try: ricci batch {} --out runs -- info",
            path.display(),
            path.display()
        ))),
        None => ricci::mesh::io::read_surface(path),
    }
}

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

/// Make a refusal say which file it is about and end with one `try: …` that works (issue 22
/// item 3): `sentence` is the error of subcommand `sub` run on the mesh `mesh` (its first
/// positional argument). Library errors do not know file names, and only the CLI knows which
/// command to suggest; sentences that already name the file or carry a `try:` keep theirs.
pub fn refusal(sub: &str, mesh: Option<&str>, sentence: String) -> String {
    let Some(mesh) = mesh else {
        return sentence;
    };
    let mut s = if sentence.contains(mesh) {
        sentence
    } else {
        format!("{mesh}: {sentence}")
    };
    // A suggestion without the command: complete it.
    if let Some(rest) =
        s.strip_suffix("try: --scheme conformal (the default), which has no such condition")
    {
        s = format!(
            "{rest}try: ricci {sub} {mesh} (the default conformal scheme has no such condition)"
        );
    }
    if s.contains("try: ") {
        return s;
    }
    let lower = s.to_lowercase();
    let line_no = s
        .split("line ")
        .nth(1)
        .and_then(|t| t.split(|c: char| !c.is_ascii_digit()).next())
        .filter(|t| !t.is_empty());
    let suggestion = if lower.contains("no such file") {
        let dir = Path::new(mesh)
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map_or(".".into(), |p| p.display().to_string());
        format!("ls {dir} (the files there)")
    } else if lower.contains("unknown mesh format") {
        format!("file {mesh} (what the file holds)")
    } else if let Some(n) = line_no {
        format!("sed -n {n}p {mesh} (the line)")
    } else if lower.contains("genus-0")
        || lower.contains("genus 0")
        || lower.contains("euler characteristic 2")
    {
        format!("ricci layout {mesh} (a closed genus-0 surface: its conformal map to the sphere)")
    } else if sub == "pou" && lower.contains("euler characteristic") {
        format!("ricci spline {mesh} --out spline (genus 1 and open surfaces)")
    } else if sub == "layout" && lower.contains("gauss–bonnet") {
        format!("ricci layout {mesh} (the geometry its topology asks for)")
    } else if sub == "render" && lower.contains("faces, but the mesh has") {
        format!("ricci layout {mesh} --out uv.obj (a layout on this mesh's faces)")
    } else {
        return s;
    };
    format!("{s}; try: {suggestion}")
}

/// Write a file atomically: to a temporary file next to it, then rename. Nothing
/// half-written is left behind if writing fails.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let kept = CAPTURE.with(|c| match c.borrow_mut().as_mut() {
        Some(c) if path.to_string_lossy().starts_with(MEMORY_PREFIX) => {
            c.files
                .insert(path.to_string_lossy().into_owned(), bytes.to_vec());
            true
        }
        _ => false,
    });
    if kept {
        return Ok(());
    }
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
    WRITTEN.with(|w| {
        if let Some(w) = w.borrow_mut().as_mut() {
            w.push(path.to_path_buf());
        }
    });
    Ok(())
}

thread_local! {
    /// The files [`write_atomic`] wrote on this thread inside [`all_or_nothing`].
    static WRITTEN: RefCell<Option<Vec<PathBuf>>> = const { RefCell::new(None) };
}

/// Runs `f`; when it fails, removes the files [`write_atomic`] wrote on this thread meanwhile,
/// and `dir` if it did not exist before and is left empty: a command that fails after writing
/// part of its output leaves none of it (nor a mix of old and new files) behind.
pub fn all_or_nothing<T>(
    dir: Option<&Path>,
    f: impl FnOnce() -> anyhow::Result<T>,
) -> anyhow::Result<T> {
    let existed = dir.map(|d| d.exists());
    let outer = WRITTEN.with(|w| w.borrow_mut().replace(Vec::new()));
    let r = f();
    let written = WRITTEN.with(|w| std::mem::replace(&mut *w.borrow_mut(), outer));
    let written = written.unwrap_or_default();
    if r.is_err() {
        for p in &written {
            let _ = std::fs::remove_file(p);
        }
        if let (Some(d), Some(false)) = (dir, existed) {
            // only when empty: the directory may hold files written outside `f`
            let _ = std::fs::remove_dir(d);
        }
    } else {
        WRITTEN.with(|w| {
            if let Some(w) = w.borrow_mut().as_mut() {
                w.extend(written);
            }
        });
    }
    r
}

/// Set once a command has printed its JSON object, so that a failure after it (e.g. the demo
/// exiting 1 after writing the report of its other stages) does not print a second one.
static PRINTED_JSON: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Write a JSON file atomically (compact); an active [`Capture`] keeps the value itself for
/// paths under [`MEMORY_PREFIX`] (no text made or parsed: kitten's metric is 1.4 MB of it).
pub fn write_json_atomic(path: &Path, v: serde_json::Value) -> anyhow::Result<()> {
    let mut v = Some(v);
    CAPTURE.with(|c| {
        if let Some(c) = c.borrow_mut().as_mut() {
            let name = path.to_string_lossy();
            if name.starts_with(MEMORY_PREFIX) {
                if let Some(v) = v.take() {
                    c.json_files.insert(name.into_owned(), v);
                }
            }
        }
    });
    match v {
        Some(v) => write_atomic(path, serde_json::to_string(&v)?.as_bytes()),
        None => Ok(()),
    }
}

/// Print one JSON object on stdout (or keep it in the active [`Capture`]).
pub fn print_json(v: &serde_json::Value) {
    PRINTED_JSON.store(true, std::sync::atomic::Ordering::SeqCst);
    let kept = CAPTURE.with(|c| match c.borrow_mut().as_mut() {
        Some(c) => {
            c.json = Some(v.clone());
            true
        }
        None => false,
    });
    if kept {
        return;
    }
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

/// A vertex id given on the command line (`flag` e.g. `--base`) must exist: a bad argument
/// (exit code 2), with the valid range.
pub fn check_vertex(flag: &str, v: u32, n_vertices: usize) -> Result<(), UsageError> {
    if (v as usize) < n_vertices {
        return Ok(());
    }
    Err(UsageError(format!(
        "{flag} {v}: the mesh has only {n_vertices} vertices (ids 0 to {})",
        n_vertices.saturating_sub(1)
    )))
}

/// Progress for long commands: the spinner on a terminal, and when stderr is not a terminal
/// (a log file, a batch, CI) one line per stage on stderr, `ricci: [  12.3 s] stage: message`,
/// and at most one line every 10 s within a stage — from 2 s on (`RICCI_PROGRESS_AFTER`
/// seconds), so that a command that fails at once still prints one sentence.
pub struct Reporter {
    pub bar: crate::cmd::layout::Bar,
    lines: bool,
    t0: std::time::Instant,
    after: f64,
    last: Option<std::time::Instant>,
    last_stage: String,
    /// The last stage and message reported and when a line was last printed, shared with the
    /// heartbeat thread of [`Reporter::with_heartbeat`].
    beat: std::sync::Arc<std::sync::Mutex<Beat>>,
    /// Seconds between heartbeat lines (10; `RICCI_PROGRESS_EVERY`).
    every: f64,
}

/// What [`Reporter::with_heartbeat`]'s thread needs to print its line.
struct Beat {
    stage: String,
    message: String,
    printed: std::time::Instant,
}

impl Reporter {
    /// `json`: no spinner (lines still go to stderr when it is not a terminal).
    pub fn new(json: bool) -> Reporter {
        use std::io::IsTerminal;
        Reporter {
            bar: crate::cmd::layout::spinner(json),
            lines: !std::io::stderr().is_terminal()
                && CAPTURE.with(|c| c.borrow().is_none())
                && std::env::var_os("RICCI_NO_PROGRESS_LINES").is_none(),
            t0: std::time::Instant::now(),
            after: std::env::var("RICCI_PROGRESS_AFTER")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(2.0),
            last: None,
            last_stage: String::new(),
            beat: std::sync::Arc::new(std::sync::Mutex::new(Beat {
                stage: String::new(),
                message: String::new(),
                printed: std::time::Instant::now(),
            })),
            every: std::env::var("RICCI_PROGRESS_EVERY")
                .ok()
                .and_then(|s| s.parse::<f64>().ok())
                .filter(|s| s.is_finite() && *s > 0.0)
                .unwrap_or(10.0),
        }
    }

    /// A line on stderr (when lines are on) regardless of throttling, e.g. an estimate.
    pub fn line(&mut self, message: &str) {
        if self.lines {
            eprintln!(
                "ricci: [{:7.1} s] {message}",
                self.t0.elapsed().as_secs_f64()
            );
        } else {
            self.bar.0.println(message);
        }
    }
}

impl Reporter {
    /// Runs `work` (a long step that reports nothing itself, e.g. the search for closed
    /// geodesics) after reporting `stage: message`; while it runs and lines are on, a line
    /// `stage: message (still running)` goes to stderr from [`Reporter`]'s start-up delay on
    /// and then every 10 s, so a log shows the command is alive.
    pub fn while_running<T: Send>(
        &mut self,
        stage: &str,
        message: &str,
        work: impl FnOnce() -> T + Send,
    ) -> T {
        use ricci::progress::Progress;
        self.report(stage, None, message);
        if !self.lines {
            return work();
        }
        let done = std::sync::atomic::AtomicBool::new(false);
        let (t0, after) = (self.t0, self.after);
        let printed_at_start = self.last_stage == stage;
        std::thread::scope(|scope| {
            scope.spawn(|| {
                let mut last = printed_at_start.then(std::time::Instant::now);
                while !done.load(std::sync::atomic::Ordering::Relaxed) {
                    std::thread::sleep(std::time::Duration::from_millis(100));
                    let due = last.is_none_or(|t| t.elapsed().as_secs_f64() >= 10.0);
                    if due && t0.elapsed().as_secs_f64() >= after {
                        eprintln!(
                            "ricci: [{:7.1} s] {stage}: {message} (still running)",
                            t0.elapsed().as_secs_f64()
                        );
                        last = Some(std::time::Instant::now());
                    }
                }
            });
            let out = work();
            done.store(true, std::sync::atomic::Ordering::Relaxed);
            out
        })
    }

    /// Runs `work` with this reporter and, when lines are on, a heartbeat: whenever no line
    /// went to stderr for `every` seconds (10; `RICCI_PROGRESS_EVERY`), one line
    /// `stage: message (still running)` with the last stage reported — for steps that report
    /// nothing while they work (one large sparse factorisation, e.g. the spline's fairing),
    /// so that a log shows the command is alive (issue 22 item 4).
    pub fn with_heartbeat<T>(&mut self, work: impl FnOnce(&mut Reporter) -> T) -> T {
        if !self.lines {
            return work(self);
        }
        let done = std::sync::atomic::AtomicBool::new(false);
        let (t0, after, every) = (self.t0, self.after, self.every);
        let beat = std::sync::Arc::clone(&self.beat);
        std::thread::scope(|scope| {
            scope.spawn(|| {
                while !done.load(std::sync::atomic::Ordering::Relaxed) {
                    std::thread::sleep(std::time::Duration::from_millis(50));
                    let Ok(mut b) = beat.lock() else { return };
                    if t0.elapsed().as_secs_f64() >= after
                        && b.printed.elapsed().as_secs_f64() >= every
                        && !b.stage.is_empty()
                    {
                        eprintln!(
                            "ricci: [{:7.1} s] {}: {} (still running)",
                            t0.elapsed().as_secs_f64(),
                            b.stage,
                            b.message
                        );
                        b.printed = std::time::Instant::now();
                    }
                }
            });
            let out = work(self);
            done.store(true, std::sync::atomic::Ordering::Relaxed);
            out
        })
    }
}

impl ricci::progress::Progress for Reporter {
    fn report(&mut self, stage: &str, fraction: Option<f64>, message: &str) {
        self.bar.report(stage, fraction, message);
        if let Ok(mut b) = self.beat.lock() {
            b.stage.clear();
            b.stage.push_str(stage);
            b.message.clear();
            b.message.push_str(message);
        }
        if !self.lines || self.t0.elapsed().as_secs_f64() < self.after {
            return;
        }
        let due = self
            .last
            .is_none_or(|t| t.elapsed() >= std::time::Duration::from_secs(10));
        if stage != self.last_stage || due {
            let pct = fraction.map_or(String::new(), |f| format!(" ({:.0}%)", 100.0 * f));
            eprintln!(
                "ricci: [{:7.1} s] {stage}{pct}: {message}",
                self.t0.elapsed().as_secs_f64()
            );
            self.last = Some(std::time::Instant::now());
            self.last_stage = stage.to_string();
            if let Ok(mut b) = self.beat.lock() {
                b.printed = std::time::Instant::now();
            }
        }
    }
}

/// A closed ring of 32 points around vertex `v` in the plane orthogonal to its normal, of
/// radius `fraction` × the bounding box diagonal, to mark a point on the surface in a picture.
pub fn ring_marker(
    pos: &[[f64; 3]],
    tris: &[[u32; 3]],
    v: u32,
    fraction: f64,
    color: ricci_render::color::Rgb,
) -> ricci_render::Polyline {
    let normals = ricci_render::render::vertex_normals(pos, tris);
    ring_around(pos, &normals, v, fraction * bbox_diagonal(pos), color)
}

/// [`ring_marker`] for every mark `(v, fraction, color)`, the vertex normals computed once (a
/// T-spline's picture rings hundreds of T-junctions).
pub fn ring_markers(
    pos: &[[f64; 3]],
    tris: &[[u32; 3]],
    marks: &[(u32, f64, ricci_render::color::Rgb)],
) -> Vec<ricci_render::Polyline> {
    let diag = bbox_diagonal(pos);
    let normals = ricci_render::render::vertex_normals(pos, tris);
    marks
        .iter()
        .map(|&(v, fraction, color)| ring_around(pos, &normals, v, fraction * diag, color))
        .collect()
}

fn bbox_diagonal(pos: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pos {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// The ring of radius `r` around vertex `v` orthogonal to its normal (`normals[v]`).
fn ring_around(
    pos: &[[f64; 3]],
    normals: &[[f64; 3]],
    v: u32,
    r: f64,
    color: ricci_render::color::Rgb,
) -> ricci_render::Polyline {
    let n = normals.get(v as usize).copied().unwrap_or([0.0, 0.0, 1.0]);
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let unit = |x: [f64; 3]| {
        let l = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt().max(1e-300);
        [x[0] / l, x[1] / l, x[2] / l]
    };
    let e1 = unit(cross(n, a));
    let e2 = unit(cross(n, e1));
    let c = pos.get(v as usize).copied().unwrap_or([0.0; 3]);
    ricci_render::Polyline {
        points: (0..32)
            .map(|i| {
                let t = i as f64 * std::f64::consts::TAU / 32.0;
                let (x, y) = (r * t.cos(), r * t.sin());
                [
                    c[0] + x * e1[0] + y * e2[0],
                    c[1] + x * e1[1] + y * e2[1],
                    c[2] + x * e1[2] + y * e2[2],
                ]
            })
            .collect(),
        color,
        width: 3.0,
        closed: true,
    }
}

/// Per-stage timings of one command run (`ricci layout`'s `timings`): CPU seconds of the
/// process (all threads, [`process_cpu_seconds`]) and wall seconds per stage, in the order the
/// stages ended.
#[derive(Default)]
struct Stages {
    last: Option<(std::time::Instant, f64)>,
    cpu: serde_json::Map<String, serde_json::Value>,
    wall: serde_json::Map<String, serde_json::Value>,
}

thread_local! {
    static STAGES: RefCell<Stages> = RefCell::new(Stages::default());
}

/// Start timing the stages of a command run (forgets earlier ones).
pub fn stages_start() {
    STAGES.with(|s| {
        *s.borrow_mut() = Stages {
            last: Some((
                std::time::Instant::now(),
                process_cpu_seconds().unwrap_or(f64::NAN),
            )),
            ..Stages::default()
        }
    });
}

/// End the stage `name` here (its time runs from the previous mark); a stage ended twice adds
/// up. Does nothing before [`stages_start`].
pub fn stage_done(name: &str) {
    STAGES.with(|s| {
        let mut s = s.borrow_mut();
        let Some((t, c)) = s.last else { return };
        let now_c = process_cpu_seconds().unwrap_or(f64::NAN);
        let add = |m: &mut serde_json::Map<String, serde_json::Value>, x: f64| {
            let prev = m.get(name).and_then(|v| v.as_f64()).unwrap_or(0.0);
            let v = prev + x;
            m.insert(
                name.to_string(),
                if v.is_finite() {
                    serde_json::json!((v * 1000.0).round() / 1000.0)
                } else {
                    serde_json::Value::Null
                },
            );
        };
        add(&mut s.cpu, now_c - c);
        add(&mut s.wall, t.elapsed().as_secs_f64());
        s.last = Some((std::time::Instant::now(), now_c));
    });
}

/// The stages timed since [`stages_start`]: (`timings`: CPU seconds per stage, null where the
/// CPU clock is not available; `timings_wall`: wall seconds per stage).
pub fn stages_take() -> (serde_json::Value, serde_json::Value) {
    STAGES.with(|s| {
        let s = std::mem::take(&mut *s.borrow_mut());
        (
            serde_json::Value::Object(s.cpu),
            serde_json::Value::Object(s.wall),
        )
    })
}
