//! `ricci demo --out DIR [--json] [--resolution N]`: the whole pipeline on the built-in
//! genus-2 surface, with pictures, tables and a static `DIR/index.html` (docs/DESIGN.md §1, §4).
//!
//! The demo is a list of [`STAGES`]; each stage reads what earlier stages left in the
//! [`Ctx`], writes its files through the [`Env`] and returns a [`Section`] (text, pictures, tables, files and a JSON
//! summary) for the page and for `--json`. A stage whose inputs failed is skipped and says so;
//! a stage that fails is shown as failed in the page, its files are dropped, and the command
//! exits with status 1 after writing the report of everything else.
//!
//! Everything is written into a hidden staging folder inside DIR first (each file atomically)
//! and moved into DIR when all stages have run, `index.html` last: an interrupted run leaves
//! no half-written file in DIR.
//!
//! For tests of that path, the environment variable `RICCI_DEMO_FAIL=ID` makes stage `ID`
//! fail at its start (as if the library had returned an error).
//!
//! Adding a stage: write `pub fn NAME(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section>`
//! in its own file `demo/NAME.rs` (shared helpers are in `demo/common.rs`), declare it with
//! `mod NAME;` below, put what later stages need into [`Ctx`], and add one entry to
//! [`STAGES`], the one list of stages; remove its entry from [`PLACEHOLDERS`].

// One file per stage (in the order of [`STAGES`]); `common` holds what several share.
mod atlas;
mod beside;
mod common;
mod cone;
mod flow;
mod layout;
mod loops;
mod pou;
mod spectrum;
mod spline;
mod surface;

mod forms_stage;
mod geodesics_stage;
mod param_stage;
mod report;
mod tspline_stage;

use crate::util::{print_json, write_atomic, UsageError};
use indicatif::{ProgressBar, ProgressStyle};
use report::{Page, Section, Status};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use common::Ctx;

/// Where a stage writes its files and reports its progress.
pub struct Env<'a> {
    pub out: &'a mut Out,
    pub bar: &'a mut StageBar,
}

#[derive(clap::Args)]
pub struct Args {
    /// Output folder (created if missing; files of the same names are replaced).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Edges around each handle of the built-in genus-2 surface (12 to 200).
    // Read as a signed number so that a negative value gets the range check of `run`, not
    // clap's "not in 0..=4294967295".
    #[arg(long, short = 'n', default_value_t = 40, allow_hyphen_values = true)]
    pub resolution: i64,
    /// Print one JSON object on stdout (per-stage summaries and the file list).
    #[arg(long)]
    pub json: bool,
}

/// One stage of the demo.
pub struct Stage {
    /// Anchor in the page and key in the JSON.
    pub id: &'static str,
    pub title: &'static str,
    /// Paper section the stage follows (shown under the title).
    pub reference: &'static str,
    /// Stages whose results this one needs.
    pub needs: &'static [&'static str],
    pub run: fn(&mut Ctx, &mut Env) -> anyhow::Result<Section>,
}

/// The stages, in order.
pub const STAGES: &[Stage] = &[
    Stage {
        id: "surface",
        title: "Surface",
        reference: "built-in genus-2 surface (ricci::mesh::generate::genus), validation and topology",
        needs: &[],
        run: surface::surface,
    },
    Stage {
        id: "flow",
        title: "Hyperbolic uniformization",
        reference: "discrete conformal equivalence in H² (the default scheme; Gu–Luo–Sun–Wu 2018), Newton; the uniformization of paper 001 §V, paper 002 §4.3",
        needs: &["surface"],
        run: flow::hyperbolic_flow,
    },
    Stage {
        id: "cone",
        title: "Flat metric with a single cone",
        reference: "Euclidean Ricci flow (Thurston circle packing, the papers' scheme) with all curvature 2πχ on one vertex (paper 000 §4 Steps 2–3)",
        needs: &["surface"],
        run: cone::single_cone,
    },
    Stage {
        id: "loops",
        title: "Canonical loops",
        reference: "canonical fundamental group generators through a base vertex (paper 001 §V, paper 002 §4.3.2)",
        needs: &["flow"],
        run: loops::loops,
    },
    Stage {
        id: "layout",
        title: "Fundamental polygon and universal cover",
        reference: "isometric layout in the Poincaré disk, deck group, tiling (paper 001 §V–VI, paper 002 §4.3.3)",
        needs: &["loops"],
        run: layout::layout,
    },
    Stage {
        id: "spectrum",
        title: "Geodesic length spectrum",
        reference: "closed geodesics from the Fuchsian group, ℓ = 2 acosh(|tr|/2) (paper 002 §6.3.3)",
        needs: &["layout"],
        run: spectrum::spectrum,
    },
    Stage {
        id: "atlas",
        title: "Affine atlas with one extraordinary point",
        reference: "singularity placement, connectivity modification, flat cone metric (Thurston circle packing, the papers' scheme), charts and transitions (paper 000 §4 Steps 1–5, paper 002 §5.2)",
        needs: &["surface"],
        run: atlas::atlas,
    },
    Stage {
        id: "spline",
        title: "Manifold spline with one extraordinary point",
        reference: "manifold triangular B-splines (DMS) over the affine structure (flat cone metric by Thurston circle packing, the papers' scheme), fairing, G¹ hole filling (paper 000 §5)",
        needs: &["surface"],
        run: spline::spline,
    },
    Stage {
        id: "pou",
        title: "Partition-of-unity surface without extraordinary points",
        reference: "C∞ radial bumps on hyperbolic disks blending local quadratics over the hyperbolic structure (paper 004 §4)",
        needs: &["surface"],
        run: pou::pou,
    },

    Stage { id: "param", title: "Conformal UV map with cones", reference: "ricci param: greedy cones (Ben-Chen–Gotsman–Bunin 2008), conformal flow with intrinsic Delaunay flips, cut, UVs on the input's faces", needs: &["surface"], run: param_stage::param },
    Stage { id: "tspline", title: "Manifold T-spline of the surface", reference: "one cubic spline on the domain manifold's quad mesh of knot intervals (cylinders of a holomorphic 1-form glued by translations), least-squares fit with uniform refinement, continuity measured across every cell side (paper 003 §2–3)", needs: &["surface"], run: tspline_stage::tspline },
    Stage { id: "forms", title: "Holomorphic 1-forms and the conformal net", reference: "harmonic basis, Hodge star, period matrix, zeros, conformal net and critical horizontal trajectories (paper 002 §4.2, §6.3)", needs: &["surface"], run: forms_stage::forms },
    Stage { id: "geodesics", title: "Shortest closed geodesics on the surface", reference: "axes of the deck transformations of the shortest classes, pulled back into the fundamental polygon (paper 002 §6.3.3)", needs: &["layout"], run: geodesics_stage::geodesics },
];

/// Stages that run on a thread (and rayon pool) of their own, beside the stages after them,
/// as soon as the stages they need have succeeded ([`beside`]): the manifold spline is more
/// than half of the demo's CPU time and needs only the surface. Such a stage gets a copy of
/// the surface ([`Ctx::beside`]) and leaves nothing in the [`Ctx`]; a stage that needs it
/// waits for it. The page, the JSON and the pictures do not depend on this (only timings).
pub const BESIDE: &[&str] = &["spline"];

/// Stages announced in the page but not built yet (title, sentence).
pub const PLACEHOLDERS: &[(&str, &str)] = &[];

/// The files of a run, written into a staging folder inside the output folder and moved into
/// place at the end.
pub struct Out {
    dir: PathBuf,
    staging: PathBuf,
    files: Vec<String>,
    /// Whether this value removes the staging folder when dropped (a [`Out::sibling`] does
    /// not).
    owner: bool,
}

impl Out {
    fn new(dir: &Path) -> anyhow::Result<Out> {
        if dir.exists() && !dir.is_dir() {
            anyhow::bail!(
                "{}: the output path exists and is not a folder",
                dir.display()
            );
        }
        std::fs::create_dir_all(dir).map_err(|e| {
            anyhow::anyhow!("{}: cannot create the output folder ({e})", dir.display())
        })?;
        let staging = dir.join(format!(".ricci-demo-{}", std::process::id()));
        std::fs::create_dir_all(&staging).map_err(|e| {
            anyhow::anyhow!(
                "{}: cannot write into the output folder ({e})",
                dir.display()
            )
        })?;
        Ok(Out {
            dir: dir.to_path_buf(),
            staging,
            files: Vec::new(),
            owner: true,
        })
    }

    /// The same staging folder with a file list of its own (for a stage on another thread).
    fn sibling(&self) -> Out {
        Out {
            dir: self.dir.clone(),
            staging: self.staging.clone(),
            files: Vec::new(),
            owner: false,
        }
    }

    /// Write one file (atomically) into the staging folder.
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
        write_atomic(&self.staging.join(name), bytes)?;
        if !self.files.iter().any(|f| f == name) {
            self.files.push(name.to_string());
        }
        Ok(())
    }

    /// Forget (and delete) the files written after the first `keep`.
    fn drop_after(&mut self, keep: usize) {
        for f in self.files.drain(keep..) {
            let _ = std::fs::remove_file(self.staging.join(f));
        }
    }

    /// Move every file into the output folder, `index.html` last, and remove the staging
    /// folder.
    fn commit(&mut self) -> anyhow::Result<()> {
        self.files.sort_by_key(|f| f == "index.html");
        for f in &self.files {
            let to = self.dir.join(f);
            std::fs::rename(self.staging.join(f), &to)
                .map_err(|e| anyhow::anyhow!("{}: {e}", to.display()))?;
        }
        let _ = std::fs::remove_dir(&self.staging);
        Ok(())
    }
}

impl Drop for Out {
    fn drop(&mut self) {
        // After a commit the folder is empty; after an error nothing of it is kept.
        if self.owner {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// A spinner per stage on stderr: `[k/N] title — step: message`.
pub struct StageBar {
    bar: ProgressBar,
    prefix: String,
}

impl StageBar {
    fn new(hidden: bool) -> StageBar {
        let bar = if hidden {
            ProgressBar::hidden()
        } else {
            ProgressBar::new_spinner()
        };
        bar.set_style(
            ProgressStyle::with_template("{spinner} {elapsed:>3} {prefix} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        StageBar {
            bar,
            prefix: String::new(),
        }
    }
    fn stage(&mut self, k: usize, n: usize, title: &str) {
        self.prefix = format!("[{k}/{n}] {title}");
        self.bar.set_prefix(self.prefix.clone());
        self.bar.set_message("");
    }
    /// Announce a step of the current stage.
    pub fn step(&self, msg: &str) {
        self.bar.set_message(format!("— {msg}"));
    }
}

impl ricci::progress::Progress for StageBar {
    fn report(&mut self, stage: &str, _fraction: Option<f64>, message: &str) {
        self.bar.set_message(format!("— {stage}: {message}"));
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    if !(12..=200).contains(&a.resolution) {
        return Err(UsageError(format!(
            "--resolution {} must be between 12 and 200 edges around each handle",
            a.resolution
        ))
        .into());
    }
    let mut out = Out::new(&a.out)?;
    let mut bar = StageBar::new(a.json);
    let mut ctx = Ctx::new(a.resolution as u32);
    let sections = run_stages(&mut ctx, &mut out, &mut bar);
    bar.bar.finish_and_clear();

    let failed: Vec<&Section> = sections.iter().filter(|s| !s.status.usable()).collect();
    // demo.json and index.html; their names go into the file list first so it is complete.
    for f in ["demo.json", "index.html"] {
        if !out.files.iter().any(|x| x == f) {
            out.files.push(f.to_string());
        }
    }
    let total = t0.elapsed().as_secs_f64();
    let summary = summary_json(&a, &sections, &out.files, total);
    out.write(
        "demo.json",
        serde_json::to_string_pretty(&summary)?.as_bytes(),
    )?;
    let page = Page {
        title: "ricci — the pipeline on a genus-2 surface",
        subtitle: format!(
            "Discrete surface Ricci flow on the built-in genus-2 surface (resolution {}): \
             uniformization, canonical loops, the fundamental polygon in the Poincaré disk, \
             its tiling, the length spectrum, the affine atlas with one extraordinary point and \
             the manifold spline built on it. {} of {} stages succeeded.",
            a.resolution,
            sections.len() - failed.len(),
            sections.len()
        ),
        sections: &sections,
        placeholders: PLACEHOLDERS,
        total_seconds: total,
        command: format!(
            "ricci demo --out {} --resolution {}",
            a.out.display(),
            a.resolution
        ),
        files: vec![(
            "demo.json".into(),
            "the numbers of every stage (as --json prints them)".into(),
        )],
    };
    out.write("index.html", report::index_html(&page).as_bytes())?;
    out.commit()?;

    print_outcome(&a, &summary, &sections, total);
    if let Some(first) = failed.first() {
        anyhow::bail!(
            "{} of {} demo stages did not succeed (first: {}: {}); the report of the others is in {}",
            failed.len(),
            sections.len(),
            first.id,
            first.status.message().unwrap_or(""),
            a.out.join("index.html").display()
        );
    }
    Ok(())
}

/// Run the stages: in order on this thread, except those of [`BESIDE`], which start on their
/// own thread as soon as the stages they need are done. Returns the sections in the order of
/// [`STAGES`], and leaves the files in `out` in that order too.
fn run_stages(ctx: &mut Ctx, out: &mut Out, bar: &mut StageBar) -> Vec<Section> {
    let n = STAGES.len();
    let mut done: Vec<Option<Section>> = (0..n).map(|_| None).collect();
    let mut files: Vec<Vec<String>> = vec![Vec::new(); n];
    let mut started = vec![false; n];
    let mut running: Vec<beside::Beside> = Vec::new();
    for k in 0..n {
        // Start the stages of BESIDE whose needs are done (or skip them, if one failed).
        for (j, st) in STAGES.iter().enumerate().skip(k) {
            if started[j]
                || !BESIDE.contains(&st.id)
                || st.needs.iter().any(|id| !is_done(&done, id))
            {
                continue;
            }
            started[j] = true;
            let job = missing_needs(st, &done)
                .is_empty()
                .then(|| beside::Beside::start(j, st, ctx.beside(), out))
                .flatten();
            match job {
                Some(job) => running.push(job),
                None => {
                    bar.stage(j + 1, n, st.title);
                    let keep = out.files.len();
                    let missing = missing_needs(st, &done);
                    let s = run_stage(
                        st,
                        &missing,
                        ctx,
                        out,
                        bar,
                        &crate::util::process_cpu_seconds,
                    );
                    files[j] = out.files.split_off(keep);
                    progress_line(bar, j, st, &s);
                    done[j] = Some(s);
                }
            }
        }
        let st = &STAGES[k];
        if started[k] {
            continue;
        }
        // Wait for the stages running beside that this one needs.
        for id in st.needs {
            if let Some(i) = running.iter().position(|r| STAGES[r.k].id == *id) {
                let job = running.swap_remove(i);
                finish_beside(job, bar, &mut done, &mut files);
            }
        }
        bar.stage(k + 1, n, st.title);
        // The CPU time of this thread and the global pool: the process's minus the stages
        // running beside.
        let cpu_now = || {
            let others: Option<f64> = running.iter().map(|r| r.cpu.seconds()).sum();
            crate::util::process_cpu_seconds()
                .zip(others)
                .map(|(p, o)| p - o)
        };
        let keep = out.files.len();
        let missing = missing_needs(st, &done);
        let s = run_stage(st, &missing, ctx, out, bar, &cpu_now);
        files[k] = out.files.split_off(keep);
        progress_line(bar, k, st, &s);
        done[k] = Some(s);
        // Report the stages beside that have finished meanwhile.
        while let Some(i) = running.iter().position(|r| r.is_finished()) {
            finish_beside(running.swap_remove(i), bar, &mut done, &mut files);
        }
    }
    running.sort_by_key(|r| r.k);
    for job in running {
        let st = &STAGES[job.k];
        bar.stage(job.k + 1, n, st.title);
        bar.step("finishing (it ran beside the stages after it)");
        finish_beside(job, bar, &mut done, &mut files);
    }
    out.files = files.concat();
    done.into_iter()
        .zip(STAGES)
        .map(|(s, st)| {
            s.unwrap_or_else(|| {
                let mut s = Section::new(st.id, st.title, st.reference);
                s.status = Status::Failed("this stage failed: it was not run".into());
                s
            })
        })
        .collect()
}

/// Join a stage that ran beside, print its line and keep its section and files.
fn finish_beside(
    job: beside::Beside,
    bar: &StageBar,
    done: &mut [Option<Section>],
    files: &mut [Vec<String>],
) {
    let k = job.k;
    let (s, f) = job.join(&STAGES[k]);
    progress_line(bar, k, &STAGES[k], &s);
    files[k] = f;
    done[k] = Some(s);
}

/// Whether stage `id` has finished (successfully or not).
fn is_done(done: &[Option<Section>], id: &str) -> bool {
    STAGES
        .iter()
        .position(|s| s.id == id)
        .is_none_or(|i| done[i].is_some())
}

/// The stages `st` needs that did not succeed (or have not run).
fn missing_needs<'a>(st: &'a Stage, done: &[Option<Section>]) -> Vec<&'a str> {
    st.needs
        .iter()
        .copied()
        .filter(|id| {
            !done
                .iter()
                .flatten()
                .any(|s| s.id == *id && s.status.usable())
        })
        .collect()
}

/// The line of a finished stage on stderr: `✓ [k/N] title (seconds)`.
fn progress_line(bar: &StageBar, k: usize, st: &Stage, section: &Section) {
    bar.bar.println(format!(
        "{} [{}/{}] {} ({:.2} s){}",
        match section.status {
            Status::Ok => "✓",
            Status::Warning(_) => "!",
            _ => "✗",
        },
        k + 1,
        STAGES.len(),
        st.title,
        section.seconds,
        section
            .status
            .message()
            .map(|m| format!(": {m}"))
            .unwrap_or_default()
    ));
}

/// Run one stage (or skip it when stages it needs, `missing`, did not succeed) and time it (CPU
/// seconds by `cpu_now`); a failure drops the files the stage wrote and becomes the section's
/// status.
fn run_stage(
    st: &Stage,
    missing: &[&str],
    ctx: &mut Ctx,
    out: &mut Out,
    bar: &mut StageBar,
    cpu_now: &dyn Fn() -> Option<f64>,
) -> Section {
    let ts = Instant::now();
    let cpu0 = cpu_now();
    let mut section = if missing.is_empty() {
        let keep = out.files.len();
        let mut env = Env { out, bar };
        let result = match std::env::var("RICCI_DEMO_FAIL") {
            Ok(id) if id == st.id => {
                Err(anyhow::anyhow!("failure injected by RICCI_DEMO_FAIL={id}"))
            }
            _ => (st.run)(ctx, &mut env),
        };
        match result {
            Ok(s) => s,
            Err(e) => {
                out.drop_after(keep);
                let mut s = Section::new(st.id, st.title, st.reference);
                s.status =
                    Status::Failed(format!("this stage failed: {}", crate::util::sentence(&e)));
                s
            }
        }
    } else {
        let mut s = Section::new(st.id, st.title, st.reference);
        s.status = Status::Skipped(format!(
            "not run: it needs the stage{} {}, which did not succeed",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", ")
        ));
        s
    };
    section.id = st.id;
    section.title = st.title.to_string();
    section.reference = st.reference.to_string();
    section.seconds = ts.elapsed().as_secs_f64();
    section.cpu_seconds = cpu0.zip(cpu_now()).map(|(a, b)| b - a);
    section
}

/// The JSON summary (`--json`) or one line per stage on stdout; warnings on stderr.
fn print_outcome(a: &Args, summary: &Value, sections: &[Section], total: f64) {
    if a.json {
        print_json(summary);
    } else {
        println!(
            "{}: {} stages in {:.2} s",
            a.out.join("index.html").display(),
            sections.len(),
            total
        );
        for s in sections {
            println!(
                "  {:<9} {:<8} {:6.2} s  {}",
                s.id,
                s.status.name(),
                s.seconds,
                s.status.message().unwrap_or(&s.title)
            );
        }
    }
    for s in sections {
        if let Status::Warning(m) = &s.status {
            eprintln!("warning: demo stage {}: {m}", s.id);
        }
    }
}

fn summary_json(a: &Args, sections: &[Section], files: &[String], total: f64) -> Value {
    let mut stages = serde_json::Map::new();
    for s in sections {
        let mut v = match &s.summary {
            Value::Object(_) => s.summary.clone(),
            _ => json!({}),
        };
        v["status"] = json!(s.status.name());
        v["message"] = json!(s.status.message());
        v["seconds"] = json!(s.seconds);
        v["cpu_seconds"] = json!(s.cpu_seconds);
        v["files"] = json!(s.files.iter().map(|f| &f.0).collect::<Vec<_>>());
        stages.insert(s.id.to_string(), v);
    }
    json!({
        "out": a.out.display().to_string(),
        "resolution": a.resolution,
        "ok": sections.iter().all(|s| s.status.usable()),
        "stage_order": sections.iter().map(|s| s.id).collect::<Vec<_>>(),
        "stages": stages,
        "placeholders": PLACEHOLDERS.iter().map(|p| p.0).collect::<Vec<_>>(),
        "files": files,
        "seconds": total,
    })
}
