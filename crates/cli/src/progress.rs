//! A progress bar on standard error for the stages of long model work.

use cadmorph::model::Progress;

/// indicatif draws nothing when standard error is not a terminal, so pipes, logs and
/// `--json` output stay clean.
pub struct Bar(indicatif::ProgressBar);

impl Bar {
    /// A spinner with the stage name, a bar and a step count.
    pub fn new() -> Self {
        let bar = indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::stderr());
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{spinner} {msg:<22} {wide_bar} {pos}/{len} {elapsed}")
        {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        Self(bar)
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

impl Progress for Bar {
    fn start(&self, stage: &str, total: u64) {
        self.0.set_message(stage.to_owned());
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn step(&self, n: u64) {
        self.0.inc(n);
    }
}
