//! A progress bar for long work: shown on a terminal's stderr once the work has taken a
//! second, cleared when it ends.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Runs `work` on a scoped thread, showing (when `show`) `done` of `total` `unit` with
/// `label`; `total` may grow while the work runs. `None` if the work panicked.
pub fn with_progress<T: Send>(
    label: &str,
    unit: &str,
    show: bool,
    done: &AtomicU64,
    total: &AtomicU64,
    work: impl FnOnce() -> T + Send,
) -> Option<T> {
    std::thread::scope(|scope| {
        let (sender, receiver) = std::sync::mpsc::channel();
        scope.spawn(move || {
            // A panic here drops the sender, which the receiver reports as `None`.
            let _ = sender.send(work());
        });
        let started = Instant::now();
        let mut bar: Option<ProgressBar> = None;
        let outcome = loop {
            match receiver.recv_timeout(Duration::from_millis(50)) {
                Ok(result) => break Some(result),
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break None,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            }
            let known = total.load(Ordering::Relaxed) > 0;
            if show && known && bar.is_none() && started.elapsed() > Duration::from_secs(1) {
                let b = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
                b.set_style(
                    ProgressStyle::with_template(&format!(
                        "{{msg}} [{{bar:40}}] {{pos}}/{{len}} {unit}, {{eta}} left"
                    ))
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
                );
                b.set_message(label.to_string());
                bar = Some(b);
            }
            if let Some(b) = &bar {
                b.set_length(total.load(Ordering::Relaxed));
                b.set_position(done.load(Ordering::Relaxed));
            }
        };
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        outcome
    })
}
