//! `solve` stopped before its stopping rule, keeping what it computed: after `--max-seconds` of
//! solving, or at a first SIGINT/SIGTERM/SIGHUP, the loop ends after the current shot and the
//! solution so far is written as a whole set, as any solve's (progressive refinement gives a
//! usable answer after every shot). A second signal ends the run at once, as any signal outside
//! the loop does (`output_set::exit_on_signals`).

use crate::display::output_set;
use crate::pipeline::{Solution, Stopped};
use crate::solver::ShotRecord;
use std::cell::Cell;

/// The loop's extra stopping rules, and which of them stopped it.
pub struct Limits {
    max_seconds: Option<f64>,
    /// Seconds of solving at the last shot.
    seconds: Cell<f64>,
    why: Cell<Option<Stopped>>,
}

impl Limits {
    /// Stop after `max_seconds` of solving, if given, or at a first signal; from now on a first
    /// signal no longer ends the process.
    pub fn begin(max_seconds: Option<f64>) -> Limits {
        output_set::defer_first_signal(true);
        eprintln!(
            "solving (Ctrl-C or SIGTERM: stop after the current shot and write the solution so \
             far; twice: stop at once)"
        );
        Limits {
            max_seconds,
            seconds: Cell::new(0.0),
            why: Cell::new(None),
        }
    }

    /// After each shot.
    pub fn see(&self, record: &ShotRecord) {
        self.seconds.set(record.seconds);
    }

    /// Between shots: whether to stop now.
    pub fn stop(&self) -> bool {
        if output_set::stop_requested().is_some() {
            self.why.set(Some(Stopped::Interrupted));
        } else if self.max_seconds.is_some_and(|s| self.seconds.get() >= s) {
            self.why.set(Some(Stopped::MaxSeconds));
        }
        self.why.get().is_some()
    }

    /// After the loop: signals end the process again; which of these rules stopped it, if one
    /// did.
    pub fn end(&self) -> Option<Stopped> {
        output_set::defer_first_signal(false);
        self.why.get()
    }
}

impl Drop for Limits {
    /// A loop that ended in an error must not leave the next signal deferred.
    fn drop(&mut self) {
        output_set::defer_first_signal(false);
    }
}

/// What the run says when one of these rules stopped it.
pub fn said(why: Stopped, solution: &Solution) -> String {
    let cause = match why {
        Stopped::Interrupted => format!(
            "interrupted by {}",
            output_set::stop_requested().unwrap_or("a signal")
        ),
        Stopped::MaxSeconds => "stopped by --max-seconds".to_string(),
        _ => "stopped".to_string(),
    };
    format!(
        "{cause} after {} shots: the outputs hold the solution so far, unshot fraction {:.5} \
         (stats.json: \"stopped\")",
        solution.shots, solution.unshot_fraction
    )
}
