//! Stages that run beside the others ([`super::BESIDE`]): each on a thread of its own with a
//! rayon pool of its own, started as soon as the stages it needs have succeeded, joined when a
//! stage needs it or at the end. On two cores the manifold spline (more than half of the
//! demo's CPU time, needing only the surface) then shares the machine with the ten stages after
//! the surface instead of waiting for them.
//!
//! CPU seconds stay per stage: the ids of a beside stage's threads (its own and its pool's) are
//! recorded, its CPU time is their sum, and a stage of the main thread is charged the process's
//! CPU time during it minus what the beside stages used meanwhile.

use super::report::{Section, Status};
use super::{run_stage, Ctx, Out, Stage, StageBar};
use crate::util::{current_thread_id, thread_cpu_seconds};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// The CPU time of a set of threads: their kernel ids while they run, the total once the
/// stage is over (its pool's threads end with the pool).
#[derive(Default)]
pub struct ThreadsCpu {
    tids: Mutex<Vec<u32>>,
    total: Mutex<Option<f64>>,
}

impl ThreadsCpu {
    /// Record the calling thread.
    fn add_current(&self) {
        if let (Some(t), Ok(mut tids)) = (current_thread_id(), self.tids.lock()) {
            tids.push(t);
        }
    }
    /// CPU seconds of the threads so far (0 before the first has recorded itself).
    pub fn seconds(&self) -> Option<f64> {
        if let Some(t) = self.total.lock().ok().and_then(|t| *t) {
            return Some(t);
        }
        let tids = self.tids.lock().ok()?;
        Some(tids.iter().filter_map(|&t| thread_cpu_seconds(t)).sum())
    }
    /// Freeze the total (before the pool's threads end).
    fn finish(&self) -> Option<f64> {
        let s = self.seconds();
        if let Ok(mut t) = self.total.lock() {
            *t = s;
        }
        s
    }
}

/// A stage running beside the main thread.
pub struct Beside {
    /// Index of the stage in [`super::STAGES`].
    pub k: usize,
    pub cpu: Arc<ThreadsCpu>,
    handle: JoinHandle<(Section, Vec<String>)>,
}

impl Beside {
    /// Start stage `st` (index `k`) on a thread of its own with `ctx` (a copy of what it reads)
    /// and a file list of its own in `out`'s staging folder; `None` when no thread can be
    /// started (the caller then runs it in line). The stages it needs have succeeded.
    pub fn start(k: usize, st: &'static Stage, ctx: Ctx, out: &Out) -> Option<Beside> {
        let cpu = Arc::new(ThreadsCpu::default());
        let cpu_thread = cpu.clone();
        let mut out = out.sibling();
        let handle = std::thread::Builder::new()
            .name(format!("demo-{}", st.id))
            .spawn(move || {
                cpu_thread.add_current();
                let cpu_pool = cpu_thread.clone();
                let pool = rayon::ThreadPoolBuilder::new()
                    .thread_name(|i| format!("demo-beside-{i}"))
                    .start_handler(move |_| cpu_pool.add_current())
                    .build();
                let mut ctx = ctx;
                let mut bar = StageBar::new(true);
                let cpu_now = || cpu_thread.seconds();
                let mut section = match &pool {
                    Ok(pool) => {
                        pool.install(|| run_stage(st, &[], &mut ctx, &mut out, &mut bar, &cpu_now))
                    }
                    // No pool of its own: the global one (its CPU time is then not separated).
                    Err(_) => run_stage(st, &[], &mut ctx, &mut out, &mut bar, &cpu_now),
                };
                section.cpu_seconds = cpu_thread.finish();
                drop(pool);
                (section, std::mem::take(&mut out.files))
            })
            .ok()?;
        Some(Beside { k, cpu, handle })
    }

    pub fn is_finished(&self) -> bool {
        self.handle.is_finished()
    }

    /// Wait for the stage: its section and the files it wrote (a panic of the stage becomes a
    /// failed section).
    pub fn join(self, st: &Stage) -> (Section, Vec<String>) {
        self.handle.join().unwrap_or_else(|_| {
            let mut s = Section::new(st.id, st.title, st.reference);
            s.status =
                Status::Failed("this stage failed: it stopped with an internal error".into());
            (s, Vec::new())
        })
    }
}
