//! The one look of every progress bar in `grit`.

use indicatif::{ProgressBar, ProgressStyle};

use super::output::say;

/// The style of every bar: what it counts, elapsed time, the bar, the count, a message.
pub fn style() -> ProgressStyle {
    ProgressStyle::with_template("{prefix:>18} [{elapsed_precise}] {wide_bar} {pos}/{len} {msg}")
        .expect("valid template")
}

/// A bar of `len` steps named `prefix`; hidden (drawing nothing) when `show` is false.
pub fn bar(len: u64, prefix: &str, show: bool) -> ProgressBar {
    let b = if show {
        ProgressBar::new(len)
    } else {
        ProgressBar::hidden()
    };
    b.set_style(style());
    b.set_prefix(prefix.to_string());
    b
}

/// Prints `line` above the bar, or on its own where the bar is hidden because standard error
/// is not a terminal (a log file): a hidden bar prints nothing.
pub fn line(bar: &ProgressBar, line: &str) {
    if bar.is_hidden() {
        say!("{line}");
    } else {
        bar.println(line);
    }
}

/// [`line`] for a message rather than an output row: above the bar, or on standard error where
/// the bar is hidden (no terminal, `--quiet`) and would swallow it.
pub fn note(bar: &ProgressBar, line: &str) {
    if bar.is_hidden() {
        eprintln!("{line}");
    } else {
        bar.println(line);
    }
}
