//! A coarse grid over a closed surface's box that says where most points lie without casting
//! rays for each. A cell that no triangle touches lies wholly within the same shells (a segment
//! inside it crosses no triangle), and so does every untouched cell that shares a face with it
//! (the segment between their centres stays in the two): one location, found by rays, holds
//! for each connected region of untouched cells. Points in cells a triangle touches are left
//! to the rays.
//!
//! Most points the checks ask about lie in the other structure's box but away from its surface
//! (a rib beside a lung, an organ in the box of a curved vessel). A point near the surface,
//! where two structures meet, casts a short ray instead: only as far as the first placed cell
//! along it, whose location the crossings on the way change shell by shell (parity along any
//! path through a closed surface agrees). A ray out of the surface's box meets more of its
//! tree, and two must agree.

use super::rays::{direction, Cast, Location, RayBvh, ON_SURFACE, TILTS};

/// The most cells one surface's grid has, a byte each: this many per triangle (a tenth of
/// what the trees hold per triangle), within these bounds.
const CELLS_PER_TRIANGLE: usize = 8;
const MIN_CELLS: usize = 1 << 12;
const MAX_CELLS: usize = 1 << 22;
/// A cell's edge in mean triangle edges: small enough that few points share a cell with the
/// surface, large enough that the grid stays small.
const EDGES_PER_CELL: f64 = 2.0;
/// A triangle marks every cell within this of its box (mm, plus a fraction of the
/// coordinates), more than [`ON_SURFACE`]: no point of an unmarked cell is on the surface.
const MARK_PAD: f64 = 1e-4;
/// A short ray looks for a placed cell every half cell along it, this many times, before
/// another direction is tried: rays that stay short cross few of the tree's nodes.
const STEPS: usize = 4;

/// A cell a triangle touches (or one whose region the rays could not place): its points get
/// rays.
const TOUCHED: u8 = 0;
/// A cell not reached yet while the grid is built.
const UNKNOWN: u8 = 1;
/// Cells placed hold `LOCATED + shells`; a region within more shells than a byte holds stays
/// with the rays.
const LOCATED: u8 = 2;

/// Which cells of the grid a surface touches, and where the others lie.
#[derive(Debug, Default)]
pub(super) struct Cells {
    min: [f64; 3],
    /// The surface's box: a point farther than [`MARK_PAD`] beyond it is outside every shell.
    max: [f64; 3],
    size: f64,
    dims: [usize; 3],
    /// Per cell, x fastest: [`TOUCHED`] or `LOCATED + shells`.
    state: Vec<u8>,
}

impl Cells {
    /// The grid over the box `min`..`max` of the closed surface `triangles` (indices into
    /// `positions`, which must be in range), its regions placed by `rays` (built over the same
    /// surface). A surface without triangles or with a box that is not finite gets no cells:
    /// every point goes to the rays.
    pub(super) fn new(
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        min: [f64; 3],
        max: [f64; 3],
        rays: &RayBvh,
    ) -> Self {
        let Some((size, dims)) = layout(positions, triangles, min, max) else {
            return Self::default();
        };
        let mut cells = Self {
            min,
            max,
            size,
            dims,
            state: vec![UNKNOWN; dims[0] * dims[1] * dims[2]],
        };
        cells.mark(positions, triangles);
        cells.place(rays);
        cells
    }

    /// Marks every cell that a triangle's box (padded) meets.
    fn mark(&mut self, positions: &[[f32; 3]], triangles: &[[u32; 3]]) {
        let pad = |x: f64| MARK_PAD + 1e-9 * x.abs();
        for tri in triangles {
            let corners = tri.map(|v| positions[v as usize].map(f64::from));
            let (mut lo, mut hi) = ([0; 3], [0; 3]);
            for k in 0..3 {
                let (a, b) = (corners.iter())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
                        (a.min(c[k]), b.max(c[k]))
                    });
                lo[k] = self.axis_cell(k, a - pad(a));
                hi[k] = self.axis_cell(k, b + pad(b));
            }
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    let row = (z * self.dims[1] + y) * self.dims[0];
                    self.state[row + lo[0]..=row + hi[0]].fill(TOUCHED);
                }
            }
        }
    }

    /// Places each connected region of untouched cells by one location of a cell's centre.
    fn place(&mut self, rays: &RayBvh) {
        let [nx, ny, nz] = self.dims;
        let mut stack: Vec<usize> = Vec::new();
        for seed in 0..self.state.len() {
            if self.state[seed] != UNKNOWN {
                continue;
            }
            let value = match rays.locate(self.centre(seed)) {
                Location::Within { shells } if shells < usize::from(u8::MAX - LOCATED) => {
                    LOCATED + shells as u8
                }
                // A centre on the surface cannot be in an untouched cell; should the rays
                // say so, the region's points get rays of their own.
                _ => TOUCHED,
            };
            self.state[seed] = value;
            stack.push(seed);
            while let Some(i) = stack.pop() {
                let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
                let mut visit = |j: usize| {
                    if self.state[j] == UNKNOWN {
                        self.state[j] = value;
                        stack.push(j);
                    }
                };
                if x > 0 {
                    visit(i - 1);
                }
                if x + 1 < nx {
                    visit(i + 1);
                }
                if y > 0 {
                    visit(i - nx);
                }
                if y + 1 < ny {
                    visit(i + nx);
                }
                if z > 0 {
                    visit(i - nx * ny);
                }
                if z + 1 < nz {
                    visit(i + nx * ny);
                }
            }
        }
    }

    /// Where `p` lies against the surface `rays` was built over (the one these cells were).
    pub(super) fn locate(&self, p: [f64; 3], rays: &RayBvh) -> Location {
        match self.cell_of(p).map(|i| self.state[i]) {
            Some(s) if s >= LOCATED => Location::Within {
                shells: usize::from(s - LOCATED),
            },
            Some(_) => self.short_ray(p, rays).unwrap_or_else(|| rays.locate(p)),
            None => rays.locate(p),
        }
    }

    /// Where `p` lies by a short ray to the first placed point along it, towards the nearest
    /// side of the surface's box first, then the other five; `None` where none can tell (no
    /// placed point near, or crossings that leave open which shells of the placed point's
    /// count they changed). One ray is enough where [`RayBvh::locate`] wants two
    /// that agree: its end's location is the region's, which had those votes, and the rays'
    /// test counts every crossing of a closed shell exactly once or doubts it.
    pub(super) fn short_ray(&self, p: [f64; 3], rays: &RayBvh) -> Option<Location> {
        let nearest = rays.nearest_side(p)?;
        let others = (0..6).map(|s| (s / 2, if s % 2 == 0 { -1.0 } else { 1.0 }));
        let sides = std::iter::once(nearest).chain(others.filter(|&s| s != nearest));
        for ((axis, sign), tilt) in sides.zip(TILTS) {
            let dir = direction(axis, sign, tilt);
            let Some((length, there)) = self.placed_along(p, dir) else {
                continue;
            };
            let odd = match rays.cast_within(p, dir, length) {
                Cast::OnSurface => return Some(Location::OnSurface),
                Cast::Doubtful => continue,
                Cast::Crossed(odd) => odd.len(),
            };
            // The shells the crossings flip are known where the placed point lies in none or
            // all of them, or where none flips.
            let shells = match (there, odd) {
                (n, 0) => n,
                (0, k) => k,
                (n, k) if n == rays.shell_count() => n - k,
                _ => continue,
            };
            return Some(Location::Within { shells });
        }
        None
    }

    /// The first point along the ray from `p` along `dir` (every half cell) in a placed cell or
    /// clear of the surface's box: its distance from `p`, and inside how many shells it lies.
    fn placed_along(&self, p: [f64; 3], dir: [f64; 3]) -> Option<(f64, usize)> {
        let step = 0.5 * self.size;
        (1..=STEPS).find_map(|i| {
            let length = i as f64 * step;
            let q: [f64; 3] = std::array::from_fn(|k| p[k] + length * dir[k]);
            let clear = (0..3).any(|k| {
                q[k] < self.min[k] - 2.0 * MARK_PAD || q[k] > self.max[k] + 2.0 * MARK_PAD
            });
            if clear {
                return Some((length, 0));
            }
            match self.cell_of(q).map(|c| self.state[c]) {
                Some(s) if s >= LOCATED => Some((length, usize::from(s - LOCATED))),
                _ => None,
            }
        })
    }

    /// Whether the cells answer for `p` without rays.
    #[cfg(test)]
    pub(super) fn placed(&self, p: [f64; 3]) -> bool {
        self.cell_of(p).is_some_and(|i| self.state[i] >= LOCATED)
    }

    /// The cell along axis `k` holding coordinate `x`, clamped to the grid.
    fn axis_cell(&self, k: usize, x: f64) -> usize {
        let c = (x - self.min[k]) / self.size;
        if c < 1.0 {
            0
        } else {
            (c as usize).min(self.dims[k] - 1)
        }
    }

    /// The cell holding `p`, `None` outside the grid.
    fn cell_of(&self, p: [f64; 3]) -> Option<usize> {
        if self.state.is_empty() {
            return None;
        }
        let mut at = [0usize; 3];
        for k in 0..3 {
            // Truncation is the floor at and above 0, without a call to `floor`.
            let c = (p[k] - self.min[k]) / self.size;
            if !(c >= 0.0 && c < self.dims[k] as f64) {
                return None;
            }
            at[k] = c as usize;
        }
        Some((at[2] * self.dims[1] + at[1]) * self.dims[0] + at[0])
    }

    fn centre(&self, i: usize) -> [f64; 3] {
        let at = [
            i % self.dims[0],
            (i / self.dims[0]) % self.dims[1],
            i / (self.dims[0] * self.dims[1]),
        ];
        std::array::from_fn(|k| self.min[k] + (at[k] as f64 + 0.5) * self.size)
    }
}

/// The cell edge and the cells along each axis for a surface with box `min`..`max`: a few
/// mean triangle edges, larger where the box would need more cells than the surface may have.
fn layout(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    min: [f64; 3],
    max: [f64; 3],
) -> Option<(f64, [usize; 3])> {
    let edges: f64 = (triangles.iter())
        .map(|t| {
            let (a, b) = (positions[t[0] as usize], positions[t[1] as usize]);
            (0..3)
                .map(|k| (f64::from(a[k]) - f64::from(b[k])).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum();
    let mean_edge = edges / triangles.len().max(1) as f64;
    let extent: [f64; 3] = std::array::from_fn(|k| max[k] - min[k]);
    let volume: f64 = extent.iter().product();
    let most = (CELLS_PER_TRIANGLE * triangles.len()).clamp(MIN_CELLS, MAX_CELLS);
    let mut size = (EDGES_PER_CELL * mean_edge).max((volume / most as f64).cbrt());
    if !(size.is_finite() && size > ON_SURFACE && extent.iter().all(|e| e.is_finite())) {
        return None;
    }
    loop {
        let along = extent.map(|e| (e / size).floor() + 1.0);
        if along.iter().product::<f64>() <= most as f64 {
            return Some((size, along.map(|n| n as usize)));
        }
        size *= 1.25;
    }
}
