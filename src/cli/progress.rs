//! A progress line on the terminal for the commands that take seconds on a large mesh (sweeps
//! and suggestions): rewritten in place at most every tenth of a second, cleared when the work
//! ends, and only when standard error is a terminal, so pipes, logs and `--json` consumers see
//! nothing of it.

use crate::suggest::Progress;
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// How often the line is rewritten.
const EVERY: Duration = Duration::from_millis(100);

/// The line for one piece of work.
pub(super) struct ProgressLine<W: Write> {
    out: Option<W>,
    what: String,
    /// Whether the work has a known total (a sweep, the grid) or only counts (the local
    /// search, which stops long before the grid's size).
    counts_only: bool,
    last: Option<Instant>,
    width: usize,
}

impl ProgressLine<std::io::Stderr> {
    /// A line on standard error when it is a terminal; otherwise one that writes nothing.
    pub(super) fn on_terminal(what: &str, counts_only: bool) -> Self {
        let err = std::io::stderr();
        let out = err.is_terminal().then_some(err);
        ProgressLine::new(out, what, counts_only)
    }
}

impl<W: Write> ProgressLine<W> {
    pub(super) fn new(out: Option<W>, what: &str, counts_only: bool) -> Self {
        Self {
            out,
            what: what.to_string(),
            counts_only,
            last: None,
            width: 0,
        }
    }

    /// Shows `p` if the line was last written long enough ago; always `true` (the commands are
    /// stopped with Ctrl-C, not through the progress callback).
    pub(super) fn update(&mut self, p: Progress) -> bool {
        let now = Instant::now();
        if self.last.is_some_and(|t| now - t < EVERY) {
            return true;
        }
        self.last = Some(now);
        let text = if self.counts_only {
            format!("{}: {} parameter sets measured", self.what, p.done)
        } else {
            format!("{}: {} of {}", self.what, p.done, p.total)
        };
        self.write(&text);
        true
    }

    /// Clears the line (the work is over, its result comes next).
    pub(super) fn finish(mut self) -> Option<W> {
        if self.width > 0 {
            self.write("");
        }
        self.out
    }

    /// Writes `text` over the line, padding out what a longer line left.
    fn write(&mut self, text: &str) {
        let Some(out) = self.out.as_mut() else {
            return;
        };
        let len = text.chars().count();
        let pad = self.width.saturating_sub(len);
        // A terminal that went away is no reason to stop the work.
        write!(out, "\r{text}{}\r", " ".repeat(pad)).ok();
        out.flush().ok();
        self.width = len;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(done: usize, total: usize) -> Progress {
        Progress { done, total }
    }

    #[test]
    fn rewrites_one_line_at_most_ten_times_a_second_and_clears_it() {
        let mut line = ProgressLine::new(Some(Vec::new()), "suggest hc (grid)", false);
        line.update(p(1, 1331));
        line.update(p(2, 1331)); // Within a tenth of a second: not shown.
        line.last = line.last.map(|t| t - EVERY);
        line.update(p(10, 1331));
        let out = String::from_utf8(line.finish().unwrap()).unwrap();
        let shown: Vec<&str> = out.split('\r').filter(|s| !s.trim().is_empty()).collect();
        assert_eq!(
            shown,
            [
                "suggest hc (grid): 1 of 1331",
                "suggest hc (grid): 10 of 1331"
            ]
        );
        assert!(!out.contains('\n'), "one line, rewritten: {out:?}");
        // The last write blanks the longest text shown.
        let cleared = out.rsplit('\r').nth(1).unwrap();
        assert!(cleared.trim().is_empty() && cleared.len() >= shown[1].len());
    }

    #[test]
    fn the_local_search_counts_without_a_total_and_no_terminal_gets_nothing() {
        let mut line = ProgressLine::new(Some(Vec::new()), "suggest", true);
        line.update(p(25, 1331));
        let out = String::from_utf8(line.finish().unwrap()).unwrap();
        assert!(
            out.contains("suggest: 25 parameter sets measured"),
            "{out:?}"
        );
        assert!(!out.contains("1331"));
        let mut silent = ProgressLine::<Vec<u8>>::new(None, "suggest", true);
        assert!(silent.update(p(1, 2)));
        assert!(silent.finish().is_none());
    }
}
