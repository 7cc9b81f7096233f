//! Progress a user sees everywhere: on a terminal, indicatif's bar; without one (a CI log,
//! `nohup`, a notebook), where indicatif draws nothing, one line per finished stage (each
//! message the bar showed) with its time on stderr, written by a thread that watches the bar.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// How often the watcher looks at the bar: a stage shorter than this may go unreported.
const POLL: Duration = Duration::from_millis(50);

/// A bar drawn with `template` (indicatif's syntax) over `len` steps, reported in lines
/// beginning `what:` where stderr is not a terminal.
pub fn bar(what: &'static str, len: u64, template: &str) -> Progress {
    let bar = ProgressBar::new(len).with_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let dropped = Arc::new(AtomicBool::new(false));
    let watcher =
        (!std::io::stderr().is_terminal()).then(|| watch(what, &bar, Arc::clone(&dropped)));
    Progress {
        bar,
        watcher,
        dropped,
    }
}

/// A progress bar and, without a terminal, the thread writing its lines. The last stage's
/// line and the total are written when the command finishes the bar (`finish_and_clear`
/// and the like); a bar dropped unfinished (the command failed) writes no more, so that a
/// refusal stays one line.
pub struct Progress {
    bar: ProgressBar,
    watcher: Option<std::thread::JoinHandle<()>>,
    dropped: Arc<AtomicBool>,
}

impl std::ops::Deref for Progress {
    type Target = ProgressBar;

    fn deref(&self) -> &ProgressBar {
        &self.bar
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.dropped.store(true, Ordering::Release);
        if let Some(watcher) = self.watcher.take() {
            // A watcher that panicked has nothing more to write.
            let _ = watcher.join();
        }
    }
}

/// Prints a line for each stage of `bar` (a message it showed) when the next begins or the
/// bar finishes, with the stage's time, then the whole time; stops without a word once
/// `dropped` is set while the bar is unfinished.
fn watch(
    what: &'static str,
    bar: &ProgressBar,
    dropped: Arc<AtomicBool>,
) -> std::thread::JoinHandle<()> {
    let weak = bar.downgrade();
    std::thread::spawn(move || {
        let started = Instant::now();
        let mut stage_began = started;
        let mut stage = String::new();
        let finished_stage = |stage: &str, began: Instant| {
            if !stage.is_empty() {
                eprintln!("{what}: {stage} ({:.1} s)", began.elapsed().as_secs_f64());
            }
        };
        loop {
            std::thread::sleep(POLL);
            let Some(bar) = weak.upgrade() else { return };
            let message = bar.message();
            if message != stage {
                finished_stage(&stage, stage_began);
                (stage, stage_began) = (message, Instant::now());
            }
            if bar.is_finished() {
                break;
            }
            if dropped.load(Ordering::Acquire) {
                return;
            }
        }
        finished_stage(&stage, stage_began);
        eprintln!(
            "{what}: finished in {:.1} s",
            started.elapsed().as_secs_f64()
        );
    })
}
