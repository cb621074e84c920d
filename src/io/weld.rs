//! Welding triangle soup into an indexed mesh by exact position equality.
//!
//! STL stores every triangle's corners separately; an indexed mesh needs shared vertices. Only
//! bit-identical positions merge (with -0.0 == +0.0): no tolerance, so distinct vertices that a
//! segmentation put close together are never fused.
//!
//! The map is a small open-addressing table of `u32` vertex numbers keyed on the three
//! coordinate bit patterns: far cheaper per lookup than a general-purpose `HashMap`, which
//! matters because a 400k-triangle STL makes 1.2M lookups.
use crate::mesh::Mesh;

/// Welds a triangle soup (three positions per triangle) into an indexed mesh. Vertices are
/// numbered in order of first appearance; positions equal bit for bit (with +0 == -0) merge.
/// A trailing incomplete triangle (when `soup.len()` is not a multiple of 3) is ignored.
pub fn weld_exact(soup: &[[f32; 3]]) -> Mesh {
    let mut welder = Welder::with_expected_triangles(soup.len() / 3);
    let triangles = soup
        .chunks_exact(3)
        .map(|t| {
            [
                welder.insert(t[0]),
                welder.insert(t[1]),
                welder.insert(t[2]),
            ]
        })
        .collect();
    Mesh::new(welder.into_positions(), triangles)
}

const EMPTY: u32 = u32::MAX;

/// Incremental exact welder: feed positions, get vertex numbers.
pub(super) struct Welder {
    positions: Vec<[f32; 3]>,
    /// Normalised bit patterns of `positions`, compared on lookup.
    keys: Vec<[u32; 3]>,
    /// Vertex numbers or `EMPTY`; length is a power of two, at most half full.
    table: Vec<u32>,
}

impl Welder {
    /// A closed triangle mesh has about half as many vertices as triangles: size for that.
    pub(super) fn with_expected_triangles(triangles: usize) -> Self {
        let vertices = triangles / 2 + 8;
        Self {
            positions: Vec::with_capacity(vertices),
            keys: Vec::with_capacity(vertices),
            table: vec![EMPTY; (vertices * 2).next_power_of_two()],
        }
    }

    /// Number of distinct positions so far.
    pub(super) fn len(&self) -> usize {
        self.positions.len()
    }

    /// The vertex number of `p`, adding it if new. Callers keep the vertex count below
    /// `u32::MAX` (a triangle soup that large cannot be read on any supported target).
    #[inline]
    pub(super) fn insert(&mut self, p: [f32; 3]) -> u32 {
        let key = key_of(p);
        let mask = self.table.len() - 1;
        let mut slot = hash(key) as usize & mask;
        loop {
            let id = self.table[slot];
            if id == EMPTY {
                break;
            }
            if self.keys[id as usize] == key {
                return id;
            }
            slot = (slot + 1) & mask;
        }
        let id = self.positions.len() as u32;
        self.table[slot] = id;
        self.positions.push(p);
        self.keys.push(key);
        if self.keys.len() * 2 > self.table.len() {
            self.grow();
        }
        id
    }

    pub(super) fn into_positions(self) -> Vec<[f32; 3]> {
        self.positions
    }

    fn grow(&mut self) {
        let size = self.table.len() * 2;
        let mask = size - 1;
        let mut table = vec![EMPTY; size];
        for (id, &key) in self.keys.iter().enumerate() {
            let mut slot = hash(key) as usize & mask;
            while table[slot] != EMPTY {
                slot = (slot + 1) & mask;
            }
            table[slot] = id as u32;
        }
        self.table = table;
    }
}

/// Bit patterns with -0.0 mapped to +0.0 so the two zeros weld.
#[inline]
fn key_of(p: [f32; 3]) -> [u32; 3] {
    p.map(|c| {
        let bits = c.to_bits();
        if bits == 0x8000_0000 {
            0
        } else {
            bits
        }
    })
}

/// Two folded 64x64->128 multiplies: every input bit reaches the low bits used as the slot.
/// Voxel-grid coordinates share most of their bits, so a weaker mix clusters badly.
#[inline]
fn hash(k: [u32; 3]) -> u64 {
    #[inline]
    fn fold(a: u64, b: u64) -> u64 {
        let m = u128::from(a) * u128::from(b);
        (m as u64) ^ ((m >> 64) as u64)
    }
    let xy = u64::from(k[0]) | (u64::from(k[1]) << 32);
    let h = fold(xy ^ 0x243F_6A88_85A3_08D3, 0x9E37_79B9_7F4A_7C15);
    fold(h ^ u64::from(k[2]), 0xD6E8_FEB8_6659_FD93)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_corners_merge_in_first_appearance_order() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        let c = [0.0, 1.0, 0.0];
        let d = [1.0, 1.0, 0.0];
        let m = weld_exact(&[b, a, c, c, a, d]);
        assert_eq!(m.positions, vec![b, a, c, d]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [2, 1, 3]]);
    }

    #[test]
    fn zeros_of_both_signs_weld_but_near_values_do_not() {
        let p = [0.0, 1.0, 2.0];
        let q = [-0.0, 1.0, 2.0];
        let r = [0.0, 1.0, f32::from_bits(2.0f32.to_bits() + 1)];
        let m = weld_exact(&[p, q, r]);
        assert_eq!(m.positions.len(), 2);
        assert_eq!(m.triangles, vec![[0, 0, 1]]);
    }

    #[test]
    fn growth_keeps_every_vertex_findable() {
        let mut w = Welder::with_expected_triangles(0);
        let grid: Vec<[f32; 3]> = (0..5000)
            .map(|i| {
                [
                    (i % 17) as f32 * 0.5,
                    (i / 17 % 19) as f32,
                    (i / 323) as f32,
                ]
            })
            .collect();
        let ids: Vec<u32> = grid.iter().map(|&p| w.insert(p)).collect();
        assert_eq!(w.len(), 5000);
        assert!(grid.iter().zip(&ids).all(|(&p, &id)| w.insert(p) == id));
        assert_eq!(w.len(), 5000);
        assert_eq!(ids, (0..5000).collect::<Vec<u32>>());
    }

    #[test]
    fn trailing_partial_triangle_is_ignored() {
        let m = weld_exact(&[[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]]);
        assert_eq!(m.triangles.len(), 1);
        assert_eq!(m.positions.len(), 3);
    }
}
