//! The 3D view: the mesh drawn with wgpu inside egui (a paint callback), lit by lights fixed to
//! the camera, two-sided (front faces only for closed structures no plane cuts), anti-aliased
//! (4x MSAA in its own target, composited into egui's pass), with an optional wireframe; orbit,
//! pan and zoom.
//!
//! Works on WebGPU and on WebGL2. The camera math and the per-frame record are in
//! [`crate::view`].
//!
//! Modules: `pipelines` (surface, wireframe and composite pipelines), `target` (the view's
//! multisampled render target), `buffers` (the model's vertex and index buffers), `context`
//! (a case's other structures around the model), `callback` (the egui-wgpu callback and the
//! resources it draws with), `controls` (input to camera moves).

mod buffers;
mod callback;
mod context;
mod controls;
mod pipelines;
mod slice;
mod target;

pub use context::ContextSurface;

use eframe::egui;
use eframe::egui_wgpu::{self, wgpu};

use std::sync::Arc;

use crate::case::CaseImage;
use crate::view::{
    first_view, CameraPose, Clip, OrbitCamera, Planes, SlicePlacement, SliceTexture, SliceUniforms,
    StandardView, ViewUniforms, OUTPUT_LINEAR, VERTEX_COLORS,
};
use callback::{ViewCallback, ViewResources};
use glam::Vec3;
use pipelines::Pipelines;

/// Bits of the depth buffer eframe gives egui's render pass (`WebOptions::depth_buffer`). The
/// view has its own depth buffer, so none; the composite pipeline matches whatever this is.
pub const EGUI_DEPTH_BUFFER_BITS: u8 = 0;

/// Behind the model: dark and slightly cool, so the warm lit surface stands out.
/// (Thumbnails share it: [`crate::view::thumbnail::BACKGROUND_SRGBA`].)
pub const BACKGROUND: egui::Color32 = {
    let [r, g, b, _] = crate::view::thumbnail::BACKGROUND_SRGBA;
    egui::Color32::from_rgb(r, g, b)
};

/// Where the checks warn (sRGB, with opacity): magenta, which anatomy's colour tables leave
/// to no tissue, seen through whatever lies in front.
pub const MARK_COLOR: [u8; 4] = [255, 0, 220, 200];

/// The 3D view of one model. Its GPU resources live in egui-wgpu's callback resources, so one
/// `Viewer` per app.
pub struct Viewer {
    /// Draw the triangle edges over the surface.
    pub wireframe: bool,
    /// The caller paints with a plain left drag (the brush): orbiting moves to Ctrl/⌘ + left
    /// drag and the middle button.
    pub painting: bool,
    camera: OrbitCamera,
    /// The model framed from its first direction (face-on when flat, else the default), where
    /// [`Self::reset_view`] returns to.
    home: OrbitCamera,
    vertex_count: usize,
    has_colors: bool,
    /// egui's framebuffer is sRGB: the shader writes linear light.
    output_linear: bool,
    /// Why the model is not shown (too large for this GPU, mismatched arrays), if so.
    problem: Option<String>,
    /// The model's colour where it is a case's structure (display sRGB), else the default.
    model_color: Option<[f32; 4]>,
    /// Whether the model is drawn (a case's structure can be hidden).
    show_model: bool,
    /// The model is closed and wound outward (see [`crate::case::CaseStructure::closed_outward`]).
    model_closed: bool,
    /// Other structures are drawn around the model.
    has_context: bool,
    /// The box the home view frames (the whole case): the clipping plane moves across it.
    scene: (Vec3, Vec3),
    /// The clipping plane, cutting every structure; `None` cuts nothing.
    pub clip: Option<Clip>,
    /// The image's three planes, shown (with no clip) where the case has an image.
    pub planes: Option<Planes>,
    /// Which image was last set (its key, remembered even when its texture could not be made,
    /// so a refusal is not retried every frame) and where it lies when shown.
    image: Option<(usize, Option<SlicePlacement>)>,
}

/// The camera, the home view and the scene box, kept across a new model of the same scene.
#[derive(Clone, Copy)]
pub struct ViewState {
    camera: OrbitCamera,
    home: OrbitCamera,
    scene: (Vec3, Vec3),
}

fn box_of(points: &[[f32; 3]]) -> (Vec3, Vec3) {
    crate::mesh::bounding_box(points).map_or((Vec3::ZERO, Vec3::ZERO), |(lo, hi)| {
        (Vec3::from(lo), Vec3::from(hi))
    })
}

impl Viewer {
    pub fn new(render_state: &egui_wgpu::RenderState) -> Self {
        let pipelines = Pipelines::new(
            &render_state.device,
            &render_state.adapter,
            render_state.target_format,
            egui_wgpu::depth_format_from_bits(EGUI_DEPTH_BUFFER_BITS, 0),
        );
        let info = render_state.adapter.get_info();
        log::info!(
            "3D view on {:?} ({:?}), framebuffer {:?}, {}x MSAA",
            info.backend,
            info.name,
            render_state.target_format,
            pipelines.samples
        );
        let resources = ViewResources::new(&render_state.device, pipelines);
        if let Err(e) = resources.warm_up(&render_state.device, &render_state.queue) {
            log::warn!("the view's pipelines were not tried before the first frame: {e}");
        }
        render_state
            .renderer
            .write()
            .callback_resources
            .insert(resources);
        Self {
            wireframe: false,
            painting: false,
            camera: OrbitCamera::default(),
            home: OrbitCamera::default(),
            vertex_count: 0,
            has_colors: false,
            output_linear: render_state.target_format.is_srgb(),
            problem: None,
            model_color: None,
            show_model: true,
            model_closed: false,
            has_context: false,
            scene: (Vec3::ZERO, Vec3::ZERO),
            clip: None,
            planes: None,
            image: None,
        }
    }

    /// The case's image, shown on the clipping plane (`None`: no image). Uploaded when it is
    /// another image than the one shown, reduced to what the GPU takes along each side.
    pub fn set_image(&mut self, rs: &egui_wgpu::RenderState, image: Option<&Arc<CaseImage>>) {
        let key = image.map(|i| Arc::as_ptr(i) as usize);
        if self.image.map(|(k, _)| k) == key {
            return;
        }
        let max_side = rs.device.limits().max_texture_dimension_3d as usize;
        let texture = image.and_then(|i| SliceTexture::new(i, max_side));
        let result = with_resources(rs, |view| {
            view.slice = (texture.as_ref()).map(|t| {
                slice::SliceResources::new(&rs.device, &rs.queue, &view.pipelines.slice_layout, t)
            });
            view.slice_generation += 1;
            Ok(())
        });
        match result {
            Ok(()) => self.image = key.map(|k| (k, texture.map(|t| t.placement))),
            Err(e) => self.fail(e),
        }
    }

    /// How the model is shown as a case's structure: its colour and opacity (`None`: the
    /// default, opaque), whether it is drawn at all, and whether it is closed and wound outward.
    pub fn set_model_look(&mut self, color: Option<[f32; 4]>, visible: bool, closed: bool) {
        self.model_color = color;
        self.show_model = visible;
        self.model_closed = closed;
    }

    /// The case's other structures, drawn around the model (replacing those set before).
    pub fn set_context(&mut self, rs: &egui_wgpu::RenderState, surfaces: &[ContextSurface<'_>]) {
        let result = with_resources(rs, |view| {
            view.context = context::upload_all(&rs.device, &rs.queue, surfaces)?;
            view.context_generation += 1;
            Ok(())
        });
        match result {
            Ok(()) => self.has_context = !surfaces.is_empty(),
            Err(e) => self.fail(e),
        }
    }

    /// New colours for the structures `set_context` gave, in the same order; their surfaces
    /// stay as uploaded.
    pub fn set_context_colors(&mut self, rs: &egui_wgpu::RenderState, colors: &[[u8; 4]]) {
        let result = with_resources(rs, |view| {
            if view.context.len() != colors.len() {
                return Err(format!(
                    "{} colours for {} structures",
                    colors.len(),
                    view.context.len()
                ));
            }
            for (mesh, &color) in view.context.iter_mut().zip(colors) {
                mesh.recolor(&rs.queue, color)?;
            }
            view.context_generation += 1;
            Ok(())
        });
        if let Err(e) = result {
            self.fail(e);
        }
    }

    /// Marks drawn over everything (replacing those set before): where the last checks'
    /// warnings lie.
    pub fn set_marks(&mut self, rs: &egui_wgpu::RenderState, surfaces: &[ContextSurface<'_>]) {
        let result = with_resources(rs, |view| {
            view.marks = context::upload_all(&rs.device, &rs.queue, surfaces)?;
            view.marks_generation += 1;
            Ok(())
        });
        if let Err(e) = result {
            self.fail(e);
        }
    }

    /// Frames every point of `surfaces` (a whole case) and makes that the view's home.
    pub fn frame_all(&mut self, surfaces: &[&[[f32; 3]]]) {
        let points: Vec<[f32; 3]> = surfaces.iter().flat_map(|s| s.iter().copied()).collect();
        if !points.is_empty() {
            self.home = first_view(&points);
            self.scene = box_of(&points);
            self.reset_view();
        }
    }

    /// A new model: uploads triangles and edges, sets positions/normals, no colours, fits the camera.
    pub fn set_mesh(
        &mut self,
        rs: &egui_wgpu::RenderState,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        triangles: &[[u32; 3]],
        edges: &[[u32; 2]],
    ) {
        let result = with_resources(rs, |view| {
            view.mesh
                .set_mesh(&rs.device, &rs.queue, positions, normals, triangles, edges)
        });
        match result {
            Ok(()) => {
                self.vertex_count = positions.len();
                self.has_colors = false;
                self.home = first_view(positions);
                self.scene = box_of(positions);
                self.problem = None;
                self.reset_view();
            }
            Err(e) => self.fail(e),
        }
    }

    /// New positions for the same model (after smoothing on the CPU).
    pub fn set_positions(
        &mut self,
        rs: &egui_wgpu::RenderState,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
    ) {
        let result = with_resources(rs, |view| {
            view.mesh
                .set_positions(&rs.device, &rs.queue, positions, normals)
        });
        if let Err(e) = result {
            self.fail(e);
        }
    }

    /// New positions from buffers on the same device (WebGPU path: the smoothing engine's vec4
    /// position buffer and a vec4 normal buffer), copied GPU-to-GPU with copy_buffer_to_buffer,
    /// no CPU round trip. Both buffers have COPY_SRC usage and hold vertex_count * 16 bytes.
    pub fn copy_positions_from(
        &mut self,
        rs: &egui_wgpu::RenderState,
        positions: &wgpu::Buffer,
        normals: &wgpu::Buffer,
    ) {
        let result = with_resources(rs, |view| {
            view.mesh
                .copy_positions_from(&rs.device, &rs.queue, positions, normals)
        });
        if let Err(e) = result {
            self.fail(e);
        }
    }

    /// Per-vertex colours (RGBA8, sRGB-encoded as a colour map gives them), or None for the base colour.
    pub fn set_colors(&mut self, rs: &egui_wgpu::RenderState, colors: Option<&[[u8; 4]]>) {
        let Some(colors) = colors else {
            // The shader stops reading the colour buffer; nothing to upload.
            self.has_colors = false;
            return;
        };
        match with_resources(rs, |view| view.mesh.set_colors(&rs.queue, colors)) {
            Ok(()) => self.has_colors = self.vertex_count > 0,
            Err(e) => self.fail(e),
        }
    }

    /// Paints into all the space `ui` has left. Left (or middle) drag orbits, shift+left drag
    /// pans, the wheel or a pinch zooms, a double click resets the view. Right drags are not
    /// used here (nor plain left drags while [`Self::painting`]): the caller reads them from
    /// the returned `Response`.
    pub fn show(&mut self, ui: &mut egui::Ui) -> egui::Response {
        let (rect, response) =
            ui.allocate_exact_size(ui.available_size(), egui::Sense::click_and_drag());
        controls::apply(&mut self.camera, ui, &response, self.painting);
        if response.double_clicked_by(egui::PointerButton::Primary) && !self.painting {
            self.reset_view();
        }

        if let Some(problem) = &self.problem {
            ui.painter().rect_filled(rect, 0.0, BACKGROUND);
            centered_note(ui, rect, problem, ui.visuals().error_fg_color);
        } else if rect.width() >= 1.0 && rect.height() >= 1.0 {
            // The composite lays the view over its background: no egui rectangle lies under it,
            // and with nothing to show it shows the background alone.
            let mut flags = 0;
            if self.has_colors {
                flags |= VERTEX_COLORS;
            }
            if self.output_linear {
                flags |= OUTPUT_LINEAR;
            }
            let mut uniforms = ViewUniforms::new(&self.camera, rect.width() / rect.height(), flags);
            if let Some([r, g, b, a]) = self.model_color {
                uniforms = uniforms.with_base_color([r, g, b]).with_opacity(a);
            }
            uniforms = uniforms.with_clip(self.clip_plane());
            let (slices, outlined) = self.slices();
            let callback = ViewCallback {
                rect,
                uniforms,
                wireframe: self.wireframe,
                show_model: self.show_model,
                model_closed: self.model_closed,
                slices,
                outlined,
            };
            ui.painter()
                .add(egui_wgpu::Callback::new_paint_callback(rect, callback));
            if self.vertex_count == 0 && !self.has_context {
                centered_note(ui, rect, "Nothing to show", ui.visuals().weak_text_color());
            }
        }
        response
    }

    /// Where the image's slices lie this frame, and whether the surfaces outline their cut on
    /// the clip's.
    fn slices(&self) -> ([Option<SliceUniforms>; 3], bool) {
        let Some((_, Some(placement))) = self.image else {
            return ([None; 3], false);
        };
        if let Some(planes) = self.planes.filter(|_| self.clip.is_none()) {
            let planes = planes.planes(self.scene.0, self.scene.1);
            return (planes.map(|p| placement.uniforms(p)), false);
        }
        let clipped = self
            .clip
            .and_then(|_| placement.uniforms(self.clip_plane()));
        ([clipped, None, None], clipped.is_some())
    }

    /// The camera, the home view and the scene, to keep across a new model of the same scene.
    pub fn view_state(&self) -> ViewState {
        ViewState {
            camera: self.camera,
            home: self.home,
            scene: self.scene,
        }
    }

    pub fn set_view_state(&mut self, state: ViewState) {
        self.camera = state.camera;
        self.home = state.home;
        self.scene = state.scene;
    }

    /// Looks at the whole scene from one of the standard sides.
    pub fn look_from(&mut self, side: StandardView) {
        self.camera = side.camera(&self.home);
    }

    /// The clipping plane `(n, d)` in the scene as it stands (zero with none).
    pub fn clip_plane(&self) -> [f32; 4] {
        self.clip
            .map_or([0.0; 4], |c| c.plane(self.scene.0, self.scene.1))
    }

    /// Where the camera is, as a link keeps it.
    pub fn pose(&self) -> CameraPose {
        CameraPose::of(&self.camera)
    }

    /// Moves the camera to `pose`.
    pub fn set_pose(&mut self, pose: CameraPose) {
        self.camera = pose.applied_to(&self.camera);
    }

    /// The camera the view is drawn with (for picking).
    pub fn camera(&self) -> &OrbitCamera {
        &self.camera
    }

    /// Frames the whole model as it was first shown (face-on when flat, else from the front-left).
    pub fn reset_view(&mut self) {
        self.camera = self.home;
    }

    /// Records why the model cannot be shown; the view shows the reason instead.
    fn fail(&mut self, problem: String) {
        log::error!("3D view: {problem}");
        self.problem = Some(problem);
    }
}

/// Runs `f` on the view's GPU resources (created by [`Viewer::new`]).
fn with_resources(
    rs: &egui_wgpu::RenderState,
    f: impl FnOnce(&mut ViewResources) -> Result<(), String>,
) -> Result<(), String> {
    let mut renderer = rs.renderer.write();
    match renderer.callback_resources.get_mut::<ViewResources>() {
        Some(view) => f(view),
        None => Err("the 3D view's GPU resources are missing".into()),
    }
}

fn centered_note(ui: &egui::Ui, rect: egui::Rect, text: &str, color: egui::Color32) {
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        text,
        egui::FontId::proportional(16.0),
        color,
    );
}
