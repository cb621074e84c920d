use std::collections::HashMap;

use super::rays::{direction, Cast, Location, RayBvh, TILTS};
use super::*;

/// An outward-wound box from `min` to `max`: 8 corners, 12 triangles.
fn cube(min: [f32; 3], max: [f32; 3]) -> Mesh {
    let positions = (0..8)
        .map(|v| [0, 1, 2].map(|k| if v >> k & 1 == 1 { max[k] } else { min[k] }))
        .collect();
    let quads = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let triangles = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    Mesh::new(positions, triangles)
}

/// `outer` with `inner` as an inward-facing cavity shell: one structure, two shells.
fn with_cavity(outer: Mesh, inner: Mesh) -> Mesh {
    let offset = outer.positions.len() as u32;
    let mut mesh = outer;
    mesh.positions.extend(inner.positions);
    mesh.triangles.extend(
        inner
            .triangles
            .iter()
            .map(|t| [t[0] + offset, t[2] + offset, t[1] + offset]),
    );
    mesh
}

/// The staircase surface of the unit voxels of `grid` (indexed `[x][y][z]`) that hold `label`,
/// welded, as a label map's extraction makes it: neighbouring labels share faces exactly.
fn voxel_surface(grid: &[Vec<Vec<u8>>], label: u8) -> Mesh {
    let n = [grid.len(), grid[0].len(), grid[0][0].len()];
    let at = |p: [i64; 3]| -> u8 {
        if (0..3).all(|k| p[k] >= 0 && (p[k] as usize) < n[k]) {
            grid[p[0] as usize][p[1] as usize][p[2] as usize]
        } else {
            0
        }
    };
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut vertex = |p: [i64; 3]| {
        *index.entry(p).or_insert_with(|| {
            positions.push(p.map(|x| x as f32));
            positions.len() as u32 - 1
        })
    };
    for x in 0..n[0] as i64 {
        for y in 0..n[1] as i64 {
            for z in 0..n[2] as i64 {
                let v = [x, y, z];
                if at(v) != label {
                    continue;
                }
                for axis in 0..3 {
                    for side in [0i64, 1] {
                        let mut next = v;
                        next[axis] += 2 * side - 1;
                        if at(next) == label {
                            continue;
                        }
                        // The face's corners in order around the outward normal.
                        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                        let mut corner = |du: i64, dw: i64| {
                            let mut p = v;
                            p[axis] += side;
                            p[u] += du;
                            p[w] += dw;
                            vertex(p)
                        };
                        let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        let q = if side == 1 {
                            q
                        } else {
                            [q[0], q[3], q[2], q[1]]
                        };
                        triangles.push([q[0], q[1], q[2]]);
                        triangles.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
    }
    Mesh::new(positions, triangles)
}

/// A grid of `n` voxels a side, labelled by `label(x, y, z)`.
fn grid(n: usize, label: impl Fn(usize, usize, usize) -> u8) -> Vec<Vec<Vec<u8>>> {
    (0..n)
        .map(|x| {
            (0..n)
                .map(|y| (0..n).map(|z| label(x, y, z)).collect())
                .collect()
        })
        .collect()
}

fn pair(list: &[PairRelation], a: usize, b: usize) -> PairRelation {
    *list
        .iter()
        .find(|r| (r.a, r.b) == (a, b))
        .unwrap_or_else(|| panic!("no pair ({a}, {b}) in {list:?}"))
}

/// Moves every vertex of `mesh` away from its centroid by `by` mm.
fn push_out(mesh: &Mesh, by: f64) -> Mesh {
    let n = mesh.positions.len() as f64;
    let c = [0, 1, 2].map(|k| mesh.positions.iter().map(|p| p[k] as f64).sum::<f64>() / n);
    let positions = mesh
        .positions
        .iter()
        .map(|p| {
            let d = [0, 1, 2].map(|k| p[k] as f64 - c[k]);
            let r = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            [0, 1, 2].map(|k| (c[k] + d[k] * (r + by) / r) as f32)
        })
        .collect();
    Mesh::new(positions, mesh.triangles.clone())
}

#[test]
fn test_meshes_are_closed_and_outward() {
    assert_eq!(cube([0.0; 3], [1.0; 3]).signed_volume(), 1.0);
    let hollow = with_cavity(cube([0.0; 3], [3.0; 3]), cube([1.0; 3], [2.0; 3]));
    assert_eq!(hollow.signed_volume(), 26.0);
    let g = grid(4, |x, y, z| u8::from(x < 2 && y < 3 && z < 4));
    assert_eq!(voxel_surface(&g, 1).signed_volume(), 24.0);
}

#[test]
fn rays_tell_inside_outside_and_on_a_staircase_at_centres_corners_and_edges() {
    // A voxel ball: every grid corner and edge midpoint on its surface is a staircase vertex
    // or edge, where rays are most likely to go wrong.
    let n = 10;
    let ball = |x: usize, y: usize, z: usize| {
        let d = [x, y, z].map(|c| c as f64 + 0.5 - n as f64 / 2.0);
        u8::from(d.iter().map(|v| v * v).sum::<f64>() < 12.0)
    };
    let mesh = voxel_surface(&grid(n, ball), 1);
    let rays = RayBvh::new(&mesh.positions, &mesh.triangles);
    let filled = |v: [i64; 3]| {
        v.iter().all(|&c| (0..n as i64).contains(&c))
            && ball(v[0] as usize, v[1] as usize, v[2] as usize) == 1
    };
    let mut checked = 0;
    // Points at half-voxel steps: a voxel centre, a face centre, an edge midpoint or a corner.
    for x in -2..=2 * n as i64 + 2 {
        for y in -2..=2 * n as i64 + 2 {
            for z in -2..=2 * n as i64 + 2 {
                let h = [x, y, z];
                // The voxels the point touches: one for a centre, up to 8 for a corner.
                let spans = h.map(|c| {
                    if c % 2 == 0 {
                        vec![c / 2 - 1, c / 2]
                    } else {
                        vec![c / 2]
                    }
                });
                let mut count = (0, 0);
                for &i in &spans[0] {
                    for &j in &spans[1] {
                        for &k in &spans[2] {
                            count.0 += usize::from(filled([i, j, k]));
                            count.1 += 1;
                        }
                    }
                }
                let expected = match count {
                    (0, _) => Location::Within { shells: 0 },
                    (f, all) if f == all => Location::Within { shells: 1 },
                    _ => Location::OnSurface,
                };
                let p = h.map(|c| c as f64 / 2.0);
                assert_eq!(rays.locate(p), expected, "at {p:?}");
                checked += 1;
            }
        }
    }
    assert!(checked > 10_000);
}

#[test]
fn a_ray_through_an_edge_or_a_vertex_is_doubted_and_another_one_cast() {
    let box_ = cube([0.0; 3], [10.0; 3]);
    let rays = RayBvh::new(&box_.positions, &box_.triangles);
    // Dyadic tilts make the arithmetic exact, so these rays meet the edge, the corner and the
    // quad's diagonal exactly at x = 10, where counting the two (or more) triangles that touch
    // the ray once or twice would be a guess.
    let up = [1.0, 0.5, 0.25];
    let down = [1.0, 0.5, -0.25];
    let grazing = [
        ([2.0, 6.0, 3.0], up),   // edge (10, 10, 5)
        ([2.0, 6.0, 8.0], up),   // corner (10, 10, 10)
        ([2.0, 1.0, 2.0], down), // edge (10, 5, 0)
        ([2.0, 1.0, 3.0], up),   // diagonal of the x = 10 face, (10, 5, 5)
    ];
    for (origin, dir) in grazing {
        assert_eq!(rays.cast(origin, dir), Cast::Doubtful, "from {origin:?}");
        assert_eq!(rays.locate(origin), Location::Within { shells: 1 });
    }
    // Through a face's interior it is a plain crossing of the one shell.
    assert_eq!(rays.cast([2.0, 1.0, 2.0], up), Cast::Crossed(vec![0]));
    assert_eq!(
        rays.cast([2.0, 1.0, 2.0], direction(0, 1.0, TILTS[0])),
        Cast::Crossed(vec![0])
    );
}

#[test]
fn cubes_apart_are_left_out_unless_the_tolerance_bridges_them() {
    let a = cube([0.0; 3], [1.0; 3]);
    let b = cube([5.0; 3], [6.0; 3]);
    assert!(relations(&[&a, &b], &[0.5, 0.5]).is_empty());
    // Grown by 5 mm the boxes meet, but no corner of one comes within 5 mm of the other.
    let near = relations(&[&a, &b], &[0.5, 5.0]);
    let r = pair(&near, 0, 1);
    assert!(!r.a_inside_b && !r.b_inside_a && !r.crosses, "{r:?}");
    assert_eq!(r.overlap_depth, 0.0);
}

#[test]
fn a_cube_in_another_s_material_is_inside_and_crosses_it() {
    let inner = cube([2.0; 3], [4.0; 3]);
    let outer = cube([0.0; 3], [10.0; 3]);
    let r = pair(&relations(&[&inner, &outer], &[0.1, 0.1]), 0, 1);
    assert!(r.a_inside_b, "{r:?}");
    assert!(!r.b_inside_a, "{r:?}");
    // Nested without a cavity, its surface lies in the outer one's material: its corner at 4
    // is deepest.
    assert!((r.overlap_depth - 4.0).abs() < 1e-9, "{r:?}");
    assert!(r.crosses);
}

#[test]
fn a_cube_in_a_cavity_is_inside_without_crossing_and_one_in_the_wall_crosses() {
    let hollow = with_cavity(cube([0.0; 3], [10.0; 3]), cube([2.0; 3], [8.0; 3]));
    let in_cavity = cube([3.0; 3], [7.0; 3]);
    let in_wall = cube([0.5; 3], [1.5; 3]);
    let list = relations(&[&hollow, &in_cavity, &in_wall], &[0.1; 3]);
    let r = pair(&list, 0, 1);
    assert!(r.b_inside_a && !r.a_inside_b, "{r:?}");
    assert_eq!(r.overlap_depth, 0.0, "{r:?}");
    assert!(!r.crosses);
    let r = pair(&list, 0, 2);
    assert!(r.b_inside_a && !r.a_inside_b, "{r:?}");
    // Its corner at 1.5 is deepest: 0.5 from the cavity's corner along each axis.
    assert!((r.overlap_depth - 0.75f64.sqrt()).abs() < 1e-9, "{r:?}");
    assert!(r.crosses);
    assert_eq!(list.len(), 2, "the small cubes are apart: {list:?}");
}

#[test]
fn overlapping_cubes_cross_by_the_depth_of_the_deepest_vertex() {
    let a = cube([0.0; 3], [10.0; 3]);
    let b = cube([7.0, -5.0, -5.0], [20.0, 15.0, 15.0]);
    let r = pair(&relations(&[&a, &b], &[0.5, 0.5]), 0, 1);
    assert!(!r.a_inside_b && !r.b_inside_a, "{r:?}");
    assert!((r.overlap_depth - 3.0).abs() < 1e-9, "{r:?}");
    assert!(r.crosses);
    // The pair takes the larger tolerance: 4 mm covers the 3 mm overlap.
    let r = pair(&relations(&[&a, &b], &[0.5, 4.0]), 0, 1);
    assert!((r.overlap_depth - 3.0).abs() < 1e-9, "{r:?}");
    assert!(!r.crosses);
}

#[test]
fn structures_sharing_staircase_faces_touch_without_crossing() {
    // An organ (1) with a tumour (2) carved out of it and a neighbour (3) against one side,
    // all sharing faces exactly, as a label map's extraction gives them.
    let labels = grid(12, |x, y, z| {
        let core = (4..6).contains(&x) && (4..6).contains(&y) && (4..6).contains(&z);
        let organ = (1..9).contains(&x) && (1..9).contains(&y) && (1..9).contains(&z);
        let side = (9..11).contains(&x) && (2..6).contains(&y) && (2..6).contains(&z);
        match (core, organ, side) {
            (true, _, _) => 2,
            (_, true, _) => 1,
            (_, _, true) => 3,
            _ => 0,
        }
    });
    let organ = voxel_surface(&labels, 1);
    let tumour = voxel_surface(&labels, 2);
    let side = voxel_surface(&labels, 3);
    let tol = [0.5; 3];
    let list = relations(&[&organ, &tumour, &side], &tol);
    let r = pair(&list, 0, 1);
    assert!(r.b_inside_a && !r.a_inside_b, "{r:?}");
    let r = pair(&list, 0, 2);
    assert!(!r.a_inside_b && !r.b_inside_a, "{r:?}");
    assert!(
        list.iter().all(|r| r.overlap_depth == 0.0 && !r.crosses),
        "{list:?}"
    );

    // Within the tolerance the tumour stays inside without crossing; beyond it, it crosses.
    let list = relations(&[&organ, &push_out(&tumour, 0.3), &side], &tol);
    let r = pair(&list, 0, 1);
    assert!(r.b_inside_a && !r.crosses, "{r:?}");
    assert!(
        r.overlap_depth > 0.1 && r.overlap_depth <= 0.3 + 1e-6,
        "{r:?}"
    );
    let grown = relations(&[&organ, &push_out(&tumour, 1.0), &side], &tol);
    let r = pair(&grown, 0, 1);
    assert!(r.b_inside_a && r.crosses, "{r:?}");
    assert!(
        r.overlap_depth > 0.5 && r.overlap_depth <= 1.0 + 1e-6,
        "{r:?}"
    );
    let change = changes(&list, &grown);
    assert_eq!(change.new_crossings, vec![(0, 1)]);
    assert!(change.left_inside.is_empty(), "{change:?}");

    // Pushed out beyond the organ's wall (3 voxels), it no longer lies inside.
    let out = relations(&[&organ, &push_out(&tumour, 6.0), &side], &tol);
    let change = changes(&list, &out);
    assert_eq!(change.left_inside, vec![(1, 0)]);
}

#[test]
fn a_tumour_in_a_dent_open_by_a_voxel_layer_still_lies_inside() {
    // As in the phantom, the organ's voxels stop one layer short over the tumour: the tumour's
    // top touches the background, 1 mm from the organ's surface at most. That is over either
    // tolerance but within their sum, which is how far apart the staircases of two touching
    // true boundaries can lie.
    let labels = grid(10, |x, y, z| {
        let core = (4..6).contains(&x) && (4..6).contains(&y) && (4..7).contains(&z);
        let organ = (1..9).contains(&x) && (1..9).contains(&y) && (1..7).contains(&z);
        match (core, organ) {
            (true, _) => 2,
            (_, true) => 1,
            _ => 0,
        }
    });
    let organ = voxel_surface(&labels, 1);
    let tumour = voxel_surface(&labels, 2);
    let r = pair(&relations(&[&organ, &tumour], &[0.6, 0.6]), 0, 1);
    assert!(r.b_inside_a && !r.a_inside_b && !r.crosses, "{r:?}");
    let r = pair(&relations(&[&organ, &tumour], &[0.45, 0.45]), 0, 1);
    assert!(!r.b_inside_a, "{r:?}");
}

#[test]
fn changes_report_left_insides_and_new_crossings_only() {
    let far = |inside: bool| if inside { 0.0 } else { f64::INFINITY };
    let rel = |a, b, a_inside_b, b_inside_a, crosses| PairRelation {
        a,
        b,
        a_inside_b,
        b_inside_a,
        a_outside_b: far(a_inside_b),
        b_outside_a: far(b_inside_a),
        tolerance: 0.5,
        overlap_depth: if crosses { 1.0 } else { 0.0 },
        crosses,
    };
    let before = [
        rel(0, 1, true, false, false),
        rel(0, 2, false, true, false),
        rel(1, 2, false, false, true),
        rel(2, 3, true, false, false),
    ];
    let after = [
        rel(0, 1, false, false, true),
        rel(1, 2, false, false, true),
        rel(2, 3, true, false, false),
        rel(3, 4, false, false, true),
    ];
    let c = changes(&before, &after);
    assert_eq!(c.left_inside, vec![(0, 1), (2, 0)]);
    assert_eq!(c.new_crossings, vec![(0, 1), (3, 4)]);
    assert_eq!(changes(&after, &after), RelationChanges::default());

    // A structure already touching the outside (within the enclosure tolerance, 2 mm out)
    // has not left for reaching 0.4 mm farther; 0.6 mm farther is more than the tolerance.
    let touching = |outside: f64| PairRelation {
        a_outside_b: outside,
        ..rel(0, 1, true, false, false)
    };
    let c = changes(&[touching(2.0)], &[touching(2.4)]);
    assert!(c.left_inside.is_empty(), "{c:?}");
    let c = changes(&[touching(2.0)], &[touching(2.6)]);
    assert_eq!(c.left_inside, vec![(0, 1)]);
}

#[test]
fn marks_are_the_vertices_that_left_or_reach_too_deep() {
    // A tumour in an organ's cavity, one corner pulled out through the wall.
    let organ = with_cavity(cube([0.0; 3], [10.0; 3]), cube([2.0; 3], [8.0; 3]));
    let tumour = cube([3.0; 3], [7.0; 3]);
    let mut pulled = tumour.clone();
    pulled.positions[7] = [12.0; 3];
    let tol = [0.25, 0.25];
    let before = relations(&[&organ, &tumour], &tol);
    let after = relations(&[&organ, &pulled], &tol);
    let changed = changes(&before, &after);
    assert_eq!(changed.left_inside, vec![(1, 0)], "{changed:?}");
    // Pulled out, the tumour now holds the organ's corners at 8 and 10 too: a new crossing.
    assert_eq!(changed.new_crossings, vec![(0, 1)], "{changed:?}");
    let marked = marks(&[&organ, &pulled], &tol, &before, &changed);
    assert_eq!(marked, vec![vec![7, 15], vec![7]]);
    // Nothing changed, nothing marked.
    let none = marks(
        &[&organ, &tumour],
        &tol,
        &before,
        &changes(&before, &before),
    );
    assert_eq!(none, vec![Vec::<u32>::new(); 2]);

    // Two cubes apart, then one pushed 3 mm into the other: the corners of `a` inside `b` are
    // marked; no corner of `b` lies in `a`.
    let a = cube([0.0; 3], [10.0; 3]);
    let apart = cube([12.0, -5.0, -5.0], [25.0, 15.0, 15.0]);
    let into = cube([7.0, -5.0, -5.0], [20.0, 15.0, 15.0]);
    let before = relations(&[&a, &apart], &[0.5, 0.5]);
    let after = relations(&[&a, &into], &[0.5, 0.5]);
    let changed = changes(&before, &after);
    assert_eq!(changed.new_crossings, vec![(0, 1)], "{changed:?}");
    let marked = marks(&[&a, &into], &[0.5, 0.5], &before, &changed);
    assert_eq!(marked, vec![vec![1, 3, 5, 7], vec![]]);
    // A tolerance past the 3 mm depth marks nothing.
    let marked = marks(&[&a, &into], &[0.5, 4.0], &before, &changed);
    assert_eq!(marked, vec![Vec::<u32>::new(); 2]);
}

/// A block with a cavity and a notch down one edge (outside, but in its box): the rays and
/// cells of its surface.
fn notched_block() -> (RayBvh, super::cells::Cells) {
    let voxels = grid(30, |x, y, z| {
        let block = [x, y, z].iter().all(|&c| (2..28).contains(&c));
        let cavity = [x, y, z].iter().all(|&c| (9..21).contains(&c));
        let notch = x >= 22 && y >= 22;
        u8::from(block && !cavity && !notch)
    });
    let mesh = voxel_surface(&voxels, 1);
    let rays = RayBvh::new(&mesh.positions, &mesh.triangles);
    let bounds = Box3::of(&mesh.positions).unwrap();
    let cells = super::cells::Cells::new(
        &mesh.positions,
        &mesh.triangles,
        bounds.min,
        bounds.max,
        &rays,
    );
    (rays, cells)
}

#[test]
fn cells_place_points_as_the_rays_do_in_material_cavity_and_a_notch() {
    let (rays, cells) = notched_block();
    // Every half voxel: on faces, edges and corners of the staircase as well as between.
    let mut placed = [0usize; 3];
    let steps = (-2..=62).map(|i| f64::from(i) * 0.5);
    for x in steps.clone() {
        for y in steps.clone() {
            for z in steps.clone() {
                let p = [x, y, z];
                let by_rays = rays.locate(p);
                assert_eq!(cells.locate(p, &rays), by_rays, "at {p:?}");
                if let (true, Location::Within { shells }) = (cells.placed(p), by_rays) {
                    placed[shells] += 1;
                }
            }
        }
    }
    // Outside (the notch), in the material and in the cavity, most points went without rays.
    assert!(placed.iter().all(|&n| n > 500), "{placed:?}");
    assert!(
        placed.iter().sum::<usize>() > 65 * 65 * 65 / 5,
        "{placed:?}"
    );
}

#[test]
fn a_short_ray_to_a_placed_cell_tells_what_the_rays_out_of_the_box_tell() {
    // The block with a cavity and a notch, and points near its faces but off the voxel grid,
    // where the cells leave them to rays: in the material, the cavity and outside.
    let (rays, cells) = notched_block();
    assert_eq!(rays.shell_count(), 2);
    let mut told = [0usize; 3];
    let mut left = 0;
    let steps = (0..=120).map(|i| f64::from(i) * 0.25 + 0.0173);
    for x in steps.clone() {
        for y in steps.clone() {
            for z in steps.clone() {
                let p = [x, y + 0.0311, z - 0.0057];
                if cells.placed(p) {
                    continue;
                }
                let by_rays = rays.locate(p);
                match cells.short_ray(p, &rays) {
                    Some(short) => {
                        assert_eq!(short, by_rays, "at {p:?}");
                        if let Location::Within { shells } = short {
                            told[shells] += 1;
                        }
                    }
                    None => left += 1,
                }
                assert_eq!(cells.locate(p, &rays), by_rays, "at {p:?}");
            }
        }
    }
    // Near the outer faces, the notch and the cavity's faces, the short rays told most: a ray
    // from the cavity that ends in the wall, within one of the two shells, cannot tell which
    // it crossed, and another direction is tried.
    assert!(told.iter().all(|&n| n > 10_000), "{told:?}, {left} left");
    assert!(
        left * 50 < told.iter().sum::<usize>(),
        "{told:?}, {left} left"
    );
}

#[test]
fn trees_refitted_to_moved_vertices_tell_what_trees_built_anew_tell() {
    // Two neighbouring voxel blocks sharing faces, a hollow one around a third, as opened;
    // then each pushed out from its centre, as smoothing moves vertices and keeps triangles.
    let voxels = grid(16, |x, y, z| {
        let inner = [x, y, z].iter().all(|&c| (6..10).contains(&c));
        let shell = [x, y, z].iter().all(|&c| (3..13).contains(&c));
        match (inner, shell, x < 8) {
            (true, _, _) => 3,
            (false, true, true) => 1,
            (false, true, false) => 2,
            _ => 0,
        }
    });
    let opened: Vec<Mesh> = (1..=3).map(|l| voxel_surface(&voxels, l)).collect();
    let moved: Vec<Mesh> = opened.iter().map(|m| push_out(m, 0.3)).collect();
    let tol = [0.5; 3];
    let mut shapes = TreeShapes::default();
    let before = relations_refitting(&opened.iter().collect::<Vec<_>>(), &tol, &mut shapes);
    assert_eq!(before, relations(&opened.iter().collect::<Vec<_>>(), &tol));
    let after = relations_refitting(&moved.iter().collect::<Vec<_>>(), &tol, &mut shapes);
    assert_eq!(after, relations(&moved.iter().collect::<Vec<_>>(), &tol));
    assert!(after.iter().any(|r| r.crosses), "{after:?}");
    // Shapes of other triangles are not refitted: the trees are built anew.
    let swapped = [&moved[2], &moved[0], &moved[1]];
    assert_eq!(
        relations_refitting(&swapped, &tol, &mut shapes),
        relations(&swapped, &tol)
    );
}
