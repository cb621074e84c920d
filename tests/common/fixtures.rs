//! Small deterministic fixtures: pseudo-random numbers (xorshift, so they need no crate) and
//! the triangles of a grid.

pub struct Rng(pub u64);

impl Rng {
    /// The next number in [0, 1).
    pub fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Two triangles per cell of an `nx` x `ny` grid of vertices numbered row by row.
pub fn grid_triangles(nx: u32, ny: u32) -> Vec<[u32; 3]> {
    let mut triangles = Vec::new();
    for y in 0..ny - 1 {
        for x in 0..nx - 1 {
            let v = y * nx + x;
            triangles.push([v, v + 1, v + nx + 1]);
            triangles.push([v, v + nx + 1, v + nx]);
        }
    }
    triangles
}
