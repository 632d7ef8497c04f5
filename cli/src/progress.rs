//! Progress of fits and comparisons on stderr.
//!
//! On a terminal: a bar (indicatif) that stays hidden for the first second, so quick runs
//! print nothing, names the model and start being fitted and shows the elapsed time (no
//! estimate: the iterations a start needs are not known in advance). Without a terminal (a
//! log file, CI): one line per model and start as it begins. Nothing with `--quiet` or
//! `--json`.

use frictionid_engine::identify::Progress as FitProgress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeSet;
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How long an operation runs before its bar appears.
pub const SHOW_AFTER: Duration = Duration::from_secs(1);

/// Where progress goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Nothing (`--quiet`, `--json`).
    Silent,
    /// A bar on the terminal.
    Bar,
    /// One line per model and start on stderr.
    Lines,
}

impl Mode {
    /// The mode for a run: silent unless `enabled`, else a bar on a terminal and lines
    /// elsewhere.
    pub fn detect(enabled: bool) -> Self {
        match (enabled, std::io::stderr().is_terminal()) {
            (false, _) => Self::Silent,
            (true, true) => Self::Bar,
            (true, false) => Self::Lines,
        }
    }
}

/// Progress over `total` units of work, safe to advance from several threads.
#[derive(Debug)]
pub struct Progress {
    bar: ProgressBar,
    started: Instant,
    mode: Mode,
    shown: AtomicBool,
    /// (model, start) pairs already announced.
    seen: Mutex<BTreeSet<(String, usize)>>,
}

impl Progress {
    /// Progress over `total` units labelled `message`; `enabled = false` (quiet) never prints.
    pub fn new(total: u64, message: impl Into<String>, enabled: bool) -> Self {
        Self::with_mode(total, message, Mode::detect(enabled))
    }

    /// Progress in an explicit `mode`.
    pub fn with_mode(total: u64, message: impl Into<String>, mode: Mode) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        let style = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        bar.set_style(style);
        bar.set_message(message.into());
        Self {
            bar,
            started: Instant::now(),
            mode,
            shown: AtomicBool::new(false),
            seen: Mutex::new(BTreeSet::new()),
        }
    }

    /// Progress over `total` items of work of comparable size (the groups of a campaign):
    /// the bar estimates the time left; without a terminal, [`Progress::item_done`] prints a
    /// line per item.
    pub fn items(total: u64, message: impl Into<String>, enabled: bool) -> Self {
        let progress = Self::new(total, message, enabled);
        let style =
            ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed}, ~{eta} left)")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> ");
        progress.bar.set_style(style);
        progress
    }

    /// One item done: the bar advances; without a terminal, a line names the item.
    pub fn item_done(&self, label: &str) {
        self.inc(1);
        if self.mode == Mode::Lines {
            let elapsed = self.started.elapsed().as_secs_f64();
            let (done, total) = (self.bar.position(), self.bar.length().unwrap_or(0));
            let _ = writeln!(
                std::io::stderr(),
                "[{elapsed:6.1} s] {label} ({done}/{total})"
            );
        }
    }

    /// Records `n` more units done; shows the bar once the work has run for [`SHOW_AFTER`].
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
        if self.mode == Mode::Bar
            && !self.shown.load(Ordering::Relaxed)
            && self.started.elapsed() >= SHOW_AFTER
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.bar.enable_steady_tick(Duration::from_millis(200));
        }
    }

    /// Takes one report of the identifier: names the model and start on the bar, and
    /// announces a new (model, start) pair (a line without a terminal). Returns whether the
    /// pair is new.
    pub fn observe(&self, p: &FitProgress) -> bool {
        let label = start_label(p);
        self.bar
            .set_message(format!("{label}, iteration {}", p.iteration));
        let new = self
            .seen
            .lock()
            .map(|mut s| s.insert((p.model.clone(), p.start)))
            .unwrap_or(false);
        if new && self.mode == Mode::Lines {
            let elapsed = self.started.elapsed().as_secs_f64();
            let _ = writeln!(std::io::stderr(), "[{elapsed:6.1} s] {label}");
        }
        new
    }

    /// Changes the label.
    pub fn set_message(&self, message: impl Into<String>) {
        self.bar.set_message(message.into());
    }

    /// Units done so far.
    pub fn position(&self) -> u64 {
        self.bar.position()
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// "fitting stribeck, start 2/4" (no start count for a single start).
pub fn start_label(p: &FitProgress) -> String {
    if p.starts > 1 {
        format!("fitting {}, start {}/{}", p.model, p.start + 1, p.starts)
    } else {
        format!("fitting {}", p.model)
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(model: &str, start: usize, iteration: u64) -> FitProgress {
        FitProgress {
            model: model.into(),
            start,
            starts: 4,
            iteration,
            max_iterations: 200,
            cost: 1.0,
        }
    }

    #[test]
    fn counts_work_and_stays_hidden_when_silent() {
        let p = Progress::with_mode(10, "fitting", Mode::Silent);
        std::thread::scope(|s| {
            for _ in 0..5 {
                s.spawn(|| p.inc(2));
            }
        });
        assert_eq!(p.position(), 10);
        assert!(!p.shown.load(Ordering::Relaxed));
        p.finish();
    }

    #[test]
    fn each_model_and_start_is_announced_once() {
        let p = Progress::with_mode(2, "comparing", Mode::Silent);
        assert!(p.observe(&report("coulomb", 0, 1)));
        assert!(!p.observe(&report("coulomb", 0, 2)));
        assert!(p.observe(&report("coulomb", 1, 1)));
        assert!(p.observe(&report("stribeck", 0, 1)));
        assert_eq!(
            start_label(&report("stribeck", 1, 3)),
            "fitting stribeck, start 2/4"
        );
    }
}
