//! Progress reporting from long library computations, without printing.
//!
//! Long functions take `&mut dyn Progress`; the CLI implements it with a progress bar, tests
//! and library users pass [`NoProgress`].

/// Receives progress of a long computation.
pub trait Progress {
    /// `stage` names the step ("newton", "layout", …), `fraction` in [0, 1] when known, and
    /// `message` is a short status (e.g. "iteration 4: max |K − K̄| = 3.1e-7").
    fn report(&mut self, stage: &str, fraction: Option<f64>, message: &str);
}

/// Ignores all progress.
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&mut self, _: &str, _: Option<f64>, _: &str) {}
}

impl<F: FnMut(&str, Option<f64>, &str)> Progress for F {
    fn report(&mut self, stage: &str, fraction: Option<f64>, message: &str) {
        self(stage, fraction, message)
    }
}
