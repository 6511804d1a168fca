//! A progress bar on stderr for long commands (indicatif).
//!
//! The bar is created lazily: only once more than [`DELAY`] of wall time has passed
//! since the [`Progress`] was made, and only when stderr is a terminal. Short
//! commands, and every command whose stderr is captured (scripts, tests, CI), never
//! draw anything. [`Progress::finish`] (or dropping it) clears the bar, so nothing
//! of it stays on the screen.
//!
//! `Progress` is `Sync`: threads may share one (`&Progress`) and call
//! [`Progress::inc`] as they complete work; the count is an atomic and the bar
//! draws at most 20 times a second.
//!
//! ```ignore
//! let progress = Progress::new(runs.len() as u64, "runs");
//! for scene in &runs {
//!     simulation::run(scene, &mut |_| {})?;
//!     progress.inc(1);
//! }
//! progress.finish();
//! ```

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Wall time after which the bar appears.
pub const DELAY: Duration = Duration::from_secs(1);

/// Counts work done out of a total and shows it on stderr after [`DELAY`].
#[derive(Debug)]
pub struct Progress {
    start: Instant,
    unit: &'static str,
    /// Whether a bar may be drawn at all (stderr is a terminal).
    enabled: bool,
    total: AtomicU64,
    done: AtomicU64,
    bar: OnceLock<ProgressBar>,
}

impl Progress {
    /// A counter of `total` items named `unit` (e.g. `"steps"`, `"runs"`), starting
    /// the clock now.
    pub fn new(total: u64, unit: &'static str) -> Self {
        Progress {
            start: Instant::now(),
            unit,
            enabled: std::io::stderr().is_terminal(),
            total: AtomicU64::new(total),
            done: AtomicU64::new(0),
            bar: OnceLock::new(),
        }
    }

    /// Changes the total (e.g. once the number of steps is known).
    pub fn set_total(&self, total: u64) {
        self.total.store(total, Ordering::Relaxed);
        if let Some(bar) = self.bar.get() {
            bar.set_length(total);
        }
    }

    /// Counts `n` more items done; shows the bar if it is time to.
    pub fn inc(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        if !self.enabled {
            return;
        }
        match self.bar.get() {
            Some(bar) => bar.set_position(done),
            None => {
                if self.start.elapsed() >= DELAY {
                    self.bar.get_or_init(|| self.make_bar(done));
                }
            }
        }
    }

    /// Items counted so far.
    #[allow(dead_code)] // for callers that report counts (compare, converge)
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }

    /// Whether a bar has been drawn (never when stderr is not a terminal).
    #[cfg(test)]
    pub fn is_shown(&self) -> bool {
        self.bar.get().is_some()
    }

    /// Clears the bar from the screen (if it was shown). Idempotent.
    pub fn finish(&self) {
        if let Some(bar) = self.bar.get() {
            bar.finish_and_clear();
        }
    }

    fn make_bar(&self, done: u64) -> ProgressBar {
        let template = format!(
            "{{spinner}} [{{bar:32}}] {{pos}}/{{len}} {} · {{elapsed}} elapsed · ETA {{eta}}",
            self.unit
        );
        let style = ProgressStyle::with_template(&template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let bar = ProgressBar::with_draw_target(
            Some(self.total.load(Ordering::Relaxed)),
            ProgressDrawTarget::stderr(),
        )
        .with_style(style)
        .with_position(done)
        .with_elapsed(self.start.elapsed());
        bar.enable_steady_tick(Duration::from_millis(200));
        bar
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_from_threads_and_never_draws_without_a_terminal() {
        let progress = Progress::new(8, "runs");
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    progress.inc(1);
                    progress.inc(1);
                });
            }
        });
        assert_eq!(progress.done(), 8);
        progress.set_total(10);
        progress.finish();
        if !std::io::stderr().is_terminal() {
            assert!(!progress.is_shown());
        }
    }
}
