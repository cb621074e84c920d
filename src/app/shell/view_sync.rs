//! Bringing the 3D view's buffers up to date with the document each frame: a new model (framed,
//! or keeping the view where it is another structure of the same segmentation), its positions
//! (the original, the CPU result or the GPU engine's buffers), its colours, and the case's other
//! structures with their looks. Each is uploaded only when it changed.

use eframe::egui_wgpu::RenderState;

use super::Shell;
use crate::app::gpu_engine::GpuEngine;
use crate::app::viewer;
use crate::session::{ColorField, Legend, Session};
use crate::view;

/// Where the view's positions come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Positions {
    Original,
    /// The surface the model's structure holds for these parameters (a case file's, a search's).
    Kept,
    /// The CPU engine's result for this revision.
    Cpu(u64),
    /// The GPU engine's buffers after the run for this revision.
    Gpu(u64),
    /// The CPU copy of this revision's result, moved back towards the original by this much
    /// (bits of the f32).
    Toward(u64, u32),
}

/// The state of the view's buffers.
#[derive(Default)]
pub(super) struct Shown {
    pub(super) generation: u64,
    pub(super) positions: Option<Positions>,
    /// Field and result revision of the colours, `None` for plain shading.
    pub(super) colors: Option<(ColorField, u64)>,
    pub(super) legend: Option<Legend>,
    /// The version of the structures' looks and the slide towards the segmentation the other
    /// structures were uploaded for.
    pub(super) looks: Option<(u64, u32)>,
    /// When the looks were last uploaded (the page's clock), and how many of the structures'
    /// new surfaces from "Suggest all" they held.
    pub(super) looks_at_ms: f64,
    pub(super) looks_applied: u64,
    /// The structure singled out (by the quiz) when the colours were last set.
    pub(super) highlight: Option<Option<usize>>,
    /// The checks' marks and the version of the looks shown they were uploaded for.
    pub(super) marks: (Option<u64>, u64),
}

impl Shell {
    /// Brings the view's buffers up to date with the document: a new model, new positions
    /// (the original, the CPU result or the GPU buffers), new colours, the other structures
    /// and the checks' marks.
    pub(super) fn sync_view(&mut self, ctx: &eframe::egui::Context) {
        let looks_every_ms = crate::app::Pacing::of(ctx).looks_every_ms;
        let doc = self.doc.borrow();
        let coloring = self.shown_coloring(&doc);
        let Some((viewer, rs)) = &mut self.view else {
            return;
        };
        let session = doc.session();
        if session.case().model().is_none() {
            return;
        }
        let shown = &mut self.shown;
        if shown.generation != session.case().model_id() || shown.positions.is_none() {
            sync_model(viewer, rs, session, &mut self.framed_case);
            // A link's camera, now that the view frames the case it was made for.
            if let Some(pose) = self.pending_pose.take() {
                viewer.set_pose(pose);
            }
            *shown = Shown {
                generation: session.case().model_id(),
                positions: Some(Positions::Original),
                ..Shown::default()
            };
        }
        let toward = doc.view_asks.toward_segmentation;
        let gpu = (self.gpu.as_ref()).filter(|_| doc.backend() == crate::app::Backend::WebGpu);
        let wanted = wanted_positions(session, gpu, self.show_original, toward, shown.positions);
        if shown.positions != Some(wanted)
            && upload_positions(viewer, rs, session, gpu, wanted, shown.positions, toward)
        {
            shown.positions = Some(wanted);
        }
        // The brush shows what it paints; the weights' colours follow their own changes.
        let colors = if self.brush.active {
            Some((ColorField::Weights, session.case().weights_version()))
        } else {
            (coloring.filter(|_| !self.show_original))
                .zip(session.case().last_result().map(|r| r.revision))
        };
        if shown.colors != colors {
            let computed = colors.and_then(|(field, _)| session.case().colors(field));
            viewer.set_colors(rs, computed.as_ref().map(|(c, _)| c.as_slice()));
            shown.legend = computed.map(|(_, l)| l);
            shown.colors = colors;
        }
        let highlight = doc.quiz_highlight();
        let looks = (session.case().case_version(), toward.to_bits());
        let now = crate::app::document::now_ms();
        if shown.looks != Some(looks) && !holds_looks(shown, session, looks, now, looks_every_ms) {
            upload_looks(viewer, rs, session, (toward, highlight));
            shown.looks = Some(looks);
            shown.looks_at_ms = now;
            shown.looks_applied = session.background().suggest_all_applied();
            shown.highlight = Some(highlight);
        } else if shown.highlight != Some(highlight) {
            // Only the colours change: the surfaces stay where they are on the GPU.
            viewer.set_context_colors(rs, &context_colors(session, highlight));
            set_model_look(viewer, session, highlight);
            shown.highlight = Some(highlight);
        }
        // On the surfaces as shown (which may be held back), not as the case has them.
        let marks = (
            session.background().marks_key(),
            shown.looks.map_or(0, |(version, _)| version),
        );
        if shown.marks != marks {
            upload_marks(viewer, rs, session);
            shown.marks = marks;
        }
    }
}

/// Whether the view keeps the looks it shows although the case has `looks` now: while "Suggest
/// all" runs and every change since the last upload is a structure's new surface from it, the
/// surfaces show in groups, `every_ms` apart. Each upload redraws every structure, which a
/// software GPU pays for with CPU time the workers need; the author's own edits show at once.
fn holds_looks(
    shown: &Shown,
    session: &Session,
    looks: (u64, u32),
    now: f64,
    every_ms: f64,
) -> bool {
    let Some((version, toward)) = shown.looks else {
        return false;
    };
    let background = session.background();
    let applied = background.suggest_all_applied();
    background.suggesting_all()
        && toward == looks.1
        && applied >= shown.looks_applied
        && looks.0.checked_sub(version) == Some(applied - shown.looks_applied)
        && now - shown.looks_at_ms < every_ms
}

/// A new model in the view: framed when it is a new case's first, else where the view was.
fn sync_model(
    viewer: &mut viewer::Viewer,
    rs: &RenderState,
    session: &Session,
    framed_case: &mut Option<(String, usize)>,
) {
    let Some(model) = session.case().model() else {
        return;
    };
    let mesh = model.mesh();
    let normals = crate::mesh::vertex_normals(&mesh.positions, &mesh.triangles);
    let kept_view = viewer.view_state();
    viewer.set_mesh(rs, &mesh.positions, &normals, &mesh.triangles, &model.edges);
    // A segmentation is framed whole once; another of its structures keeps the view.
    let structures = session.case().as_case().structures.as_slice();
    let case =
        (structures.len() > 1).then(|| (session.case().case_file().to_string(), structures.len()));
    match (&case, case == *framed_case) {
        (Some(_), true) => viewer.set_view_state(kept_view),
        (Some(_), false) => {
            let all: Vec<&[[f32; 3]]> = (structures.iter()).map(|s| s.positions()).collect();
            viewer.frame_all(&all);
        }
        (None, _) => {}
    }
    *framed_case = case;
}

/// Where the view's positions should come from now.
fn wanted_positions(
    session: &Session,
    gpu: Option<&GpuEngine>,
    show_original: bool,
    toward: f32,
    shown: Option<Positions>,
) -> Positions {
    let result = session.case().last_result();
    let before_result = if session.case().kept_surface().is_some() {
        Positions::Kept
    } else {
        Positions::Original
    };
    if show_original {
        Positions::Original
    } else if toward > 0.0 {
        result.map_or(Positions::Original, |r| {
            Positions::Toward(r.revision, toward.to_bits())
        })
    } else if let Some(gpu) = gpu {
        // The structure's own surface (a case file's) is shown rather than the engine's
        // recomputation of it; the engine's buffers stay while they are what is shown.
        match gpu.submitted(session.case().model_id()) {
            Some(run)
                if before_result == Positions::Original || shown == Some(Positions::Gpu(run)) =>
            {
                Positions::Gpu(run)
            }
            _ => before_result,
        }
    } else {
        result.map_or(before_result, |r| Positions::Cpu(r.revision))
    }
}

/// Uploads the `wanted` positions (`shown`: those the view has); false while the GPU engine's
/// run is still under way.
fn upload_positions(
    viewer: &mut viewer::Viewer,
    rs: &RenderState,
    session: &Session,
    gpu: Option<&GpuEngine>,
    wanted: Positions,
    shown: Option<Positions>,
    toward: f32,
) -> bool {
    let Some(model) = session.case().model() else {
        return false;
    };
    let mesh = model.mesh();
    let result = session.case().last_result();
    let kept = session.case().kept_surface();
    let mut set = |positions: &[[f32; 3]]| {
        let normals = crate::mesh::vertex_normals(positions, &mesh.triangles);
        viewer.set_positions(rs, positions, &normals);
    };
    match wanted {
        Positions::Original => set(&mesh.positions),
        Positions::Toward(..) => {
            let moved =
                result.and_then(|r| view::toward_original(&mesh.positions, &r.positions, toward));
            if let Some(p) = moved {
                set(&p);
            }
        }
        Positions::Kept => {
            if let Some(p) = kept {
                set(p);
            }
        }
        Positions::Cpu(_) => {
            // The engine recomputing the kept surface finds the same one: the view need not
            // draw it again.
            let unchanged =
                shown == Some(Positions::Kept) && result.map(|r| &r.positions[..]) == kept;
            if let Some(r) = result.filter(|_| !unchanged) {
                set(&r.positions);
            }
        }
        // While a run is under way in the engine's buffers they hold none of its results:
        // copy once it is done.
        Positions::Gpu(_) => match gpu.and_then(|g| g.buffers(session.case().model_id())) {
            Some((positions, normals)) => viewer.copy_positions_from(rs, positions, normals),
            None => return false,
        },
    }
    true
}

/// How much of its opacity a structure keeps while another is singled out.
const FADED: f32 = 0.15;

/// The case's other structures with their looks (drawn back towards the segmentation by
/// `toward`; all but `highlight`, where one is singled out, faded), and the model's look.
fn upload_looks(
    viewer: &mut viewer::Viewer,
    rs: &RenderState,
    session: &Session,
    (toward, highlight): (f32, Option<usize>),
) {
    let others = session.case().other_structures();
    let list = session.case().as_case().structures.as_slice();
    let moved: Vec<Option<Vec<[f32; 3]>>> = (others.iter())
        .map(|o| {
            let original = &list[o.index].original.positions;
            (toward > 0.0)
                .then(|| view::toward_original(original, o.positions, toward))
                .flatten()
        })
        .collect();
    let colors = context_colors(session, highlight);
    let surfaces: Vec<viewer::ContextSurface<'_>> = (others.iter().zip(&moved).zip(colors))
        .map(|((o, moved), color)| viewer::ContextSurface {
            positions: moved.as_deref().unwrap_or(o.positions),
            triangles: o.triangles,
            color,
            closed: o.closed,
        })
        .collect();
    viewer.set_context(rs, &surfaces);
    viewer.set_image(rs, session.case().as_case().image.as_ref());
    set_model_look(viewer, session, highlight);
}

/// A structure's colour, faded where another (`highlight`) is singled out.
fn look(index: usize, mut color: [f32; 4], highlight: Option<usize>) -> [f32; 4] {
    if highlight.is_some_and(|h| h != index) {
        color[3] *= FADED;
    }
    color
}

/// The colours of the case's other structures, in `other_structures`' order.
fn context_colors(session: &Session, highlight: Option<usize>) -> Vec<[u8; 4]> {
    (session.case().other_structures().iter())
        .map(|o| {
            look(o.index, o.color, highlight).map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
        })
        .collect()
}

/// The model's look as a structure of the case.
fn set_model_look(viewer: &mut viewer::Viewer, session: &Session, highlight: Option<usize>) {
    let model = session.case().model_structure();
    let current = session.case().current_structure().unwrap_or_default();
    viewer.set_model_look(
        model.map(|l| look(current, l.color, highlight)),
        model.is_none_or(|l| l.visible),
        model.is_some_and(|l| l.closed_outward()),
    );
}

/// The checks' marks over the structures.
fn upload_marks(viewer: &mut viewer::Viewer, rs: &RenderState, session: &Session) {
    let patches = session.background().marked_surfaces();
    let surfaces: Vec<viewer::ContextSurface<'_>> = (patches.iter())
        .map(|p| viewer::ContextSurface {
            positions: &p.positions,
            triangles: &p.triangles,
            color: viewer::MARK_COLOR,
            closed: false,
        })
        .collect();
    viewer.set_marks(rs, &surfaces);
}
