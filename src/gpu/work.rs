//! How much device work a submission holds, for callers that spread runs over several
//! submissions so a frame never queues behind a long one (the web app on a slow adapter): the
//! cost of a run's pieces in vertex-iterations, and a size that adapts to how long they take.

use crate::smooth::Filter;

/// A measure pass costs about this many smoothing steps with their drift (as timed on
/// SwiftShader and lavapipe on the 206k-vertex mesh).
const MEASURE_STEPS: u64 = 6;

/// Smoothing kernels in one iteration: Taubin's lambda and mu steps and HC's two passes, one
/// for the others.
pub(crate) fn steps_per_iteration(filter: Filter) -> u64 {
    match filter {
        Filter::Taubin | Filter::Hc => 2,
        Filter::Laplace | Filter::Sinc => 1,
    }
}

/// The cost of one iteration of `filter` on `vertices` vertices (vertex-steps).
pub(crate) fn iteration_cost(filter: Filter, vertices: u64) -> u64 {
    (vertices * steps_per_iteration(filter)).max(1)
}

/// The cost of one of `parts` parts of a measure pass on `vertices` vertices (vertex-steps).
pub(crate) fn measure_part_cost(vertices: u64, parts: usize) -> u64 {
    (vertices * MEASURE_STEPS / parts.max(1) as u64).max(1)
}

/// A submission size (vertex-steps) that adapts to how long submissions take: twice as large
/// while the work in one (its time beyond the shortest seen, which stands for what any
/// submission costs however small) stays well under the target, half as large when it is well
/// over, between a floor and a ceiling.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AdaptiveSize {
    pub size: u64,
    min: u64,
    max: u64,
    target_ms: f64,
    shortest_ms: Option<f64>,
}

impl AdaptiveSize {
    pub(crate) fn new(first: u64, min: u64, max: u64, target_ms: f64) -> Self {
        Self {
            size: first.clamp(min, max),
            min,
            max,
            target_ms,
            shortest_ms: None,
        }
    }

    /// Learns from a submission that took `ms` (from submission to its result, or a frame):
    /// `full` says whether the size limited it (a smaller one says nothing about a larger).
    pub(crate) fn adapt(&mut self, ms: f64, full: bool) {
        let shortest = self.shortest_ms.map_or(ms, |s| s.min(ms));
        self.shortest_ms = Some(shortest);
        self.adapt_work(ms - shortest, full);
    }

    /// Learns from a submission whose work took `work` ms; `full` as for [`Self::adapt`].
    pub(crate) fn adapt_work(&mut self, work: f64, full: bool) {
        if work > 2.0 * self.target_ms {
            self.size = (self.size / 2).max(self.min);
        } else if full && work < self.target_ms / 2.0 {
            self.size = self.size.saturating_mul(2).min(self.max);
        }
    }

    #[cfg(test)]
    fn shortest(&self) -> Option<f64> {
        self.shortest_ms
    }
}

/// The device work a frame should add to what drawing it costs (ms).
pub const FRAME_WORK_MS: f64 = 40.0;

/// How much work the web app sends to the device per frame (a run's pieces, then the
/// background's segments). The device runs its queue in order, so drawing waits for the work
/// sent before it; the browser runs a frame or two ahead, so the wait shows in the interval of
/// one of the next frames. What drawing alone takes is the lower quartile of the intervals of
/// the recent frames with no work sent in the `WINDOW` frames before them; a frame's work is
/// its interval beyond that, or beyond the lower quartile of the last `RECENT_FRAMES`
/// intervals of any frame where that is shorter (frames without work are rare while the
/// background works, and the last ones may date from a file opening, which takes long). The
/// size halves after a frame whose work is well over the
/// target, and doubles once a frame that the size limited is `WINDOW` frames old and the
/// last `CALM_FRAMES` frames all stayed well under it: quick to shrink, slow to grow. A
/// piece larger than the size waits, the frames until then saving up for it. The size starts
/// at about ten Laplace iterations of a 200k-vertex mesh (on a real GPU a whole run in a frame
/// or two) and adapts from there.
#[derive(Clone, Copy, Debug)]
pub struct FrameWork {
    size: AdaptiveSize,
    last_frame_ms: Option<f64>,
    /// Per frame of the window, newest first: whether work went out, whether the size
    /// limited it, and the work seen in its interval (ms).
    window: [(bool, bool, f64); WINDOW],
    /// Intervals of the latest frames without work.
    idle_ms: Intervals<IDLE_FRAMES>,
    /// Intervals of the latest frames, with or without work.
    recent_ms: Intervals<RECENT_FRAMES>,
    shortest_ms: f64,
    /// Frames since one whose work was over half the target.
    calm_frames: usize,
    /// Sent in the current frame: vertex-steps, and whether the size limited them.
    spent: u64,
    full: bool,
    /// Vertex-steps this frame may send: the size, plus what frames that held a larger piece
    /// back saved up for it (so a piece larger than the size goes out every few frames
    /// instead of every frame).
    credit: u64,
    /// The largest piece held back in this frame.
    held: u64,
}

/// Frames after a frame's work in which its wait may show.
const WINDOW: usize = 4;
/// The size never goes below this (vertex-steps): a Laplace iteration of a 250k-vertex mesh, a
/// whole run of a small one. Frames are long for other reasons too (a file opening, a page
/// busy elsewhere), and a smaller size would only stretch every run over more frames.
const SMALLEST_FRAME_WORK: u64 = 250_000;
/// The most frames a piece larger than the size waits: however small the size has become,
/// the frames save up at least this fraction of the piece each.
const MOST_FRAMES_SAVING: u64 = 4;
/// Frames without a wait over half the target before the size may grow.
const CALM_FRAMES: usize = 8;
/// Frames without work whose intervals estimate what drawing takes.
const IDLE_FRAMES: usize = 9;
/// Frames of any kind whose intervals bound what drawing takes from above.
const RECENT_FRAMES: usize = 16;

impl Default for FrameWork {
    fn default() -> Self {
        Self {
            size: AdaptiveSize::new(2_000_000, SMALLEST_FRAME_WORK, 1 << 40, FRAME_WORK_MS),
            last_frame_ms: None,
            window: [(false, false, 0.0); WINDOW],
            idle_ms: Intervals::default(),
            recent_ms: Intervals::default(),
            shortest_ms: f64::INFINITY,
            calm_frames: 0,
            spent: 0,
            full: false,
            credit: 0,
            held: 0,
        }
    }
}

impl FrameWork {
    /// A new frame begins at `now_ms`: learns from the one before.
    pub fn begin_frame(&mut self, now_ms: f64) {
        if let Some(last) = self.last_frame_ms {
            let interval = now_ms - last;
            self.shortest_ms = self.shortest_ms.min(interval);
            self.recent_ms.push(interval);
            let recent_work = self.spent > 0 || self.window.iter().any(|w| w.0);
            let work = if recent_work {
                (interval - self.drawing_ms()).max(0.0)
            } else {
                self.idle_ms.push(interval);
                0.0
            };
            self.window.rotate_right(1);
            self.window[0] = (self.spent > 0, self.full, work);
            self.calm_frames += 1;
            if work > 2.0 * FRAME_WORK_MS {
                self.size.adapt_work(work, true);
                self.calm_frames = 0;
            } else if work > FRAME_WORK_MS / 2.0 {
                self.calm_frames = 0;
            } else if self.window[WINDOW - 1].1 && self.calm_frames >= CALM_FRAMES {
                // The oldest frame of the window sent all it could, and no wait showed since.
                self.calm_frames = 0;
                self.size.adapt_work(0.0, true);
            }
        }
        let size = self.size.size;
        let rate = size.max(self.held.div_ceil(MOST_FRAMES_SAVING));
        self.credit = (self.credit + rate).min(size.max(self.held));
        self.spent = 0;
        self.full = false;
        self.held = 0;
        self.last_frame_ms = Some(now_ms);
    }

    /// What a frame without work takes: the lower quartile of the recent ones (frames that
    /// also open a file or lay out a new panel take longer; the quartile leaves them out), or
    /// the shortest interval seen before there are any; at most the lower quartile of the
    /// latest frames of any kind, once there are enough of them (no frame is shorter than its
    /// drawing).
    fn drawing_ms(&self) -> f64 {
        let idle = self.idle_ms.lower_quartile().unwrap_or(self.shortest_ms);
        match self.recent_ms.is_full() {
            true => self
                .recent_ms
                .lower_quartile()
                .map_or(idle, |any| idle.min(any)),
            false => idle,
        }
    }

    /// Vertex-steps this frame may still send.
    pub fn left(&self) -> u64 {
        self.credit
    }

    /// A piece of `steps` vertex-steps waits for a frame with room: the frames until then
    /// save up for it.
    pub fn hold(&mut self, steps: u64) {
        self.held = self.held.max(steps);
    }

    #[cfg(test)]
    fn size(&self) -> u64 {
        self.size.size
    }

    /// Whether something was held back in this frame.
    pub fn holding(&self) -> bool {
        self.held > 0
    }

    /// `steps` vertex-steps went out in this frame; `full`: the size limited them.
    pub fn sent(&mut self, steps: u64, full: bool) {
        self.spent += steps;
        self.full |= full;
        self.credit = self.credit.saturating_sub(steps);
    }
}

/// The latest `N` frame intervals (ms), the oldest overwritten first.
#[derive(Clone, Copy, Debug)]
struct Intervals<const N: usize> {
    ms: [f64; N],
    seen: usize,
}

impl<const N: usize> Default for Intervals<N> {
    fn default() -> Self {
        Self {
            ms: [0.0; N],
            seen: 0,
        }
    }
}

impl<const N: usize> Intervals<N> {
    fn push(&mut self, ms: f64) {
        self.ms[self.seen % N] = ms;
        self.seen += 1;
    }

    fn is_full(&self) -> bool {
        self.seen >= N
    }

    /// The lower quartile of the intervals kept; `None` before the first.
    fn lower_quartile(&self) -> Option<f64> {
        let mut sorted = self.ms;
        let sorted = &mut sorted[..self.seen.min(N)];
        sorted.sort_by(f64::total_cmp);
        sorted.get(sorted.len() / 4).copied()
    }
}

/// What a segment of a cumulative run does (see [`plan_segment`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct SegmentPlan {
    /// Iterations done once it has run.
    pub to: u32,
    /// How many of the counts asked for it measures (whole measures, in the segment).
    pub measured: usize,
    /// Whether the measure after `to` iterations follows in parts, in the next segments.
    pub then_measure: bool,
    /// Whether the budget limited it.
    pub full: bool,
}

/// Plans the segment of a run from `from` iterations that measures at the counts `remaining`
/// (ascending, none below `from`), within `budget` vertex-steps (`None`: the whole run at
/// once). An iteration costs `iteration`, a measure `measure`. It runs at least one iteration
/// unless it ends at a count whose measure did not fit: that measure then runs in parts.
pub(crate) fn plan_segment(
    from: u32,
    remaining: &[u32],
    iteration: u64,
    measure: u64,
    budget: Option<u64>,
) -> SegmentPlan {
    let last = remaining.last().copied().unwrap_or(from);
    let Some(budget) = budget else {
        return SegmentPlan {
            to: last,
            measured: remaining.len(),
            then_measure: false,
            full: false,
        };
    };
    let mut left = budget;
    let mut at = from;
    for (k, &count) in remaining.iter().enumerate() {
        let steps = u64::from(count.saturating_sub(at));
        let cost = steps * iteration;
        if cost > left {
            let fit = (left / iteration) as u32;
            // At least one iteration in a segment (none when one measure already fitted).
            let to = if k == 0 && fit == 0 { at + 1 } else { at + fit };
            return SegmentPlan {
                to: to.min(count),
                measured: k,
                then_measure: false,
                full: true,
            };
        }
        left -= cost;
        at = count;
        if measure > left {
            // The iterations up to the count fit, its measure does not: it runs in parts.
            return SegmentPlan {
                to: count,
                measured: k,
                then_measure: true,
                full: true,
            };
        }
        left -= measure;
    }
    SegmentPlan {
        to: last,
        measured: remaining.len(),
        then_measure: false,
        full: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn size_follows_the_work_beyond_the_shortest_time() {
        let mut s = AdaptiveSize::new(1000, 100, 10_000, 30.0);
        // No work beyond the latency: grows, up to the ceiling.
        s.adapt(50.0, true);
        assert_eq!(s.shortest(), Some(50.0));
        assert_eq!(s.size, 2000);
        s.adapt(55.0, true);
        assert_eq!(s.size, 4000);
        for _ in 0..10 {
            s.adapt(50.0, true);
        }
        assert_eq!(s.size, 10_000);
        // Far over the target: shrinks, down to the floor.
        for _ in 0..10 {
            s.adapt(200.0, true);
        }
        assert_eq!(s.size, 100);
        // Within the band: stays; a submission smaller than the size never grows it.
        s.adapt(80.0, true);
        assert_eq!(s.size, 100);
        s.adapt(50.0, false);
        assert_eq!(s.size, 100);
    }

    #[test]
    fn frame_work_learns_from_the_frames_with_work() {
        let mut f = FrameWork::default();
        let first = f.size();
        let mut t = 0.0;
        let mut frame = |f: &mut FrameWork, interval: f64| {
            t += interval;
            f.begin_frame(t);
        };
        // Frames without work: drawing takes 100 ms.
        for _ in 0..6 {
            frame(&mut f, 100.0);
        }
        assert_eq!(f.size(), first);
        // Work whose wait shows two frames later, 400 ms over drawing: half the size.
        f.sent(first, true);
        frame(&mut f, 20.0);
        frame(&mut f, 100.0);
        assert_eq!(f.size(), first);
        frame(&mut f, 500.0);
        assert_eq!(f.size(), first / 2);
        for _ in 0..CALM_FRAMES {
            frame(&mut f, 100.0);
        }
        // Work within the target does not grow it unless the size limited it.
        f.sent(1, false);
        for _ in 0..4 {
            frame(&mut f, 110.0);
        }
        assert_eq!(f.size(), first / 2);
        // Limited by the size and quick throughout: larger, once the window passed.
        f.sent(first / 2, true);
        for _ in 0..WINDOW - 1 {
            frame(&mut f, 110.0);
            assert_eq!(f.size(), first / 2);
        }
        frame(&mut f, 110.0);
        assert_eq!(f.size(), first);
        // Not again before enough calm frames.
        f.sent(first, true);
        for _ in 0..WINDOW {
            frame(&mut f, 110.0);
        }
        assert_eq!(f.size(), first);
    }

    #[test]
    fn long_frames_without_work_long_ago_do_not_hide_the_work() {
        let mut f = FrameWork::default();
        let first = f.size();
        let mut t = 0.0;
        // A file opening: long frames without work.
        for _ in 0..IDLE_FRAMES {
            t += 450.0;
            f.begin_frame(t);
        }
        // Then a little work in every frame, frames of 130 to 160 ms (drawing takes 130).
        for k in 0..RECENT_FRAMES {
            f.sent(1, false);
            t += if k % 2 == 0 { 130.0 } else { 160.0 };
            f.begin_frame(t);
        }
        assert_eq!(f.size(), first);
        assert_eq!(f.drawing_ms(), 130.0);
        // 270 ms beyond drawing: the size halves (judged against the idle frames alone, this
        // frame would have looked like drawing).
        f.sent(first, true);
        t += 400.0;
        f.begin_frame(t);
        assert_eq!(f.size(), first / 2);
    }

    #[test]
    fn frame_work_saves_up_for_a_piece_larger_than_the_size() {
        let mut f = FrameWork::default();
        f.begin_frame(0.0);
        let size = f.left();
        // Credit never piles up beyond one frame's size by itself.
        f.begin_frame(100.0);
        assert_eq!(f.left(), size);
        // A piece of 2.5 sizes waits two frames, then goes.
        let piece = size * 5 / 2;
        let mut t = 100.0;
        let mut frames = 0;
        while f.left() < piece {
            f.hold(piece);
            assert!(f.holding());
            t += 100.0;
            f.begin_frame(t);
            frames += 1;
        }
        assert_eq!(frames, 2);
        f.sent(piece, true);
        assert_eq!(f.left(), 0);
        // Long frames after work shrink the size to its floor; a piece still waits only a few
        // frames.
        for _ in 0..64 {
            f.sent(1, true);
            t += 5000.0;
            f.begin_frame(t);
        }
        assert_eq!(f.size(), SMALLEST_FRAME_WORK);
        let mut frames = 0;
        while f.left() < piece {
            f.hold(piece);
            t += 100.0;
            f.begin_frame(t);
            frames += 1;
        }
        assert_eq!(frames as u64, MOST_FRAMES_SAVING);
    }

    #[test]
    fn costs_count_kernels_and_measure_parts() {
        assert_eq!(iteration_cost(Filter::Laplace, 1000), 1000);
        assert_eq!(iteration_cost(Filter::Taubin, 1000), 2000);
        assert_eq!(iteration_cost(Filter::Hc, 0), 1);
        assert_eq!(measure_part_cost(1000, 6), 1000);
        assert_eq!(measure_part_cost(0, 16), 1);
    }

    /// `(to, measured, then_measure, full)` of the plan.
    fn plan(from: u32, remaining: &[u32], budget: Option<u64>) -> (u32, usize, bool, bool) {
        let p = plan_segment(from, remaining, 10, 60, budget);
        (p.to, p.measured, p.then_measure, p.full)
    }

    #[test]
    fn segments_fit_the_budget_with_measures_in_parts() {
        // Whole runs without a budget; everything fits.
        assert_eq!(plan(0, &[5, 10], None), (10, 2, false, false));
        assert_eq!(plan(0, &[5, 10], Some(1000)), (10, 2, false, false));
        // The iterations to 5 and the measure fit, then three more iterations.
        assert_eq!(plan(0, &[5, 10], Some(140)), (8, 1, false, true));
        // The iterations to 5 fit, not the measure: it follows in parts.
        assert_eq!(plan(0, &[5, 10], Some(70)), (5, 0, true, true));
        // Not even one iteration fits: one goes anyway.
        assert_eq!(plan(3, &[5], Some(4)), (4, 0, false, true));
        // A measure fitted and no further iteration does: the segment ends there.
        assert_eq!(plan(0, &[1, 10], Some(75)), (1, 1, false, true));
        // A count at the start is a measure only.
        assert_eq!(plan(0, &[0, 10], Some(30)), (0, 0, true, true));
    }
}
