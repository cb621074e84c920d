//! What the session tests share.
#![allow(dead_code)]

use meshsmooth::session::{Session, Timings};

/// Smooths and measures the current revision on the CPU engine until its result is there
/// (at once with workers on this thread); the time each half took comes back. What a frame
/// loop does, for tests with no frames.
pub fn smooth_cpu(session: &mut Session) -> Option<Timings> {
    loop {
        if let Some(timings) = session.compute_cpu() {
            return Some(timings);
        }
        if !session.smoothing_on_cpu() {
            return None;
        }
    }
}
