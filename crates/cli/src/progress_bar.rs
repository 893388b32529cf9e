//! Progress bars on the terminal (indicatif), behind the core's `Progress`.

use hikari_core::progress::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::Mutex;
use std::time::{Duration, Instant};

pub struct TerminalProgress {
    bar: Mutex<Option<ProgressBar>>,
    quiet: bool,
    /// Bars appear only once this much time has passed since `new` (work
    /// that is usually quick, such as loading a scene, shows no bar).
    delay: Duration,
    started: Instant,
}

impl TerminalProgress {
    pub fn new(quiet: bool) -> Self {
        Self::after(quiet, Duration::ZERO)
    }

    /// Bars that stay hidden until `delay` has passed.
    pub fn after(quiet: bool, delay: Duration) -> Self {
        TerminalProgress { bar: Mutex::new(None), quiet, delay, started: Instant::now() }
    }

    fn visible(&self) -> bool {
        !self.quiet && self.started.elapsed() >= self.delay
    }
}

impl Progress for TerminalProgress {
    fn begin(&self, stage: &str, total: u64) {
        let bar = if self.visible() {
            ProgressBar::new(total)
        } else {
            ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden())
        };
        bar.set_style(
            ProgressStyle::with_template("{msg:>16} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(stage.to_string());
        *self.bar.lock().unwrap() = Some(bar);
    }

    fn advance(&self, amount: u64) {
        if let Some(bar) = self.bar.lock().unwrap().as_ref() {
            if bar.is_hidden() && self.visible() {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.inc(amount);
        }
    }

    fn end(&self) {
        if let Some(bar) = self.bar.lock().unwrap().take() {
            bar.finish_and_clear();
        }
    }
}
