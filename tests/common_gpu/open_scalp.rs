//! An open mesh for the GPU tests: the scalp with a cap cut off the top, every 40th triangle
//! removed (small holes, some vertices joined only at a corner), and one vertex no triangle uses.

use meshsmooth::mesh::Mesh;

/// `scalp` (the shared fsaverage scalp) opened as above.
pub fn open_scalp(scalp: &Mesh) -> Mesh {
    let (lo, hi) = scalp.bounding_box().expect("not empty");
    let cut = lo[2] + 0.8 * (hi[2] - lo[2]);
    let triangles: Vec<[u32; 3]> = scalp
        .triangles
        .iter()
        .enumerate()
        .filter(|&(t, tri)| {
            t % 40 != 7 && !tri.iter().all(|&v| scalp.positions[v as usize][2] > cut)
        })
        .map(|(_, &tri)| tri)
        .collect();
    assert!(triangles.len() < scalp.triangles.len());
    let mut positions = scalp.positions.clone();
    positions.push(lo);
    Mesh::new(positions, triangles)
}
