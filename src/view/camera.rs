//! An orbit camera: the eye on a sphere around a target point, Z up.
//!
//! Anatomical meshes are usually stored with Z pointing superior (RAS and LPS alike), so the
//! turntable turns about Z. Yaw 0 looks from +Y, anterior in RAS (NIfTI, FreeSurfer, MNE, the
//! meshes this app mostly gets), with the patient's right on the screen's left as in a
//! radiological front view. Matrices follow wgpu's conventions: right-handed world, clip-space
//! depth in 0..1.

use glam::camera::rh::{proj, view};
use glam::{Mat4, Vec2, Vec3};

/// Turn per point of mouse travel: a drag across ~800 points turns the model once.
pub const ORBIT_RADIANS_PER_POINT: f32 = std::f32::consts::TAU / 800.0;

/// Elevation stays this far short of the poles, where "up" would be undefined.
pub const PITCH_LIMIT: f32 = std::f32::consts::FRAC_PI_2 - 0.01;

/// Default field of view across the viewport's shorter side. Narrow enough that a mesh's
/// proportions are not distorted, wide enough to feel 3D.
pub const DEFAULT_FOV: f32 = 35.0 * std::f32::consts::PI / 180.0;

/// The view [`OrbitCamera::reset_direction`] returns to: a three-quarter view from the front and
/// the patient's left (in RAS), a little above, so that both the shape and its surface relief
/// read at first sight.
pub const DEFAULT_YAW: f32 = 0.5;
pub const DEFAULT_PITCH: f32 = 0.35;

/// A fitted box's widest corner reaches this fraction of the view's shorter half-side.
const FIT_MARGIN: f32 = 1.08;

/// Rounds of centring and moving in by which [`OrbitCamera::fit_points`] settles.
const FIT_ROUNDS: usize = 4;

/// Zoom limits in bounding-sphere radii from the target: close enough to inspect a detail from
/// inside, far enough to see the mesh as a small object; never through the target.
const MIN_DISTANCE: f32 = 0.02;
const MAX_DISTANCE: f32 = 50.0;

/// The near plane never comes closer than this fraction of the far plane: with a 24-bit depth
/// buffer that keeps depth steps below 1e-4 of the far distance.
const NEAR_FRACTION_OF_FAR: f32 = 1e-3;

/// Orbit camera state. Angles in radians; `yaw` turns about +Z, `pitch` lifts the eye above the
/// XY plane through the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    /// The point the eye looks at and orbits around.
    pub target: Vec3,
    /// Eye-to-target distance, in mesh units.
    pub distance: f32,
    pub yaw: f32,
    pub pitch: f32,
    /// Field of view across the viewport's shorter side (vertical in a landscape viewport),
    /// so that a fitted mesh stays in view in portrait viewports too.
    pub fov: f32,
    /// Centre of the framed mesh's bounding sphere: the near and far planes enclose it.
    pub bounds_center: Vec3,
    /// Radius of that sphere (positive): sets the depth range and the zoom limits.
    pub bounds_radius: f32,
}

impl Default for OrbitCamera {
    /// Framing the unit cube at the origin from the default direction.
    fn default() -> Self {
        let mut camera = Self {
            target: Vec3::ZERO,
            distance: 1.0,
            yaw: DEFAULT_YAW,
            pitch: DEFAULT_PITCH,
            fov: DEFAULT_FOV,
            bounds_center: Vec3::ZERO,
            bounds_radius: 1.0,
        };
        camera.fit(Vec3::splat(-0.5), Vec3::splat(0.5));
        camera
    }
}

impl OrbitCamera {
    /// Frames the box `bbox_min..bbox_max` as seen from the current direction: the target at its
    /// centre, the eye as close as it can be with every corner of the box in view (across the
    /// shorter side, so in any aspect ratio). A degenerate or non-finite box is framed as a unit
    /// sphere around its (finite) centre.
    pub fn fit(&mut self, bbox_min: Vec3, bbox_max: Vec3) {
        let mut center = (bbox_min + bbox_max) * 0.5;
        if !center.is_finite() {
            center = Vec3::ZERO;
        }
        let mut half = (bbox_max - bbox_min).abs() * 0.5;
        if !(half.is_finite() && half.length() > 0.0) {
            half = Vec3::splat(1.0 / 3f32.sqrt());
        }
        self.bounds_center = center;
        self.bounds_radius = half.length();
        self.target = center;

        // Each corner in the camera's frame: (x, y) across the view, z away from the eye. It is
        // in view when |x| and |y| are within tan(fov / 2) of its depth, distance + z.
        let tan_half = (self.fov * 0.5).tan() / FIT_MARGIN;
        let (right, up) = self.screen_axes();
        let forward = -self.direction();
        let mut distance = 0.0f32;
        for i in 0..8 {
            let sign = |bit: u32| if i & bit == 0 { -1.0 } else { 1.0 };
            let corner = half * Vec3::new(sign(1), sign(2), sign(4));
            let (x, y, z) = (corner.dot(right), corner.dot(up), corner.dot(forward));
            distance = distance.max(x.abs().max(y.abs()) / tan_half - z);
        }
        let r = self.bounds_radius;
        self.distance = distance.clamp(MIN_DISTANCE * r, MAX_DISTANCE * r);
    }

    /// Frames a point set (a mesh's vertices) as seen from the current direction, tighter than
    /// its bounding box: the target moves to the middle of the points' extent across the view,
    /// and the eye as close as it can be with every point in view. The depth range still
    /// encloses the bounding box, from any direction. Non-finite points are ignored.
    pub fn fit_points(&mut self, points: &[[f32; 3]]) {
        let finite = || {
            points
                .iter()
                .map(|&p| Vec3::from(p))
                .filter(|p| p.is_finite())
        };
        let Some(first) = finite().next() else {
            self.fit(Vec3::ZERO, Vec3::ZERO);
            return;
        };
        let (lo, hi) = finite().fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
        self.fit(lo, hi);

        // Centre the points' perspective extent and move in until the outermost touches the
        // margin; moving in changes the perspective, so a few rounds settle both.
        let (right, up) = self.screen_axes();
        let forward = -self.direction();
        let tan_half = (self.fov * 0.5).tan() / FIT_MARGIN;
        let r = self.bounds_radius;
        for _ in 0..FIT_ROUNDS {
            let (target, distance) = (self.target, self.distance);
            // Each point's direction from the eye, as tangents across the view.
            let seen = |p: Vec3| {
                let q = p - target;
                let depth = (distance + q.dot(forward)).max(1e-6 * r);
                Vec2::new(q.dot(right), q.dot(up)) / depth
            };
            let (min, max) = finite().map(seen).fold(
                (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
                |(min, max), t| (min.min(t), max.max(t)),
            );
            let middle = (min + max) * 0.5 * distance;
            self.target += middle.x * right + middle.y * up;
            let target = self.target;
            let needed = finite().fold(0.0f32, |needed, p| {
                let q = p - target;
                let widest = q.dot(right).abs().max(q.dot(up).abs());
                needed.max(widest / tan_half - q.dot(forward))
            });
            self.distance = needed.clamp(MIN_DISTANCE * r, MAX_DISTANCE * r);
        }
    }

    /// Turns the eye to look from `direction` (from the target towards the eye), as near as the
    /// pitch limit allows; a zero or non-finite direction changes nothing.
    pub fn look_from(&mut self, direction: Vec3) {
        let d = direction.normalize_or_zero();
        if d == Vec3::ZERO {
            return;
        }
        self.pitch = d.z.asin().clamp(-PITCH_LIMIT, PITCH_LIMIT);
        self.yaw = (-d.x).atan2(d.y).rem_euclid(std::f32::consts::TAU);
    }

    /// Turns the eye back to the default direction (the target and distance stay).
    pub fn reset_direction(&mut self) {
        self.yaw = DEFAULT_YAW;
        self.pitch = DEFAULT_PITCH;
    }

    /// Turns the eye around the target by a mouse drag of `(dx, dy)` points: dragging right
    /// turns the model right, dragging down tips its top towards the viewer.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        if !(dx.is_finite() && dy.is_finite()) {
            return;
        }
        self.yaw = (self.yaw - dx * ORBIT_RADIANS_PER_POINT).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + dy * ORBIT_RADIANS_PER_POINT).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves the target in the view plane so that the point under the cursor, at the target's
    /// depth, follows a mouse drag of `(dx, dy)` points in a viewport of `viewport` points.
    pub fn pan(&mut self, dx: f32, dy: f32, viewport: Vec2) {
        let short_side = viewport.min_element();
        if !(short_side > 0.0 && dx.is_finite() && dy.is_finite()) {
            return;
        }
        // World units per point at the target's depth, across the side the fov spans.
        let scale = 2.0 * self.distance * (self.fov * 0.5).tan() / short_side;
        let (right, up) = self.screen_axes();
        self.target += (-dx * right + dy * up) * scale;
    }

    /// Moves the eye towards the target by `factor` (above 1 zooms in, below 1 out), within
    /// limits set by the mesh's size.
    pub fn zoom(&mut self, factor: f32) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let r = self.bounds_radius;
        self.distance = (self.distance / factor).clamp(MIN_DISTANCE * r, MAX_DISTANCE * r);
    }

    /// Unit vector from the target to the eye.
    pub fn direction(&self) -> Vec3 {
        let (sin_yaw, cos_yaw) = self.yaw.sin_cos();
        let (sin_pitch, cos_pitch) = self.pitch.sin_cos();
        Vec3::new(-sin_yaw * cos_pitch, cos_yaw * cos_pitch, sin_pitch)
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.distance * self.direction()
    }

    /// The screen's right and up directions in world space.
    pub fn screen_axes(&self) -> (Vec3, Vec3) {
        let forward = -self.direction();
        let right = forward.cross(Vec3::Z).normalize();
        (right, right.cross(forward))
    }

    pub fn view(&self) -> Mat4 {
        view::look_at_mat4(self.eye(), self.target, Vec3::Z)
    }

    /// Near and far plane distances enclosing the mesh's bounding sphere (with a 1% margin),
    /// as tight as the sphere allows so depth precision goes where the mesh is.
    pub fn depth_range(&self) -> (f32, f32) {
        let r = self.bounds_radius * 1.01;
        let depth_of_center = (self.bounds_center - self.eye()).dot(-self.direction());
        let far = (depth_of_center + r).max(r);
        let near = (depth_of_center - r).max(far * NEAR_FRACTION_OF_FAR);
        (near, far)
    }

    /// Vertical field of view for a viewport of this aspect ratio (width / height): `fov`
    /// itself in landscape, wider in portrait so that `fov` spans the width.
    pub fn vertical_fov(&self, aspect: f32) -> f32 {
        if aspect >= 1.0 {
            self.fov
        } else {
            2.0 * ((self.fov * 0.5).tan() / aspect).atan()
        }
    }

    /// World to clip space for a viewport of this aspect ratio (width / height); a degenerate
    /// aspect (an empty viewport) is treated as square.
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let (near, far) = self.depth_range();
        // wgpu's clip space is WebGPU's (= DirectX's): depth 0..1, y up.
        let projection = proj::directx::perspective(self.vertical_fov(aspect), aspect, near, far);
        projection * self.view()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::{PI, TAU};

    fn staircase_box() -> (Vec3, Vec3) {
        // The bundled sample's bounding box.
        (Vec3::new(22.5, 7.5, 7.5), Vec3::new(52.5, 50.5, 32.5))
    }

    fn corners(lo: Vec3, hi: Vec3) -> impl Iterator<Item = Vec3> {
        (0..8).map(move |i| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
    }

    fn assert_close(a: Vec3, b: Vec3, tol: f32) {
        assert!((a - b).length() <= tol, "{a} vs {b}");
    }

    fn assert_in_view(camera: &OrbitCamera, lo: Vec3, hi: Vec3, aspect: f32) -> f32 {
        let m = camera.view_proj(aspect);
        let mut widest = 0.0f32;
        for p in corners(lo, hi) {
            let clip = m * p.extend(1.0);
            assert!(clip.w > 0.0, "corner {p} behind the eye");
            let ndc = clip.truncate() / clip.w;
            assert!(
                ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
                "{ndc} at {aspect}"
            );
            assert!((0.0..=1.0).contains(&ndc.z), "depth {} at {aspect}", ndc.z);
            widest = widest.max(ndc.x.abs()).max(ndc.y.abs());
        }
        widest
    }

    #[test]
    fn fit_puts_the_whole_box_inside_the_frustum_from_any_side() {
        let boxes = [
            staircase_box(),
            (Vec3::ZERO, Vec3::new(100.0, 1.0, 1.0)),
            (Vec3::new(-5.0, -5.0, 0.0), Vec3::new(5.0, 5.0, 0.0)),
        ];
        for (lo, hi) in boxes {
            let mut camera = OrbitCamera::default();
            for (dx, dy) in [(0.0, 0.0), (200.0, 0.0), (-150.0, 300.0), (90.0, -1000.0)] {
                camera.orbit(dx, dy);
                camera.fit(lo, hi);
                assert_eq!(camera.target, (lo + hi) * 0.5);
                for aspect in [0.4, 1.0, 16.0 / 9.0, 3.0] {
                    assert_in_view(&camera, lo, hi, aspect);
                }
                // Framed tightly: in a square view the widest corner nearly touches the edge.
                let widest = assert_in_view(&camera, lo, hi, 1.0);
                assert!(widest > 0.85, "the box spans only {widest} of the view");
            }
        }
    }

    /// A voxelised-looking arc like the bundled sample: it fills little of its bounding box.
    fn arc() -> Vec<[f32; 3]> {
        (0..200)
            .map(|i| {
                let t = i as f32 / 199.0 * 1.5 * PI;
                [
                    30.0 + 15.0 * t.cos(),
                    25.0 + 20.0 * t.sin(),
                    20.0 + 0.1 * i as f32,
                ]
            })
            .collect()
    }

    #[test]
    fn fitting_the_points_frames_tighter_than_the_box_and_keeps_them_in_view() {
        let points = arc();
        let mut by_box = OrbitCamera::default();
        let (lo, hi) = crate::mesh::bounding_box(&points).expect("points");
        by_box.fit(Vec3::from(lo), Vec3::from(hi));
        let mut by_points = OrbitCamera::default();
        by_points.fit_points(&points);
        assert!(by_points.distance < by_box.distance);
        for aspect in [0.5, 1.0, 2.0] {
            let m = by_points.view_proj(aspect);
            for &p in &points {
                let ndc = m.project_point3(Vec3::from(p));
                assert!(
                    ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
                    "{ndc} at {aspect}"
                );
                assert!((0.0..=1.0).contains(&ndc.z));
            }
        }
        // Centred: the extremes on either side sit at about the same distance from the edge.
        let m = by_points.view_proj(1.0);
        let ndc: Vec<Vec3> = points
            .iter()
            .map(|&p| m.project_point3(Vec3::from(p)))
            .collect();
        let (left, right) = ndc
            .iter()
            .fold((1f32, -1f32), |(l, r), q| (l.min(q.x), r.max(q.x)));
        let (bottom, top) = ndc
            .iter()
            .fold((1f32, -1f32), |(b, t), q| (b.min(q.y), t.max(q.y)));
        assert!(
            (left + right).abs() < 0.05 && (bottom + top).abs() < 0.05,
            "x {left}..{right}, y {bottom}..{top}"
        );
        assert!(right.max(top) > 0.85, "spans only {right} x {top}");
        // The depth range still holds the whole box after orbiting.
        by_points.orbit(300.0, 100.0);
        let m = by_points.view_proj(1.0);
        for p in corners(Vec3::from(lo), Vec3::from(hi)) {
            assert!((0.0..=1.0).contains(&m.project_point3(p).z));
        }
        // Nothing finite to frame: the unit sphere at the origin.
        let mut empty = OrbitCamera::default();
        empty.fit_points(&[[f32::NAN; 3]]);
        assert_eq!(empty.target, Vec3::ZERO);
        assert!(empty.view_proj(1.0).is_finite());
    }

    #[test]
    fn orbiting_after_a_fit_keeps_the_mesh_within_the_depth_range() {
        let (lo, hi) = staircase_box();
        let mut camera = OrbitCamera::default();
        camera.fit(lo, hi);
        for (dx, dy) in [(200.0, 0.0), (-150.0, 300.0), (90.0, -1000.0)] {
            camera.orbit(dx, dy);
            let m = camera.view_proj(1.5);
            for p in corners(lo, hi) {
                let z = m.project_point3(p).z;
                assert!((0.0..=1.0).contains(&z), "corner {p} at depth {z}");
            }
        }
    }

    #[test]
    fn default_direction_is_from_the_front_and_above() {
        let mut camera = OrbitCamera {
            yaw: 0.0,
            pitch: 0.0,
            ..Default::default()
        };
        // From anterior (+Y in RAS): the patient's right (+X) on the screen's left.
        assert_close(camera.direction(), Vec3::Y, 1e-6);
        let (right, up) = camera.screen_axes();
        assert_close(right, -Vec3::X, 1e-6);
        assert_close(up, Vec3::Z, 1e-6);
        // The default: front, left (-X in RAS) and above.
        camera.reset_direction();
        camera.fit(Vec3::splat(-1.0), Vec3::splat(1.0));
        let eye = camera.eye();
        assert!(eye.y > 0.0 && eye.x < 0.0 && eye.z > 0.0, "{eye}");
    }

    #[test]
    fn looking_from_a_direction_puts_the_eye_there() {
        let mut camera = OrbitCamera::default();
        for d in [
            Vec3::X,
            -Vec3::Y,
            Vec3::new(0.3, -0.5, 0.8),
            Vec3::new(-1.0, 2.0, -0.5),
        ] {
            camera.look_from(d);
            assert_close(camera.direction(), d.normalize(), 1e-5);
        }
        // Straight down is held just short of the pole; nothing is no direction.
        camera.look_from(-Vec3::Z);
        assert_eq!(camera.pitch, -PITCH_LIMIT);
        let before = camera;
        camera.look_from(Vec3::ZERO);
        camera.look_from(Vec3::NAN);
        assert_eq!(camera, before);
    }

    #[test]
    fn orbiting_a_full_turn_returns_to_the_start() {
        let mut camera = OrbitCamera::default();
        let start = camera.eye();
        camera.orbit(TAU / ORBIT_RADIANS_PER_POINT, 0.0);
        assert_close(camera.eye(), start, 1e-4);
        // Dragging right moves the eye to the left, so the model turns right.
        let before = camera.eye();
        camera.orbit(10.0, 0.0);
        let (right, _) = camera.screen_axes();
        assert!((camera.eye() - before).dot(right) < 0.0);
    }

    #[test]
    fn pitch_stops_short_of_the_poles() {
        let mut camera = OrbitCamera::default();
        camera.orbit(0.0, 1e6);
        assert_eq!(camera.pitch, PITCH_LIMIT);
        assert!(camera.view_proj(1.5).is_finite());
        camera.orbit(0.0, -1e6);
        assert_eq!(camera.pitch, -PITCH_LIMIT);
        assert!(camera.view_proj(1.5).is_finite());
        // Dragging down lifts the eye.
        let z = camera.eye().z;
        camera.orbit(0.0, 10.0);
        assert!(camera.eye().z > z);
    }

    #[test]
    fn zoom_is_clamped_and_never_reaches_the_target() {
        let mut camera = OrbitCamera::default();
        let r = camera.bounds_radius;
        camera.zoom(1e9);
        assert_eq!(camera.distance, MIN_DISTANCE * r);
        assert!(camera.eye().distance(camera.target) > 0.0);
        let (near, far) = camera.depth_range();
        assert!(near > 0.0 && near < far);
        assert!(camera.view_proj(1.0).is_finite());
        camera.zoom(1e-9);
        assert_eq!(camera.distance, MAX_DISTANCE * r);
        let d = camera.distance;
        for bad in [0.0, -2.0, f32::NAN, f32::INFINITY] {
            camera.zoom(bad);
        }
        assert_eq!(camera.distance, d);
        camera.zoom(2.0);
        assert!((camera.distance - d / 2.0).abs() < 1e-4 * d);
    }

    /// Where a world point lands in a viewport of `size` points, y down.
    fn to_screen(m: Mat4, p: Vec3, size: Vec2) -> Vec2 {
        let ndc = m.project_point3(p);
        Vec2::new((ndc.x + 1.0) * 0.5 * size.x, (1.0 - ndc.y) * 0.5 * size.y)
    }

    #[test]
    fn panning_keeps_the_grabbed_point_under_the_cursor() {
        let (lo, hi) = staircase_box();
        for size in [Vec2::new(800.0, 600.0), Vec2::new(300.0, 900.0)] {
            let mut camera = OrbitCamera::default();
            camera.fit(lo, hi);
            camera.orbit(120.0, 40.0);
            let grabbed = camera.target;
            let before = to_screen(camera.view_proj(size.x / size.y), grabbed, size);
            assert_close(before.extend(0.0), (size * 0.5).extend(0.0), 1e-3);
            let drag = Vec2::new(37.0, -21.0);
            camera.pan(drag.x, drag.y, size);
            let after = to_screen(camera.view_proj(size.x / size.y), grabbed, size);
            assert_close(after.extend(0.0), (before + drag).extend(0.0), 1e-2);
        }
        // An empty viewport moves nothing.
        let mut camera = OrbitCamera::default();
        let target = camera.target;
        camera.pan(10.0, 10.0, Vec2::ZERO);
        assert_eq!(camera.target, target);
    }

    #[test]
    fn depth_range_encloses_the_mesh_after_panning_and_is_tight_from_outside() {
        let (lo, hi) = staircase_box();
        let mut camera = OrbitCamera::default();
        camera.fit(lo, hi);
        let (near, far) = camera.depth_range();
        // From outside the sphere, far / near stays small: good 24-bit depth precision.
        assert!(far / near < 10.0, "near {near} far {far}");
        // Panned so the mesh sits at the edge of the view: still inside the depth range.
        camera.pan(300.0, 0.0, Vec2::new(800.0, 800.0));
        let m = camera.view_proj(1.0);
        for p in corners(lo, hi) {
            let z = m.project_point3(p).z;
            assert!((0.0..=1.0).contains(&z), "corner {p} at depth {z}");
        }
        // Nearer points get smaller depths (depth test `Less`).
        let eye = camera.eye();
        let target = camera.target;
        let near_point = eye.lerp(target, 0.9);
        assert!(m.project_point3(near_point).z < m.project_point3(target).z);
    }

    #[test]
    fn degenerate_boxes_and_viewports_give_finite_matrices() {
        let mut camera = OrbitCamera::default();
        camera.fit(Vec3::splat(3.0), Vec3::splat(3.0));
        assert!((camera.bounds_radius - 1.0).abs() < 1e-6);
        assert_eq!(camera.target, Vec3::splat(3.0));
        camera.fit(Vec3::splat(f32::NAN), Vec3::ONE);
        assert!(camera.eye().is_finite());
        for aspect in [0.0, -1.0, f32::NAN, 1e-6, 1e6] {
            assert!(camera.view_proj(aspect).is_finite(), "aspect {aspect}");
        }
        assert!(camera.vertical_fov(1e-6) < PI);
    }
}
