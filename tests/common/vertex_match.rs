//! Finds which written vertex each vertex read back is, where the writer reordered them (the
//! compressed case glTF stores vertices in the order its codecs compress best).
#![allow(dead_code)]

use std::collections::HashMap;

/// For each of `read`, the index of the point of `written` within `tolerance` of it (the
/// nearest where several are); panics unless every point finds one and no two find the same.
/// Staircase surfaces make good keys: their vertices lie a quarter voxel apart or more.
pub fn match_vertices(written: &[[f32; 3]], read: &[[f32; 3]], tolerance: f64) -> Vec<usize> {
    assert_eq!(written.len(), read.len(), "vertex counts differ");
    let cell = tolerance.max(1e-6) * 2.0;
    let key = |p: &[f32; 3]| p.map(|v| (f64::from(v) / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, p) in written.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i);
    }
    let distance = |a: &[f32; 3], b: &[f32; 3]| {
        (0..3)
            .map(|k| (f64::from(a[k]) - f64::from(b[k])).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let mut taken = vec![false; written.len()];
    read.iter()
        .enumerate()
        .map(|(r, p)| {
            let c = key(p);
            let mut best: Option<(f64, usize)> = None;
            for d in 0..27i64 {
                let at = [c[0] + d % 3 - 1, c[1] + d / 3 % 3 - 1, c[2] + d / 9 - 1];
                for &w in grid.get(&at).into_iter().flatten() {
                    let e = distance(&written[w], p);
                    if e <= tolerance && best.is_none_or(|(b, _)| e < b) {
                        best = Some((e, w));
                    }
                }
            }
            let (_, w) = best.unwrap_or_else(|| panic!("vertex {r} read at {p:?} was not written"));
            assert!(!taken[w], "two vertices read match written vertex {w}");
            taken[w] = true;
            w
        })
        .collect()
}

/// `triangles` on the written vertices `matched` names, each starting at its lowest index
/// (codecs keep a triangle's winding, not its first corner), sorted.
pub fn triangles_as_written(triangles: &[[u32; 3]], matched: &[usize]) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| matched[v as usize] as u32))
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect();
    out.sort_unstable();
    out
}

/// `triangles` in the same form, for the written surface itself.
pub fn triangles_sorted(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let identity: Vec<usize> = (0..triangles
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0))
        .collect();
    triangles_as_written(triangles, &identity)
}
