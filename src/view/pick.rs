//! Picking: the ray from the camera through a point of the view, the nearest triangle it hits,
//! and the vertices a brush of a given radius (mm) covers around the hit, with a smooth falloff.
//!
//! The triangle search is brute force, which needs no structure to rebuild when smoothing moves
//! the vertices: every vertex is first projected onto the plane across the ray (two dot
//! products), then a triangle whose projected corners all lie on one side of the ray's
//! axis-aligned box is rejected with a few comparisons; the rare rest get the Möller–Trumbore
//! test. Its test times it on the 414k-triangle segmentation.

use glam::{Vec2, Vec3};

use super::OrbitCamera;
use crate::mesh::Topology;

/// A ray: `origin + t * direction` for `t >= 0`, `direction` of unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

/// Where a ray first meets a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub triangle: u32,
    /// Along the ray, in mesh units.
    pub distance: f32,
    pub point: Vec3,
}

impl OrbitCamera {
    /// The ray from the eye through `point` (in points from the view's top-left corner) of a
    /// view `size` points large, as [`Self::view_proj`] projects; `None` for an empty view.
    pub fn ray_through(&self, point: Vec2, size: Vec2) -> Option<Ray> {
        if !(size.x > 0.0 && size.y > 0.0 && point.is_finite()) {
            return None;
        }
        let aspect = size.x / size.y;
        let tan_v = (self.vertical_fov(aspect) * 0.5).tan();
        let ndc = Vec2::new(2.0 * point.x / size.x - 1.0, 1.0 - 2.0 * point.y / size.y);
        let (right, up) = self.screen_axes();
        let forward = -self.direction();
        let direction =
            (forward + right * (ndc.x * tan_v * aspect) + up * (ndc.y * tan_v)).normalize();
        Some(Ray {
            origin: self.eye(),
            direction,
        })
    }

    /// How many points on screen one mesh unit spans at `p` (across the view, at its depth),
    /// in a view `size` points large: sizes the brush's circle.
    pub fn points_per_unit_at(&self, p: Vec3, size: Vec2) -> f32 {
        let depth = (p - self.eye()).dot(-self.direction());
        let tan_v = (self.vertical_fov(size.x / size.y.max(1e-6)) * 0.5).tan();
        if !(depth > 0.0 && tan_v > 0.0) {
            return 0.0;
        }
        0.5 * size.y / (depth * tan_v)
    }
}

/// The nearest triangle `ray` hits (either side), if any. Triangles with indices outside
/// `positions` are skipped.
pub fn pick_triangle(positions: &[[f32; 3]], triangles: &[[u32; 3]], ray: &Ray) -> Option<Hit> {
    pick_triangle_where(positions, triangles, ray, |_| true)
}

/// The nearest triangle `ray` hits at a point `shown` keeps (what a clipping plane leaves).
pub fn pick_triangle_where(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    ray: &Ray,
    shown: impl Fn(Vec3) -> bool,
) -> Option<Hit> {
    let d = ray.direction;
    if !(d.is_finite() && d.length_squared() > 0.0) {
        return None;
    }
    // Two axes across the ray: the ray is the origin of this plane.
    let (u, v) = d.normalize().any_orthonormal_pair();
    let across: Vec<[f32; 2]> = positions
        .iter()
        .map(|&p| {
            let q = Vec3::from(p) - ray.origin;
            [q.dot(u), q.dot(v)]
        })
        .collect();
    let mut best: Option<Hit> = None;
    for (t, tri) in triangles.iter().enumerate() {
        let (Some(a), Some(b), Some(c)) = (
            across.get(tri[0] as usize),
            across.get(tri[1] as usize),
            across.get(tri[2] as usize),
        ) else {
            continue;
        };
        // The ray misses the triangle's box across it.
        if (a[0] > 0.0 && b[0] > 0.0 && c[0] > 0.0)
            || (a[0] < 0.0 && b[0] < 0.0 && c[0] < 0.0)
            || (a[1] > 0.0 && b[1] > 0.0 && c[1] > 0.0)
            || (a[1] < 0.0 && b[1] < 0.0 && c[1] < 0.0)
        {
            continue;
        }
        let corner = |k: usize| Vec3::from(positions[tri[k] as usize]);
        if let Some(distance) = moller_trumbore(ray, corner(0), corner(1), corner(2)) {
            let point = ray.origin + ray.direction * distance;
            if best.is_none_or(|h| distance < h.distance) && shown(point) {
                best = Some(Hit {
                    triangle: t as u32,
                    distance,
                    point,
                });
            }
        }
    }
    best
}

/// Möller–Trumbore: the distance along `ray` to triangle `p0 p1 p2` (either side), if it hits.
pub fn moller_trumbore(ray: &Ray, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<f32> {
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    // Parallel to the plane (or a degenerate triangle), relative to the edges' size.
    if det.abs() <= f32::EPSILON * e1.length_squared().max(e2.length_squared()) {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - p0;
    let a = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&a) {
        return None;
    }
    let q = s.cross(e1);
    let b = ray.direction.dot(q) * inv;
    if b < 0.0 || a + b > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t >= 0.0).then_some(t)
}

/// The brush's falloff at distance `d` from its centre for radius `r`: 1 within half the
/// radius, easing (smoothstep) to 0 at the rim, 0 beyond.
pub fn brush_falloff(d: f32, r: f32) -> f32 {
    if r.is_nan() || r <= 0.0 {
        return 0.0;
    }
    let t = ((r - d) / (0.5 * r)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The vertices a brush of radius `radius` centred on `hit` covers, each with its falloff in
/// (0, 1]: those within the ball that are connected to the hit triangle through vertices within
/// the ball, so a brush on one wall of a fold does not paint the facing wall.
pub fn brush_footprint(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
    hit: &Hit,
    radius: f32,
) -> Vec<(u32, f32)> {
    let n = positions.len();
    let Some(seeds) = triangles.get(hit.triangle as usize) else {
        return Vec::new();
    };
    if topology.vertex_count() != n {
        return Vec::new();
    }
    let falloff = |i: u32| {
        let d = Vec3::from(positions[i as usize]).distance(hit.point);
        (d < radius).then(|| brush_falloff(d, radius))
    };
    let mut seen = vec![false; n];
    let mut stack: Vec<u32> = Vec::new();
    let mut footprint = Vec::new();
    for &s in seeds {
        if (s as usize) < n && !seen[s as usize] {
            seen[s as usize] = true;
            stack.push(s);
        }
    }
    while let Some(i) = stack.pop() {
        let Some(f) = falloff(i) else { continue };
        if f > 0.0 {
            footprint.push((i, f));
        }
        for &j in topology.neighbors_of(i as usize) {
            if (j as usize) < n && !seen[j as usize] {
                seen[j as usize] = true;
                stack.push(j);
            }
        }
    }
    footprint
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    /// Where a world point lands in a view of `size` points, y down.
    fn to_screen(camera: &OrbitCamera, p: Vec3, size: Vec2) -> Vec2 {
        let ndc = camera.view_proj(size.x / size.y).project_point3(p);
        Vec2::new((ndc.x + 1.0) * 0.5 * size.x, (1.0 - ndc.y) * 0.5 * size.y)
    }

    fn sample() -> Mesh {
        crate::io::load(
            include_bytes!("../../tests/data/bent_tube_staircase.ply"),
            "tube.ply",
        )
        .unwrap()
    }

    /// Every triangle tested, no reject: what the fast search must agree with.
    fn pick_slowly(positions: &[[f32; 3]], triangles: &[[u32; 3]], ray: &Ray) -> Option<f32> {
        triangles
            .iter()
            .filter_map(|t| {
                let c = |k: usize| Vec3::from(positions[t[k] as usize]);
                moller_trumbore(ray, c(0), c(1), c(2))
            })
            .min_by(f32::total_cmp)
    }

    #[test]
    fn the_ray_through_a_projected_point_passes_through_it() {
        let mut camera = OrbitCamera::default();
        camera.fit(Vec3::new(20.0, 5.0, 5.0), Vec3::new(55.0, 50.0, 35.0));
        for size in [Vec2::new(800.0, 600.0), Vec2::new(300.0, 900.0)] {
            for p in [
                camera.target,
                Vec3::new(30.0, 40.0, 10.0),
                Vec3::new(50.0, 8.0, 30.0),
            ] {
                let ray = camera
                    .ray_through(to_screen(&camera, p, size), size)
                    .unwrap();
                let along = (p - ray.origin).dot(ray.direction);
                let off = (ray.origin + along * ray.direction).distance(p);
                assert!(off < 1e-3 * along, "{off} off at {size}");
                assert!((ray.direction.length() - 1.0).abs() < 1e-5);
            }
        }
        assert!(camera.ray_through(Vec2::ZERO, Vec2::ZERO).is_none());
        // A unit at the target spans as many points as the projection says.
        let size = Vec2::new(800.0, 600.0);
        let (right, _) = camera.screen_axes();
        let a = to_screen(&camera, camera.target, size);
        let b = to_screen(&camera, camera.target + right, size);
        let scale = camera.points_per_unit_at(camera.target, size);
        assert!((a.distance(b) - scale).abs() < 1e-3 * scale, "{scale}");
    }

    #[test]
    fn the_nearest_hit_is_found_from_either_side_and_agrees_with_testing_every_triangle() {
        let mesh = sample();
        let mut camera = OrbitCamera::default();
        camera.fit_points(&mesh.positions);
        let size = Vec2::new(640.0, 480.0);
        let mut hits = 0;
        for y in (0..480).step_by(24) {
            for x in (0..640).step_by(32) {
                let ray = camera
                    .ray_through(Vec2::new(x as f32, y as f32), size)
                    .unwrap();
                let fast = pick_triangle(&mesh.positions, &mesh.triangles, &ray);
                let slow = pick_slowly(&mesh.positions, &mesh.triangles, &ray);
                assert_eq!(fast.map(|h| h.distance), slow, "at {x}, {y}");
                if let Some(h) = fast {
                    hits += 1;
                    // The hit lies on its triangle, in front of the eye.
                    let t = mesh.triangles[h.triangle as usize];
                    let c = |k: usize| Vec3::from(mesh.positions[t[k] as usize]);
                    let n = (c(1) - c(0)).cross(c(2) - c(0)).normalize();
                    assert!((h.point - c(0)).dot(n).abs() < 1e-3);
                    assert!(h.distance > 0.0);
                }
            }
        }
        assert!(hits > 20, "the tube fills part of the view: {hits} hits");
        // Pointing away: nothing.
        let away = Ray {
            origin: camera.eye(),
            direction: camera.direction(),
        };
        assert_eq!(pick_triangle(&mesh.positions, &mesh.triangles, &away), None);
        // Bad indices are skipped, a zero direction hits nothing.
        assert_eq!(
            pick_triangle(&mesh.positions, &[[0, 1, 9_999_999]], &away),
            None
        );
        let zero = Ray {
            direction: Vec3::ZERO,
            ..away
        };
        assert_eq!(pick_triangle(&mesh.positions, &mesh.triangles, &zero), None);
    }

    #[test]
    fn a_triangle_is_hit_inside_and_missed_outside() {
        let (p0, p1, p2) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let down = |x, y| Ray {
            origin: Vec3::new(x, y, 5.0),
            direction: -Vec3::Z,
        };
        assert_eq!(moller_trumbore(&down(0.2, 0.2), p0, p1, p2), Some(5.0));
        assert_eq!(moller_trumbore(&down(0.6, 0.6), p0, p1, p2), None);
        assert_eq!(moller_trumbore(&down(-0.1, 0.2), p0, p1, p2), None);
        // From below (the back side) too; behind the origin not.
        let up = Ray {
            origin: Vec3::new(0.2, 0.2, -2.0),
            direction: Vec3::Z,
        };
        assert_eq!(moller_trumbore(&up, p0, p1, p2), Some(2.0));
        let away = Ray {
            direction: -Vec3::Z,
            ..up
        };
        assert_eq!(moller_trumbore(&away, p0, p1, p2), None);
        // Along the plane: no hit.
        let grazing = Ray {
            origin: Vec3::new(-1.0, 0.2, 0.0),
            direction: Vec3::X,
        };
        assert_eq!(moller_trumbore(&grazing, p0, p1, p2), None);
    }

    #[test]
    fn the_falloff_is_full_in_the_middle_and_eases_to_zero_at_the_rim() {
        assert_eq!(brush_falloff(0.0, 4.0), 1.0);
        assert_eq!(brush_falloff(2.0, 4.0), 1.0);
        assert!((brush_falloff(3.0, 4.0) - 0.5).abs() < 1e-6);
        assert_eq!(brush_falloff(4.0, 4.0), 0.0);
        assert_eq!(brush_falloff(9.0, 4.0), 0.0);
        assert_eq!(brush_falloff(0.0, 0.0), 0.0);
        let mut last = 1.0;
        for k in 0..=40 {
            let f = brush_falloff(k as f32 * 0.1, 4.0);
            assert!(f <= last);
            last = f;
        }
    }

    #[test]
    fn the_footprint_is_the_connected_part_of_the_ball() {
        // Two parallel squares 1 mm apart, each two triangles: a brush of 3.5 mm on one does
        // not reach the other, though its ball does.
        let mut positions = Vec::new();
        for z in [0.0, 1.0] {
            positions.extend([[0.0, 0.0, z], [4.0, 0.0, z], [4.0, 4.0, z], [0.0, 4.0, z]]);
        }
        let triangles = vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]];
        let mesh = Mesh::new(positions, triangles);
        let topology = Topology::build(&mesh);
        let ray = Ray {
            origin: Vec3::new(1.0, 1.0, -5.0),
            direction: Vec3::Z,
        };
        let hit = pick_triangle(&mesh.positions, &mesh.triangles, &ray).unwrap();
        assert_eq!(hit.point, Vec3::new(1.0, 1.0, 0.0));
        let mut footprint = brush_footprint(&mesh.positions, &mesh.triangles, &topology, &hit, 3.5);
        footprint.sort_by_key(|f| f.0);
        let d = |i: usize| Vec3::from(mesh.positions[i]).distance(hit.point);
        assert!(d(4) < 3.5, "the other square is within the ball");
        assert_eq!(
            footprint,
            vec![
                (0, brush_falloff(d(0), 3.5)),
                (1, brush_falloff(d(1), 3.5)),
                (3, brush_falloff(d(3), 3.5)),
            ]
        );
        // A radius smaller than the distance to any corner covers nothing.
        assert!(brush_footprint(&mesh.positions, &mesh.triangles, &topology, &hit, 1.0).is_empty());
    }

    /// The 414k-triangle segmentation (../shared/data): picks from many directions agree with
    /// testing every triangle, and the time per pick is printed.
    #[test]
    fn picking_the_large_segmentation_is_fast_and_exact() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/data/segmentations/seg_mni152_gm_plus_wm_p0.5_1mm.ply"
        );
        let bytes = std::fs::read(path).expect("the shared segmentation mesh");
        let mesh = crate::io::load(&bytes, "seg.ply").unwrap();
        assert_eq!(mesh.triangle_count(), 414_236);
        let mut camera = OrbitCamera::default();
        camera.fit_points(&mesh.positions);
        let size = Vec2::new(800.0, 600.0);
        let mut total = std::time::Duration::ZERO;
        let mut hits = 0;
        let points = 25;
        for k in 0..points {
            camera.orbit(37.0, 11.0);
            let at = Vec2::new(300.0 + 8.0 * k as f32, 200.0 + 7.0 * k as f32);
            let ray = camera.ray_through(at, size).unwrap();
            let start = std::time::Instant::now();
            let hit = pick_triangle(&mesh.positions, &mesh.triangles, &ray);
            total += start.elapsed();
            if k % 5 == 0 {
                let slow = pick_slowly(&mesh.positions, &mesh.triangles, &ray);
                assert_eq!(hit.map(|h| h.distance), slow);
            }
            hits += hit.is_some() as usize;
        }
        assert!(hits > points / 2, "{hits} of {points} rays hit the brain");
        println!(
            "pick on {} triangles: {:.2} ms per pick ({hits} hits)",
            mesh.triangle_count(),
            total.as_secs_f64() * 1e3 / points as f64
        );
    }
}
