//! The marching cubes case table, made at start-up by tracing the contour around each of the
//! 256 cube cases instead of typed in as the classic 256-row table.
//!
//! Tracing makes the table consistent by construction: a face with two diagonal inside corners
//! always joins them (it cuts each outside corner off instead), and both cubes that share a face
//! decide it from the same four corners, so neighbouring cubes meet along the same
//! segments. Every cube edge that changes sign lies on two faces, so it has two segments in the
//! cube and the segments close into loops; each loop becomes one polygon, fanned into triangles.
//! Around a vertex (a cube edge) the four cubes' polygons then form one disk, so the surface of
//! any mask is closed and 2-manifold.
//!
//! Joining diagonal inside corners makes voxels that share an edge one piece (the inside is
//! 18-connected): a thin vessel that steps diagonally from slice to slice stays one tube instead
//! of falling apart into pieces that smooth away on their own, and keeps more of its volume.
//!
//! Corner `c` of a cube sits at offset `(c & 1, (c >> 1) & 1, (c >> 2) & 1)`. Edge `e` runs along
//! axis `e / 4` from the corner whose other two bits are `e % 4` (the lower axis in bit 0).

/// Triangles of one case, as triples of cube edges, wound counter-clockwise seen from outside
/// (from the corners not in the case) in a right-handed frame.
pub(crate) type CaseTriangles = Vec<[u8; 3]>;

/// The two corners of each edge, the lower one first.
pub(crate) const EDGE_CORNERS: [[u8; 2]; 12] = edge_corners();

const fn edge_corners() -> [[u8; 2]; 12] {
    let mut out = [[0u8; 2]; 12];
    let mut e = 0;
    while e < 12 {
        let axis = e / 4;
        let rest = e % 4;
        // Spread the two remaining bits around the axis bit.
        let (lo, hi) = (rest & 1, rest >> 1);
        let base = match axis {
            0 => (lo << 1) | (hi << 2),
            1 => lo | (hi << 2),
            _ => lo | (hi << 1),
        };
        out[e] = [base as u8, (base | (1 << axis)) as u8];
        e += 1;
    }
    out
}

/// The edge joining two corners that differ in one bit.
fn edge_between(a: u8, b: u8) -> u8 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    EDGE_CORNERS
        .iter()
        .position(|&c| c == [lo, hi])
        .expect("corners one bit apart share an edge") as u8
}

/// The six faces, each as its four corners in cyclic order.
const FACES: [[u8; 4]; 6] = [
    [0, 2, 6, 4], // x = 0
    [1, 3, 7, 5], // x = 1
    [0, 1, 5, 4], // y = 0
    [2, 3, 7, 6], // y = 1
    [0, 1, 3, 2], // z = 0
    [4, 5, 7, 6], // z = 1
];

/// Each corner's position in the unit cube.
fn corner_point(c: u8) -> [f64; 3] {
    [(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]
}

/// The table for all 256 cases (bit `c` set: corner `c` is inside).
pub(crate) fn case_table() -> Vec<CaseTriangles> {
    (0..=255u8).map(case_triangles).collect()
}

fn case_triangles(case: u8) -> CaseTriangles {
    let inside = |c: u8| case >> c & 1 == 1;
    // Per edge, the (at most two) edges it is joined to by a face segment.
    let mut links: [Vec<u8>; 12] = Default::default();
    for face in FACES {
        for (a, b) in face_segments(face, inside) {
            links[a as usize].push(b);
            links[b as usize].push(a);
        }
    }
    let mut used = [false; 12];
    let mut triangles = Vec::new();
    for start in 0..12u8 {
        if used[start as usize] || links[start as usize].is_empty() {
            continue;
        }
        let mut polygon = vec![start];
        used[start as usize] = true;
        let mut current = start;
        while let Some(&next) = links[current as usize].iter().find(|&&n| !used[n as usize]) {
            used[next as usize] = true;
            polygon.push(next);
            current = next;
        }
        orient_outward(&mut polygon, inside);
        triangulate(&polygon, &mut triangles);
    }
    triangles
}

/// The midpoint of an edge, where a binary mask's vertex sits.
fn edge_midpoint(e: u8) -> [f64; 3] {
    let [a, b] = EDGE_CORNERS[e as usize];
    let (pa, pb) = (corner_point(a), corner_point(b));
    std::array::from_fn(|k| 0.5 * (pa[k] + pb[k]))
}

/// Triangulates a (generally non-planar) polygon the way that encloses the most volume: the
/// classic dynamic programme over polygon triangulations, each triangle weighted by the volume
/// it spans with the cube's centre. Corners are cut off anyway; of the ways to cut them, this
/// keeps the surface closest to the voxels' own volume (a thin vessel loses least).
fn triangulate(polygon: &[u8], out: &mut Vec<[u8; 3]>) {
    let n = polygon.len();
    let p: Vec<[f64; 3]> = polygon
        .iter()
        .map(|&e| edge_midpoint(e).map(|c| c - 0.5))
        .collect();
    let volume = |a: usize, b: usize, c: usize| {
        let (a, b, c) = (p[a], p[b], p[c]);
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
    };
    // best[i][j]: the most volume of the sub-polygon i..=j; apex[i][j]: its third corner.
    let mut best = vec![vec![0.0f64; n]; n];
    let mut apex = vec![vec![0usize; n]; n];
    for span in 2..n {
        for i in 0..n - span {
            let j = i + span;
            best[i][j] = f64::NEG_INFINITY;
            for k in i + 1..j {
                let v = best[i][k] + best[k][j] + volume(i, k, j);
                // Strictly more (with a margin for rounding), so ties keep the first apex.
                if v > best[i][j] + 1e-12 {
                    best[i][j] = v;
                    apex[i][j] = k;
                }
            }
        }
    }
    let mut pending = vec![(0, n - 1)];
    while let Some((i, j)) = pending.pop() {
        if j - i < 2 {
            continue;
        }
        let k = apex[i][j];
        out.push([polygon[i], polygon[k], polygon[j]]);
        pending.push((i, k));
        pending.push((k, j));
    }
}

/// The contour segments on one face, as pairs of edges.
fn face_segments(face: [u8; 4], inside: impl Fn(u8) -> bool) -> Vec<(u8, u8)> {
    let side = |k: usize| edge_between(face[k], face[(k + 1) % 4]);
    let crossing: Vec<usize> = (0..4)
        .filter(|&k| inside(face[k]) != inside(face[(k + 1) % 4]))
        .collect();
    match crossing.len() {
        2 => vec![(side(crossing[0]), side(crossing[1]))],
        4 => {
            // Two diagonal corners inside: join them by cutting each outside corner off on its
            // own. Side k-1 and side k meet at corner k.
            (0..4)
                .filter(|&k| !inside(face[k]))
                .map(|k| (side((k + 3) % 4), side(k)))
                .collect()
        }
        _ => Vec::new(),
    }
}

/// Winds a polygon so its normal points from the inside corners to the outside ones.
fn orient_outward(polygon: &mut [u8], inside: impl Fn(u8) -> bool) {
    let mid = edge_midpoint;
    let mut normal = [0.0; 3];
    let mut outward = [0.0; 3];
    for (i, &e) in polygon.iter().enumerate() {
        let (p, q) = (mid(e), mid(polygon[(i + 1) % polygon.len()]));
        // Newell's normal.
        normal[0] += (p[1] - q[1]) * (p[2] + q[2]);
        normal[1] += (p[2] - q[2]) * (p[0] + q[0]);
        normal[2] += (p[0] - q[0]) * (p[1] + q[1]);
        let [a, b] = EDGE_CORNERS[e as usize];
        let (inner, outer) = if inside(a) { (a, b) } else { (b, a) };
        let (pi, po) = (corner_point(inner), corner_point(outer));
        for k in 0..3 {
            outward[k] += po[k] - pi[k];
        }
    }
    let dot: f64 = (0..3).map(|k| normal[k] * outward[k]).sum();
    if dot < 0.0 {
        polygon.reverse();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn edges_join_corners_one_bit_apart() {
        for (e, [a, b]) in EDGE_CORNERS.iter().enumerate() {
            assert_eq!((a ^ b).count_ones(), 1, "edge {e}");
            assert_eq!(
                (a ^ b).trailing_zeros() as usize,
                e / 4,
                "edge {e} runs along its axis"
            );
        }
    }

    #[test]
    fn empty_and_full_cubes_have_no_triangles_and_one_corner_has_one() {
        let table = case_table();
        assert!(table[0].is_empty());
        assert!(table[255].is_empty());
        for c in 0..8 {
            assert_eq!(table[1 << c].len(), 1, "corner {c} alone");
            assert_eq!(table[255 ^ (1 << c)].len(), 1, "all but corner {c}");
        }
    }

    /// Inside a cube every triangle edge that is not on a face (a fan diagonal) is shared by two
    /// triangles in opposite directions; the edges on faces are the face segments, each used once.
    #[test]
    fn every_case_is_a_set_of_oriented_disks() {
        for (case, triangles) in case_table().iter().enumerate() {
            let mut directed: HashMap<(u8, u8), usize> = HashMap::new();
            for t in triangles {
                assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "case {case}");
                for k in 0..3 {
                    *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &directed {
                assert_eq!(n, 1, "case {case}: edge {a}->{b} used {n} times");
            }
            // Each sign-changing cube edge is a vertex of exactly one polygon.
            let crossing = (0..12)
                .filter(|&e| {
                    let [a, b] = EDGE_CORNERS[e];
                    (case >> a & 1) != (case >> b & 1)
                })
                .count();
            let mut vertices: Vec<u8> = triangles.iter().flatten().copied().collect();
            vertices.sort_unstable();
            vertices.dedup();
            assert_eq!(vertices.len(), crossing, "case {case}");
        }
    }
}
