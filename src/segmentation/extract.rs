//! Label map -> one closed surface per label, by marching cubes on each label's binary mask.
//!
//! One sweep serves every label: the grid is walked a layer of cubes at a time, cubes whose eight
//! voxels share a label are skipped, and a mixed cube is triangulated once for each label among
//! its corners with that label's own case ([`super::cube_table`]). Outside the grid counts as
//! background, so surfaces close at its border. Vertices sit at the midpoints of the voxel edges
//! they cut (the iso-level 0.5 of a binary mask), shared between cubes through per-edge slots:
//! one slot for the label at each end, since both labels' surfaces pass through that point.

use super::cube_table::{case_table, EDGE_CORNERS};
use crate::io::{LabelLayer, LabelMap};
use crate::mesh::{Mesh, NONE};

/// Triangles of every case, flattened: case `c` owns `TRIANGLES[offsets[c]..offsets[c + 1]]`.
struct Cases {
    offsets: Vec<u32>,
    triangles: Vec<[u8; 3]>,
}

impl Cases {
    fn new() -> Self {
        let mut offsets = vec![0u32];
        let mut triangles = Vec::new();
        for case in case_table() {
            triangles.extend(case);
            offsets.push(triangles.len() as u32);
        }
        Self { offsets, triangles }
    }

    fn of(&self, case: u8) -> &[[u8; 3]] {
        let c = case as usize;
        &self.triangles[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }
}

/// One label's surface under construction, in voxel index coordinates.
#[derive(Default)]
struct Builder {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// Vertex slots of the voxel edges of one plane (edges along x and along y, interleaved) or of
/// the edges between two planes (along z): per edge, the vertex of the label at its lower end and
/// at its upper end.
struct Slots {
    slots: Vec<[u32; 2]>,
    /// The slots filled since the last clear: clearing only these keeps a large, mostly empty
    /// grid from costing a full pass over its slots per layer.
    touched: Vec<u32>,
}

impl Slots {
    fn new(len: usize) -> Self {
        Slots {
            slots: vec![[NONE; 2]; len],
            touched: Vec::new(),
        }
    }

    fn clear(&mut self) {
        for &i in &self.touched {
            self.slots[i as usize] = [NONE; 2];
        }
        self.touched.clear();
    }

    fn get(&self, index: usize, end: usize) -> u32 {
        self.slots[index][end]
    }

    fn set(&mut self, index: usize, end: usize, id: u32) {
        let slot = &mut self.slots[index];
        if *slot == [NONE; 2] {
            self.touched.push(index as u32);
        }
        slot[end] = id;
    }
}

/// The surfaces of the labels of one layer, as meshes in voxel index coordinates (`i`, `j`, `k`
/// of the label map), indexed by code; codes not wanted (or the background) get `None`.
pub(crate) fn surfaces_by_code(
    dims: [usize; 3],
    layer: &LabelLayer,
    wanted: &[bool],
) -> Vec<Option<Mesh>> {
    let cases = Cases::new();
    let [nx, ny, nz] = dims;
    let (w, h) = (nx + 2, ny + 2);
    let mut builders: Vec<Option<Builder>> =
        wanted.iter().map(|&on| on.then(Builder::default)).collect();
    if let Some(b) = builders.first_mut() {
        *b = None;
    }
    let mut below = vec![0u16; w * h];
    let mut above = vec![0u16; w * h];
    let mut planes = [Slots::new(2 * w * h), Slots::new(2 * w * h)];
    let mut between = Slots::new(w * h);
    for pz in 0..=nz {
        // Padded planes pz and pz + 1 hold voxel slices pz - 1 and pz.
        std::mem::swap(&mut below, &mut above);
        if pz == 0 {
            below.fill(0);
        }
        fill_plane(&mut above, &layer.codes, dims, pz + 1);
        planes.swap(0, 1);
        planes[1].clear();
        between.clear();
        let mut sweep = LayerSweep {
            cases: &cases,
            builders: &mut builders,
            planes: &mut planes,
            between: &mut between,
            w,
            pz,
        };
        for py in 0..=ny {
            if uniform_rows(&below, &above, py * w, w) {
                continue;
            }
            for px in 0..=nx {
                let i = py * w + px;
                let c0 = below[i];
                let corners = [
                    c0,
                    below[i + 1],
                    below[i + w],
                    below[i + w + 1],
                    above[i],
                    above[i + 1],
                    above[i + w],
                    above[i + w + 1],
                ];
                if corners.iter().all(|&c| c == c0) {
                    continue;
                }
                sweep.cube(px, py, corners);
            }
        }
    }
    builders
        .into_iter()
        .map(|b| b.map(|b| Mesh::new(b.positions, b.triangles)))
        .collect()
}

/// Whether the two rows of cube corners starting at `start` in both planes all hold one code,
/// so no cube of that row is mixed (most rows of a segmentation are background throughout).
fn uniform_rows(below: &[u16], above: &[u16], start: usize, w: usize) -> bool {
    let row = &below[start..start + w];
    let first = row[0];
    row.iter().all(|&c| c == first)
        && below[start + w..start + 2 * w] == *row
        && above[start..start + w] == *row
        && above[start + w..start + 2 * w] == *row
}

/// Copies voxel slice `pz - 1` into a padded plane (a border of background around it); planes
/// outside the grid are all background.
fn fill_plane(plane: &mut [u16], codes: &[u16], dims: [usize; 3], pz: usize) {
    let [nx, ny, nz] = dims;
    let w = nx + 2;
    plane.fill(0);
    if pz == nz + 1 || pz == 0 {
        return;
    }
    let slice = &codes[(pz - 1) * nx * ny..pz * nx * ny];
    for (y, row) in slice.chunks_exact(nx).enumerate() {
        let start = (y + 1) * w + 1;
        plane[start..start + nx].copy_from_slice(row);
    }
}

/// What one layer of cubes writes to.
struct LayerSweep<'a> {
    cases: &'a Cases,
    builders: &'a mut [Option<Builder>],
    planes: &'a mut [Slots; 2],
    between: &'a mut Slots,
    w: usize,
    pz: usize,
}

impl LayerSweep<'_> {
    /// Triangulates one mixed cube (padded lower corner `(px, py)` in this layer) for each wanted
    /// label among its corners.
    fn cube(&mut self, px: usize, py: usize, corners: [u16; 8]) {
        let mut done = [0u16; 8];
        let mut n_done = 0;
        for &code in &corners {
            if code == 0 || done[..n_done].contains(&code) {
                continue;
            }
            done[n_done] = code;
            n_done += 1;
            if self.builders[code as usize].is_none() {
                continue;
            }
            let mut case = 0u8;
            for (c, &k) in corners.iter().enumerate() {
                case |= ((k == code) as u8) << c;
            }
            let cases = self.cases;
            for t in cases.of(case) {
                let v = t.map(|e| self.vertex(px, py, e, code, &corners));
                if let Some(b) = self.builders[code as usize].as_mut() {
                    b.triangles.push(v);
                }
            }
        }
    }

    /// The vertex of `code`'s surface on cube edge `e`, made on first use.
    fn vertex(&mut self, px: usize, py: usize, e: u8, code: u16, corners: &[u16; 8]) -> u32 {
        let [lo, _] = EDGE_CORNERS[e as usize];
        let (dx, dy, dz) = (
            (lo & 1) as usize,
            (lo >> 1 & 1) as usize,
            (lo >> 2 & 1) as usize,
        );
        let (x, y) = (px + dx, py + dy);
        let index = y * self.w + x;
        let axis = e / 4;
        let (slots, slot) = match axis {
            0 | 1 => (&mut self.planes[dz], 2 * index + axis as usize),
            _ => (&mut *self.between, index),
        };
        let end = usize::from(corners[lo as usize] != code);
        let known = slots.get(slot, end);
        if known != NONE {
            return known;
        }
        let b = self.builders[code as usize]
            .as_mut()
            .expect("a wanted label's builder");
        let id = b.positions.len() as u32;
        // Padded grid point (x, y, pz + dz) is voxel (x - 1, y - 1, pz + dz - 1).
        let mut p = [x as f32 - 1.0, y as f32 - 1.0, (self.pz + dz) as f32 - 1.0];
        p[axis as usize] += 0.5;
        b.positions.push(p);
        slots.set(slot, end, id);
        id
    }
}

/// Moves a mesh from voxel index coordinates into the label map's world millimetres, winding
/// its triangles the other way where the affine mirrors (so they still face outward).
pub(crate) fn to_world(mesh: &mut Mesh, map: &LabelMap) {
    for p in &mut mesh.positions {
        let w = map.affine.apply([p[0] as f64, p[1] as f64, p[2] as f64]);
        *p = w.map(|c| c as f32);
    }
    if map.affine.determinant() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
}
