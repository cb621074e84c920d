//! The triangle fan around each original vertex as the local error reads it: the fan's rim in
//! one fixed row of [`ROW`] slots, so a vertex's prism tests are one loop of fixed length over
//! consecutive slots, without a list of triangles to follow.
//!
//! Slot `t` and slot `t + 1` (the last slot wrapping to the first) are the other two corners of
//! a fan triangle in winding order, or a pair naming the vertex itself, whose edge of length 0
//! spans no prism. A closed fan of up to eight triangles fits (its first rim vertex repeated
//! after the last closes it), as does an open one of up to six. Other fans (larger, or not one
//! chain: a non-manifold vertex) have no row and are read from the fan's list of corners.

use rayon::prelude::*;

/// Slots per row.
pub(crate) const ROW: usize = 8;

/// The first slot of a vertex without a row.
const NO_ROW: u32 = u32::MAX;

/// Rows filled per parallel task.
const BLOCK: usize = 4096;

/// One row per vertex (see the module's notes).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct PrismRows(#[serde(with = "crate::mesh::flat_bytes")] Vec<[u32; ROW]>);

impl PrismRows {
    /// Rows for `n` vertices whose fans `fan(r)` lists as the other two corners of each triangle
    /// around `r`, in winding order.
    pub(crate) fn new<'a>(n: usize, fan: impl Fn(usize) -> &'a [[u32; 2]] + Sync) -> Self {
        let mut rows = vec![[NO_ROW; ROW]; n];
        rows.par_chunks_mut(BLOCK)
            .enumerate()
            .for_each(|(b, rows)| {
                for (k, row) in rows.iter_mut().enumerate() {
                    let r = b * BLOCK + k;
                    if let Some(found) = rim_row(r as u32, fan(r)) {
                        *row = found;
                    }
                }
            });
        Self(rows)
    }

    /// The row of vertex `r`, if its fan has one.
    #[inline(always)]
    pub(crate) fn row(&self, r: usize) -> Option<&[u32; ROW]> {
        self.0.get(r).filter(|row| row[0] != NO_ROW)
    }
}

/// The row of vertex `r` with fan `fan` (see the module's notes), if the fan is one chain that
/// fits. Checked at the end: the row's triangles must be the fan's, so the prism tests over
/// the row are those over the fan.
fn rim_row(r: u32, fan: &[[u32; 2]]) -> Option<[u32; ROW]> {
    let n = fan.len();
    if n == 0 || n > ROW {
        return None;
    }
    // An open fan starts where no triangle ends; a closed one anywhere.
    let start = fan
        .iter()
        .map(|p| p[0])
        .find(|&j| fan.iter().all(|p| p[1] != j))
        .unwrap_or(fan[0][0]);
    // Follow the chain; the last slot's pair wraps to the first (the check below sees to it).
    let mut row = [r; ROW];
    row[0] = start;
    let mut at = start;
    for slot in row.iter_mut().skip(1).take(n) {
        at = fan.iter().find(|p| p[0] == at)?[1];
        *slot = at;
    }
    let from_row = spanning_pairs(r, (0..ROW).map(|t| [row[t], row[(t + 1) % ROW]]));
    let from_fan = spanning_pairs(r, fan.iter().copied());
    (from_row == from_fan).then_some(row)
}

/// The pairs of `pairs` (at most [`ROW`]) that can span a prism around `r`: two corners other
/// than `r`, and not one corner twice; sorted, the unused places after them zeros.
fn spanning_pairs(r: u32, pairs: impl Iterator<Item = [u32; 2]>) -> [[u32; 2]; ROW] {
    let mut kept = [[0; 2]; ROW];
    let mut len = 0;
    for [j, k] in pairs.filter(|&[j, k]| j != k && j != r && k != r) {
        kept[len] = [j, k];
        len += 1;
    }
    kept[..len].sort_unstable();
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_fan_is_closed_by_its_first_rim_vertex() {
        let fan = [[3, 4], [5, 6], [4, 5], [6, 3]];
        assert_eq!(rim_row(0, &fan), Some([3, 4, 5, 6, 3, 0, 0, 0]));
        let eight: Vec<[u32; 2]> = (0..8).map(|t| [1 + t, 1 + (t + 1) % 8]).collect();
        assert_eq!(rim_row(0, &eight), Some([1, 2, 3, 4, 5, 6, 7, 8]));
    }

    #[test]
    fn an_open_fan_starts_where_no_triangle_ends() {
        let fan = [[2, 3], [1, 2]];
        assert_eq!(rim_row(9, &fan), Some([1, 2, 3, 9, 9, 9, 9, 9]));
        let six: Vec<[u32; 2]> = (0..6).map(|t| [1 + t, 2 + t]).collect();
        assert_eq!(rim_row(0, &six), Some([1, 2, 3, 4, 5, 6, 7, 0]));
    }

    #[test]
    fn fans_that_do_not_fit_or_are_not_one_chain_have_no_row() {
        let nine: Vec<[u32; 2]> = (0..9).map(|t| [1 + t, 1 + (t + 1) % 9]).collect();
        assert_eq!(rim_row(0, &nine), None);
        let seven_open: Vec<[u32; 2]> = (0..7).map(|t| [1 + t, 2 + t]).collect();
        assert_eq!(rim_row(0, &seven_open), None);
        // Two closed fans meeting at the vertex (a pinch).
        let pinch = [[1, 2], [2, 3], [3, 1], [4, 5], [5, 6], [6, 4]];
        assert_eq!(rim_row(0, &pinch), None);
        // Two open fans.
        assert_eq!(rim_row(0, &[[1, 2], [3, 4]]), None);
        assert_eq!(rim_row(0, &[]), None);
        // The same triangle twice is still one chain: the row walks it twice, as the list does.
        let twice = rim_row(0, &[[1, 2], [2, 3], [3, 1], [1, 2]]);
        assert_eq!(twice, Some([1, 2, 3, 1, 2, 0, 0, 0]));
    }

    #[test]
    fn rows_are_per_vertex() {
        let fans = [vec![[1, 2], [2, 3], [3, 1]], vec![]];
        let rows = PrismRows::new(2, |r| fans[r].as_slice());
        assert_eq!(rows.row(0), Some(&[1, 2, 3, 1, 0, 0, 0, 0]));
        assert_eq!(rows.row(1), None);
        assert_eq!(rows.row(2), None);
    }
}
