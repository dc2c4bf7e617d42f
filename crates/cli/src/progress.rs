//! A progress bar on standard error for the stages of long model work.

use cadmorph::model::Progress;

/// indicatif draws nothing when standard error is not a terminal, so pipes, logs and
/// `--json` output stay clean.
pub struct Bar(indicatif::ProgressBar);

impl Bar {
    /// A bar that shows nothing until the first stage starts; hidden, without its ticker
    /// thread, when standard error is not a terminal (starting and joining that thread
    /// was a fifth of a small morph's time).
    pub fn new() -> Self {
        use std::io::IsTerminal;
        if !std::io::stderr().is_terminal() {
            return Self(indicatif::ProgressBar::hidden());
        }
        let bar = indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::stderr());
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        Self(bar)
    }

    /// The style of a stage of `total` steps (0: unknown).
    fn style(total: u64) -> Option<indicatif::ProgressStyle> {
        let template = if total == 0 {
            "{spinner} {msg:<24} {elapsed}"
        } else {
            "{spinner} {msg:<24} {wide_bar} {pos}/{len} {elapsed}"
        };
        indicatif::ProgressStyle::with_template(template).ok()
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

impl Progress for Bar {
    fn start(&self, stage: &str, total: u64) {
        if let Some(style) = Self::style(total) {
            self.0.set_style(style);
        }
        self.0.set_message(stage.to_owned());
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn step(&self, n: u64) {
        // A stage of unknown size counts nothing past its (zero) length.
        if self.0.length().unwrap_or(0) > 0 {
            self.0.inc(n);
        }
    }
}
