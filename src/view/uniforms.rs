//! The record the 3D view's shader reads each frame (`View` in shaders/render.wgsl), and the
//! colours it starts from.
//!
//! Colours are linear RGB in the record: lighting is computed in linear light and encoded for
//! the framebuffer at the end, the way egui's own shader does (see [`OUTPUT_LINEAR`]).

use super::thumbnail::BACKGROUND_SRGBA;
use super::OrbitCamera;
use crate::srgb;
use bytemuck::{Pod, Zeroable};

/// The render shader, as the app loads it; tests/render_shader.rs validates it with naga.
pub const RENDER_SHADER: &str = include_str!("../../shaders/render.wgsl");

/// Flags of [`ViewUniforms::flags`], as in shaders/render.wgsl.
/// Per-vertex colours are bound and replace the base colour.
pub const VERTEX_COLORS: u32 = 1;
/// The framebuffer is sRGB and encodes on write, so the shader writes linear values. Without
/// it (egui's preferred `Rgba8Unorm`/`Bgra8Unorm` framebuffers) the shader encodes to sRGB
/// itself, as egui's `fs_main_gamma_framebuffer` does, so both give the same pixels.
pub const OUTPUT_LINEAR: u32 = 2;

/// A mesh without a colour map: a light, warm, slightly desaturated ivory between bone and
/// soft tissue, which keeps shading readable on a dark background (sRGB).
pub const BASE_COLOR_SRGB: [f32; 3] = [0.86, 0.80, 0.70];
/// Inside surfaces (back faces of open meshes) take on this tint (sRGB), so an opening reads as
/// an opening and not as a hole in the lighting.
pub const BACK_TINT_SRGB: [f32; 3] = [0.62, 0.38, 0.36];
/// How much of [`BACK_TINT_SRGB`] replaces the surface colour on back faces.
pub const BACK_TINT_AMOUNT: f32 = 0.55;
/// Where the key light sits relative to the eye, in units of the eye's distance along the
/// screen's (right, up) axes: up and to the left, the direction shapes are usually lit from, so
/// bumps read as bumps and not as dents.
pub const KEY_LIGHT_OFFSET: [f32; 2] = [-0.35, 0.5];
/// Wireframe lines: dark and partly transparent, so the edges are visible on the lit surface
/// without hiding its shading (sRGB, alpha).
pub const WIRE_COLOR_SRGB: [f32; 4] = [0.08, 0.08, 0.10, 0.6];

/// `View` in shaders/render.wgsl: std140-compatible (four-component members at 16-byte
/// offsets), 192 bytes, a valid uniform block for WebGL2 too.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ViewUniforms {
    /// World to clip space, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// The eye in world space (w = 1): the fill light and the view direction come from there.
    pub eye: [f32; 4],
    /// Unit vector towards the key light (w = 0), fixed to the camera: above and left of the eye.
    pub light: [f32; 4],
    /// Linear RGB of a mesh without colours; alpha 1.
    pub base_color: [f32; 4],
    /// Linear RGB of the back-face tint; alpha = how much of it to mix in.
    pub back_tint: [f32; 4],
    /// Linear RGB and alpha of the wireframe (not premultiplied).
    pub wire_color: [f32; 4],
    /// Linear RGB behind the meshes (alpha 1): the composite lays the view over it.
    pub background: [f32; 4],
    /// A clipping plane `(n, d)`: fragments where `n . p > d` are cut away; `n = 0` cuts
    /// nothing.
    pub clip: [f32; 4],
    pub flags: u32,
    pub _padding: [u32; 3],
}

const _: () = assert!(std::mem::size_of::<ViewUniforms>() == 192);
const _: () = assert!(std::mem::offset_of!(ViewUniforms, flags) == 176);

impl ViewUniforms {
    /// The record for `camera` in a viewport of this aspect ratio (width / height).
    pub fn new(camera: &OrbitCamera, aspect: f32, flags: u32) -> Self {
        let srgb = |c: [f32; 3]| c.map(srgb::to_linear);
        let [r, g, b] = srgb(BASE_COLOR_SRGB);
        let [tr, tg, tb] = srgb(BACK_TINT_SRGB);
        let [wr, wg, wb] = srgb([WIRE_COLOR_SRGB[0], WIRE_COLOR_SRGB[1], WIRE_COLOR_SRGB[2]]);
        let [br, bg, bb] = srgb([0, 1, 2].map(|k| f32::from(BACKGROUND_SRGBA[k]) / 255.0));
        let (right, up) = camera.screen_axes();
        let light = (camera.direction() + KEY_LIGHT_OFFSET[0] * right + KEY_LIGHT_OFFSET[1] * up)
            .normalize();
        Self {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            eye: camera.eye().extend(1.0).to_array(),
            light: light.extend(0.0).to_array(),
            base_color: [r, g, b, 1.0],
            back_tint: [tr, tg, tb, BACK_TINT_AMOUNT],
            wire_color: [wr, wg, wb, WIRE_COLOR_SRGB[3]],
            background: [br, bg, bb, 1.0],
            clip: [0.0; 4],
            flags,
            _padding: [0; 3],
        }
    }

    /// The same record with `srgb` (display colour, each in [0, 1]) as the colour of a mesh
    /// without vertex colours: a case's structure in its own colour.
    pub fn with_base_color(mut self, srgb: [f32; 3]) -> Self {
        let [r, g, b] = srgb.map(srgb::to_linear);
        self.base_color = [r, g, b, 1.0];
        self
    }

    /// The same record drawn with `opacity` (the base colour's alpha, which also scales the
    /// vertex colours' own).
    pub fn with_opacity(mut self, opacity: f32) -> Self {
        self.base_color[3] = opacity.clamp(0.0, 1.0);
        self
    }

    /// The same record cutting away what lies beyond `plane` (`n . p > d`, see
    /// [`ViewUniforms::clip`]).
    pub fn with_clip(mut self, plane: [f32; 4]) -> Self {
        self.clip = plane;
        self
    }

    /// The same record with `flags` set as well.
    pub fn with_flags(mut self, flags: u32) -> Self {
        self.flags |= flags;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_structure_colour_becomes_the_base_colour_in_linear_light() {
        let u = ViewUniforms::new(&OrbitCamera::default(), 1.0, 0).with_base_color([1.0, 0.5, 0.0]);
        assert_eq!(u.base_color[0], 1.0);
        assert!((u.base_color[1] - 0.214).abs() < 1e-3, "{:?}", u.base_color);
        assert_eq!((u.base_color[2], u.base_color[3]), (0.0, 1.0));
        assert_eq!(u.with_flags(VERTEX_COLORS).flags, VERTEX_COLORS);
    }

    #[test]
    fn the_record_carries_the_camera_and_linear_colours() {
        let camera = OrbitCamera::default();
        let u = ViewUniforms::new(&camera, 1.5, VERTEX_COLORS | OUTPUT_LINEAR);
        assert_eq!(u.view_proj, camera.view_proj(1.5).to_cols_array_2d());
        assert_eq!(u.eye[3], 1.0);
        // The key light comes from the eye's side, above it.
        let light = glam::Vec4::from(u.light).truncate();
        assert!((light.length() - 1.0).abs() < 1e-6);
        assert!(light.dot(camera.direction()) > 0.7);
        assert!(light.dot(camera.screen_axes().1) > 0.3);
        assert_eq!(u.flags, 3);
        assert!(u.base_color[0] < BASE_COLOR_SRGB[0] && u.base_color[0] > 0.5);
        assert_eq!(u.wire_color[3], WIRE_COLOR_SRGB[3]);
    }
}
