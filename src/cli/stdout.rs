//! Standard output for the tool's reports. `println!` panics when the reader has gone
//! (`meshsmooth info brain.ply | head -1`); here a closed pipe ends the program quietly, as
//! Unix tools end, and any other write error is reported like every other error.

use std::fmt;
use std::io::{self, Write};

/// `print!` for the tool's reports.
macro_rules! out {
    ($($arg:tt)*) => { $crate::cli::stdout::write(format_args!($($arg)*)) };
}

/// `println!` for the tool's reports.
macro_rules! outln {
    ($($arg:tt)*) => { $crate::cli::stdout::write(format_args!("{}\n", format_args!($($arg)*))) };
}

pub(crate) fn write(text: fmt::Arguments) {
    let mut stdout = io::stdout().lock();
    if let Err(e) = stdout.write_fmt(text).and_then(|()| stdout.flush()) {
        std::process::exit(closed_or_failed(&e));
    }
}

/// The exit status for a failed write to standard output: 0 when the reader closed the pipe
/// (it took what it wanted), 1 otherwise, with the reason on standard error.
fn closed_or_failed(e: &io::Error) -> i32 {
    if e.kind() == io::ErrorKind::BrokenPipe {
        0
    } else {
        eprintln!("meshsmooth: cannot write to standard output: {e}");
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_pipe_ends_quietly_and_other_errors_fail() {
        assert_eq!(
            closed_or_failed(&io::Error::from(io::ErrorKind::BrokenPipe)),
            0
        );
        assert_eq!(closed_or_failed(&io::Error::other("disk full")), 1);
    }
}
