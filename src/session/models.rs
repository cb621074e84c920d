//! The models of the case's structures, kept once built: selecting a structure again finds its
//! topology and the original's measures ready. Large cases would hold every structure's twice
//! over, so the least recently selected go once the kept ones pass a vertex budget.

use super::Model;

/// Vertices of the models kept beyond the current one's.
const VERTEX_BUDGET: usize = 4_000_000;

/// The models built, by structure index, the most recently selected last.
#[derive(Default)]
pub(super) struct Models {
    kept: Vec<(usize, Model)>,
}

impl Models {
    pub(super) fn get(&self, structure: usize) -> Option<&Model> {
        (self.kept.iter())
            .find(|(i, _)| *i == structure)
            .map(|(_, m)| m)
    }

    /// Keeps `model` as structure `structure`'s, the most recent; the oldest go past the
    /// budget.
    pub(super) fn keep(&mut self, structure: usize, model: Model) {
        self.kept.retain(|(i, _)| *i != structure);
        self.kept.push((structure, model));
        self.trim();
    }

    /// Makes structure `structure`'s model the most recent; false when none is kept.
    pub(super) fn touch(&mut self, structure: usize) -> bool {
        let Some(at) = self.kept.iter().position(|(i, _)| *i == structure) else {
            return false;
        };
        let entry = self.kept.remove(at);
        self.kept.push(entry);
        true
    }

    /// Forgets every model (another case opened).
    pub(super) fn clear(&mut self) {
        self.kept.clear();
    }

    fn trim(&mut self) {
        let vertices = |m: &Model| m.mesh().vertex_count();
        let mut total: usize = self.kept.iter().map(|(_, m)| vertices(m)).sum();
        let newest = self.kept.last().map_or(0, |(_, m)| vertices(m));
        while self.kept.len() > 1 && total - newest > VERTEX_BUDGET {
            total -= vertices(&self.kept.remove(0).1);
        }
    }
}
