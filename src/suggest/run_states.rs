//! States of earlier smoothing runs, kept so that a later run of the same weights can start
//! where one of them was instead of from the original.
//!
//! The local search asks for the same weights again and again at other iteration counts: a
//! search that starts at the most iterations walks down the iteration axis, and each step asks
//! for the neighbours' counts below those already run. A run keeps its state (positions and
//! the local error's drifting references) at the multiples of `every` iterations it passes
//! from two intervals below its first count on; a run that needs `k` iterations then resumes from the kept state of the most iterations up
//! to `k`. The states take `16` bytes per vertex each, within a byte budget; past it the state
//! used least recently goes.

use super::memo::RunKey;
use crate::smooth::Params;

/// One kept state: the positions and drifting references after `count` iterations.
pub(crate) struct State {
    key: RunKey,
    pub count: u32,
    pub positions: Vec<[f32; 3]>,
    pub reference: Vec<u32>,
    /// When it was kept or last used (larger is later).
    used: u64,
}

/// The kept states of one model's runs (with its vertex weights).
pub(crate) struct RunStates {
    budget_bytes: usize,
    every: u32,
    states: Vec<State>,
    clock: u64,
}

impl RunStates {
    /// Keeps states every `every` iterations (at least 1), within `budget_bytes`.
    pub fn new(budget_bytes: usize, every: u32) -> Self {
        Self {
            budget_bytes,
            every: every.max(1),
            states: Vec::new(),
            clock: 0,
        }
    }

    /// Whether a run whose first measured count is `first` keeps its state after `iteration`
    /// iterations: at the multiples of the interval from two intervals below `first` on. The
    /// search asks for the same weights again a step or two further down the iteration axis;
    /// states further down went unused and their copies cost more than they saved.
    pub fn keeps(&self, iteration: u32, first: u32) -> bool {
        iteration > 0 && iteration.is_multiple_of(self.every) && iteration + 2 * self.every >= first
    }

    /// The kept state of `params`'s weights with the most iterations up to `count`.
    pub fn latest(&mut self, params: &Params, count: u32) -> Option<&State> {
        let key = RunKey::of(params);
        self.clock += 1;
        let clock = self.clock;
        let state = self
            .states
            .iter_mut()
            .filter(|s| s.key == key && s.count <= count)
            .max_by_key(|s| s.count)?;
        state.used = clock;
        Some(state)
    }

    /// Keeps the state of `params`'s weights after `count` iterations (replacing one kept for
    /// the same count), dropping the least recently used states to stay within the budget
    /// (their buffers take the new state: no fresh pages to fault in); nothing when one state
    /// alone is over the budget.
    pub fn keep(&mut self, params: &Params, count: u32, positions: &[[f32; 3]], reference: &[u32]) {
        let bytes = Self::bytes(positions.len());
        if bytes > self.budget_bytes {
            return;
        }
        let key = RunKey::of(params);
        let mut spare = None;
        let same = self
            .states
            .iter()
            .position(|s| s.key == key && s.count == count);
        if let Some(k) = same {
            spare = Some(self.states.swap_remove(k));
        }
        while (self.states.len() + 1) * bytes > self.budget_bytes {
            let Some(oldest) = (0..self.states.len()).min_by_key(|&k| self.states[k].used) else {
                break;
            };
            spare = Some(self.states.swap_remove(oldest));
        }
        let (mut kept_positions, mut kept_reference) = spare
            .map(|s| (s.positions, s.reference))
            .unwrap_or_default();
        kept_positions.clear();
        kept_positions.extend_from_slice(positions);
        kept_reference.clear();
        kept_reference.extend_from_slice(reference);
        self.clock += 1;
        self.states.push(State {
            key,
            count,
            positions: kept_positions,
            reference: kept_reference,
            used: self.clock,
        });
    }

    /// How many states are kept.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.states.len()
    }

    /// The bytes of one state of `vertices` vertices.
    fn bytes(vertices: usize) -> usize {
        vertices * (std::mem::size_of::<[f32; 3]>() + std::mem::size_of::<u32>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::smooth::Filter;

    fn hc(alpha: f32) -> Params {
        let mut p = Params::defaults(Filter::Hc);
        p.alpha = alpha;
        p
    }

    #[test]
    fn the_latest_state_up_to_a_count_of_the_same_weights() {
        let mut states = RunStates::new(1 << 20, 5);
        assert!(states.keeps(5, 5) && states.keeps(50, 50) && states.keeps(50, 20));
        assert!(!states.keeps(0, 0) && !states.keeps(7, 5));
        assert!(
            states.keeps(10, 20) && !states.keeps(5, 20),
            "two intervals below the first"
        );
        let positions = vec![[1.0, 2.0, 3.0]; 4];
        for count in [5, 10, 15] {
            states.keep(&hc(0.1), count, &positions, &[count; 4]);
        }
        states.keep(&hc(0.2), 20, &positions, &[20; 4]);
        let count =
            |s: &mut RunStates, p: &Params, k| s.latest(p, k).map(|s| (s.count, s.reference[0]));
        assert_eq!(count(&mut states, &hc(0.1), 12), Some((10, 10)));
        assert_eq!(count(&mut states, &hc(0.1), 40), Some((15, 15)));
        assert_eq!(count(&mut states, &hc(0.1), 4), None);
        assert_eq!(count(&mut states, &hc(0.2), 20), Some((20, 20)));
        assert_eq!(count(&mut states, &hc(0.3), 20), None);
        // The bound is part of the weights.
        let mut bounded = hc(0.1);
        bounded.max_displacement = Some(1.0);
        assert_eq!(count(&mut states, &bounded, 20), None);
        // The same count again replaces the state.
        states.keep(&hc(0.1), 10, &positions, &[99; 4]);
        assert_eq!(states.len(), 4);
        assert_eq!(count(&mut states, &hc(0.1), 12), Some((10, 99)));
    }

    #[test]
    fn the_least_recently_used_go_past_the_budget() {
        // Room for three states of four vertices (64 bytes each).
        let mut states = RunStates::new(3 * 64 + 10, 1);
        let positions = vec![[0.0; 3]; 4];
        for count in 1..=3 {
            states.keep(&hc(0.1), count, &positions, &[count; 4]);
        }
        // Used: the state at 1 is now more recent than the one at 2.
        assert!(states.latest(&hc(0.1), 1).is_some());
        states.keep(&hc(0.1), 4, &positions, &[4; 4]);
        assert_eq!(states.len(), 3);
        let at = |s: &mut RunStates, k| s.latest(&hc(0.1), k).map(|s| s.count);
        assert_eq!(at(&mut states, 2), Some(1), "2 went, 1 stayed");
        assert_eq!(at(&mut states, 3), Some(3));
        assert_eq!(at(&mut states, 9), Some(4));
        // A state larger than the whole budget is not kept.
        let mut tiny = RunStates::new(10, 1);
        tiny.keep(&hc(0.1), 1, &positions, &[1; 4]);
        assert_eq!(tiny.len(), 0);
    }
}
