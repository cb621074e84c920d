//! Dropping specks: voxel components smaller than a given size become background before the
//! surfaces are made. Components are 18-connected, as the surfaces join them (voxels that share
//! a face or an edge are one piece; voxels that touch only at a corner get surfaces of their own).

use crate::io::LabelLayer;

/// The 18 neighbour offsets: the 6 face neighbours and the 12 edge neighbours.
fn neighbour_offsets() -> Vec<[i64; 3]> {
    let mut out = Vec::with_capacity(18);
    for dz in -1..=1i64 {
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                let nonzero = [dx, dy, dz].iter().filter(|&&d| d != 0).count();
                if (1..=2).contains(&nonzero) {
                    out.push([dx, dy, dz]);
                }
            }
        }
    }
    out
}

/// Sets every 18-connected component of equal codes with fewer than `min_voxels` voxels to
/// background.
pub(crate) fn drop_small_components(layer: &mut LabelLayer, dims: [usize; 3], min_voxels: usize) {
    let size = dims.map(|d| d as i64);
    let offsets = neighbour_offsets();
    let codes = &mut layer.codes;
    let mut seen = vec![false; codes.len()];
    let mut component = Vec::new();
    let mut stack = Vec::new();
    for start in 0..codes.len() {
        let code = codes[start];
        if code == 0 || seen[start] {
            continue;
        }
        component.clear();
        stack.push(start);
        seen[start] = true;
        while let Some(v) = stack.pop() {
            component.push(v);
            let p = [
                (v % dims[0]) as i64,
                ((v / dims[0]) % dims[1]) as i64,
                (v / (dims[0] * dims[1])) as i64,
            ];
            for d in &offsets {
                let q = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
                if (0..3).any(|k| q[k] < 0 || q[k] >= size[k]) {
                    continue;
                }
                let n = (q[0] + size[0] * (q[1] + size[1] * q[2])) as usize;
                if !seen[n] && codes[n] == code {
                    seen[n] = true;
                    stack.push(n);
                }
            }
        }
        if component.len() < min_voxels {
            for &v in &component {
                codes[v] = 0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxels_sharing_an_edge_are_one_component_and_a_corner_is_not() {
        // Voxels 0 and 4 share an edge (i and j differ); voxel 7 touches 4 only at a corner.
        let dims = [2, 2, 2];
        let mut codes = vec![0u16; 8];
        codes[0] = 1; // (0,0,0)
        codes[3] = 1; // (1,1,0): shares an edge with (0,0,0)
        codes[4] = 2; // (0,0,1)
        codes[7] = 0;
        let mut layer = LabelLayer {
            codes: codes.clone(),
            values: vec![0, 1, 2],
        };
        drop_small_components(&mut layer, dims, 2);
        assert_eq!(layer.codes[0], 1);
        assert_eq!(layer.codes[3], 1);
        assert_eq!(layer.codes[4], 0, "a lone voxel is a speck");
        let mut corner = vec![0u16; 8];
        corner[0] = 1;
        corner[7] = 1; // (1,1,1): only a corner in common
        let mut layer = LabelLayer {
            codes: corner,
            values: vec![0, 1],
        };
        drop_small_components(&mut layer, dims, 2);
        assert!(layer.codes.iter().all(|&c| c == 0));
    }
}
