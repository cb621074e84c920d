//! The `eframe::App`: the top bar (Open, Export, view toggles, help), the smoothing panel on the
//! left (filter, parameters, measures, colours), the mesh report on the right, the status bar,
//! and the view in the middle. Owns no algorithm: edits go to the shared document's session.

use super::backend::Backend;
use super::bottom_panel::BottomPanel;
use super::brush::Brush;
use super::case_text::CaseText;
use super::controls::{self, Controls};
use super::document::{now_ms, Document, Opening, SharedDocument};
use super::drag_params::DragParams;
use super::file_input::{Arrived, FileInput, FilesFor};
use super::gpu_engine::{GpuEngine, Sent};
use super::guide::Guide;
use super::labels::LabelPainter;
use super::picture::Picture;
use super::pointing::Pointing;
use super::shortcuts::{self, Action};
use super::structure_list::{StructureAction, StructureList};
use super::viewer::Viewer;
use super::{api, download, page, query, report_view};
use crate::export::ExportFormat;
use crate::session::ColorField;
use crate::smooth::Filter;
use crate::view::{CameraPose, ViewLink};
use crate::worker::NamedFile;
use eframe::egui;
use eframe::egui_wgpu;
use std::cell::RefCell;
use std::rc::Rc;

mod bars;
mod first_paint;
mod frame_work;
mod quiz;
mod reading;
mod sharing;
mod start;
mod tour;
mod view_area;
mod view_sync;

use first_paint::FirstPaint;
use start::{embed, gpu_engine, open_start_model, set_style, start_workers};
use view_sync::Shown;

pub struct Shell {
    doc: SharedDocument,
    files: FileInput,
    controls: Controls,
    guide: Guide,
    /// The quality graphs and the gallery.
    bottom: BottomPanel,
    brush: Brush,
    drag_params: DragParams,
    coloring: Option<ColorField>,
    bake_colors: bool,
    show_original: bool,
    help_open: bool,
    /// The right panel shows the lesson rather than the mesh report.
    lesson_tab: bool,
    /// Why the last export failed.
    export_error: Option<String>,
    /// The WebGPU engine's resources, where the page has WebGPU; it runs while the
    /// document's engine is it ([`engine_of`]).
    gpu: Option<GpuEngine>,
    /// The 3D view and the GPU it draws with; `None` when eframe has no wgpu renderer.
    view: Option<(Viewer, egui_wgpu::RenderState)>,
    /// What the view shows now, so it is re-uploaded only when that changes.
    shown: Shown,
    /// The segmentation the view framed whole (its file and structure count).
    framed_case: Option<(String, usize)>,
    structures: StructureList,
    /// The colouring of the viewer's frame, the student's (the author's is `coloring`).
    reader_coloring: Option<ColorField>,
    /// The viewer's filter of its structure list.
    reading_filter: String,
    /// The structure under the pointer.
    pointing: Pointing,
    labels: LabelPainter,
    /// The page that embeds this one (`?parent=ORIGIN`), told what happens here.
    embedding: Option<api::Embedding>,
    /// A picture of the view asked for.
    picture: Picture,
    /// The view the page's link asks for (or why it does not read), until the case it came
    /// with is open.
    link: Option<Result<ViewLink, String>>,
    /// The link's camera, until the view has framed that case.
    pending_pose: Option<CameraPose>,
    /// The camera on its way to a tour step's view.
    flight: Option<crate::view::Flight>,
    /// "Copy link" was clicked (and is still hovered).
    link_copied: bool,
    /// The case in words for screen readers.
    case_text: CaseText,
    /// Whether the last frame asked for the next at once.
    repainting: bool,
    first_paint: FirstPaint,
}

/// Opens the files that arrived, those that came together as one case (or adds each to it).
fn open_arrived(arrived: Vec<Arrived>, doc: &mut Document) {
    for group in arrived {
        let mut files = Vec::with_capacity(group.files.len());
        for file in group.files {
            match file.bytes {
                Ok(bytes) => files.push(NamedFile {
                    name: file.name,
                    bytes,
                }),
                Err(reason) => {
                    doc.session_mut().fail(&file.name, &reason);
                }
            }
        }
        match group.purpose {
            FilesFor::Add => {
                for f in files {
                    doc.ask_add(&f.name, f.bytes, None);
                }
            }
            // One image: a file, or the slices of a DICOM series chosen together.
            FilesFor::Image(preset) if !files.is_empty() => doc.ask_image(files, preset, None),
            FilesFor::Image(_) => {}
            FilesFor::NewCase if !files.is_empty() => doc.ask_open(files, None),
            FilesFor::NewCase => {}
        }
    }
}

impl Shell {
    pub fn new(cc: &eframe::CreationContext<'_>) -> Self {
        let reading = query::is_viewer();
        let software = cc
            .wgpu_render_state
            .as_ref()
            .is_some_and(|rs| crate::gpu::is_software_adapter(&rs.adapter.get_info()));
        let gpu = gpu_engine(cc, reading, software);
        let backend = if gpu.is_some() {
            Backend::WebGpu
        } else {
            Backend::Cpu
        };
        let doc = Rc::new(RefCell::new(Document::with_backend(backend)));
        start_workers(&doc, reading, &cc.egui_ctx);
        let view = cc.wgpu_render_state.as_ref().map(|rs| {
            let mut viewer = Viewer::new(rs);
            viewer.wireframe = page::query_flag("wireframe");
            (viewer, rs.clone())
        });
        set_style(&cc.egui_ctx, software);
        let files = FileInput::new(&cc.egui_ctx);
        // A file goes to the workers as soon as it is read, not a frame later.
        let weak = Rc::downgrade(&doc);
        files.on_arrival(Box::new(move |arrived| {
            if let Some(Ok(mut doc)) = weak.upgrade().as_ref().map(|d| d.try_borrow_mut()) {
                open_arrived(std::mem::take(arrived), &mut doc);
            }
        }));
        {
            // The viewer shows no guidance: nothing runs for it in the background.
            let mut doc = doc.borrow_mut();
            doc.languages = query::languages();
            doc.session_mut().set_graphs_wanted(!reading);
            doc.session_mut().set_suggest_on_open(!reading);
            doc.session_mut().case_mut().show_as_read(reading);
        }
        doc.borrow_mut().shortcuts = query::param("shortcuts").as_deref() != Some("off");
        // A link's view is of the case it names.
        let link = query::case_param().and(ViewLink::from_query(&query::search()).transpose());
        let fetching = open_start_model(&doc, &files, &cc.egui_ctx);
        let first_paint = FirstPaint::new(fetching, now_ms());
        let embedding = embed(&doc, &cc.egui_ctx);
        Self {
            doc,
            files,
            controls: Controls::default(),
            guide: Guide::default(),
            bottom: BottomPanel::new(),
            brush: Brush::default(),
            drag_params: DragParams::default(),
            coloring: Some(ColorField::LocalError),
            // A student sees the structures' own colours until asking how far they moved.
            reader_coloring: None,
            bake_colors: false,
            show_original: false,
            help_open: false,
            lesson_tab: false,
            export_error: None,
            gpu,
            view,
            shown: Shown::default(),
            framed_case: None,
            structures: StructureList::default(),
            reading_filter: String::new(),
            pointing: Pointing::default(),
            labels: LabelPainter::default(),
            embedding,
            picture: Picture::default(),
            link,
            pending_pose: None,
            flight: None,
            link_copied: false,
            case_text: CaseText::default(),
            repainting: false,
            first_paint,
        }
    }

    /// Whether the file the address names is open (or failed), or waits for a frame to take
    /// it up: nothing is being read, and a worker answered the opening.
    fn start_file_open(&self) -> bool {
        let Ok(doc) = self.doc.try_borrow() else {
            return false;
        };
        let session = doc.session();
        self.files.reading().is_empty()
            && (!session.opening_unanswered() || !session.cpu_engine().threaded())
    }

    /// This frame's engine work: the GPU engine where there is one, else the CPU engine.
    /// Returns whether it uploaded a new model to the GPU (the frame is full then).
    fn compute(&mut self) -> bool {
        let mut doc = self.doc.borrow_mut();
        if let Some(gpu) = engine_of(&mut self.gpu, &doc).filter(|_| crate::AUTHORING) {
            match gpu.step(&mut doc) {
                Ok(sent) => return sent == Sent::Model,
                Err(why) => {
                    doc.fall_back_to_cpu(why);
                    // Its buffers are not needed again.
                    self.gpu = None;
                }
            }
        }
        doc.compute_on_cpu();
        false
    }

    fn receive_files(&mut self, ctx: &egui::Context) {
        self.files.collect_dropped(ctx);
        open_arrived(self.files.take_arrived(), &mut self.doc.borrow_mut());
    }

    /// The file dialog, for files to open as a case, to add to the open one, or an image.
    fn open_picker(&mut self, purpose: FilesFor) {
        if let Err(e) = self.files.open_picker(purpose) {
            self.doc.borrow_mut().session_mut().fail("a file", &e);
        }
    }

    fn export(&mut self, format: ExportFormat) {
        let doc = self.doc.borrow();
        let session = doc.session();
        let Some(model) = session.case().model() else {
            return;
        };
        let colors = self
            .coloring
            .filter(|_| self.bake_colors)
            .and_then(|f| session.case().colors(f))
            .map(|(c, _)| c);
        let stem = model
            .name
            .rsplit_once('.')
            .map_or(model.name.as_str(), |s| s.0);
        let name = format!("{stem}_smoothed.{}", format.extension());
        self.export_error = session
            .case()
            .export(format, colors.as_deref())
            .and_then(|bytes| download::save(&name, &bytes, format.mime()))
            .err();
    }

    fn apply(&mut self, action: Action) {
        match action {
            Action::Open => self.open_picker(FilesFor::NewCase),
            Action::ToggleWireframe => {
                if let Some((viewer, _)) = &mut self.view {
                    viewer.wireframe = !viewer.wireframe;
                }
            }
            Action::ToggleOriginal => self.show_original = !self.show_original,
            Action::ResetView => {
                if let Some((viewer, _)) = &mut self.view {
                    viewer.reset_view();
                }
            }
            Action::NextColoring => {
                let all = ColorField::ALL;
                self.coloring = match self.coloring {
                    None => Some(all[0]),
                    Some(f) => all
                        .iter()
                        .position(|&g| g == f)
                        .and_then(|k| all.get(k + 1))
                        .copied(),
                };
            }
            Action::Filter(k) => self
                .doc
                .borrow_mut()
                .session_mut()
                .case_mut()
                .set_filter(Filter::ALL[k]),
            Action::ExportGlb if crate::AUTHORING => self.export(ExportFormat::Glb),
            Action::ExportGlb => {}
            Action::ToggleHelp => self.help_open = !self.help_open,
            Action::ApplySuggestion => {
                let mut doc = self.doc.borrow_mut();
                if let Some(s) = doc.session().background().suggestion() {
                    let _ = doc.session_mut().case_mut().set_params(s.suggestion.params);
                }
            }
            Action::ToggleGraphs if crate::AUTHORING => {
                let open = !self.bottom.open;
                self.bottom
                    .set_open(open, self.doc.borrow_mut().session_mut());
            }
            Action::ToggleGraphs => {}
            Action::ToggleBrush => self.brush.active = !self.brush.active,
            Action::CancelBackground => {
                let mut doc = self.doc.borrow_mut();
                let session = doc.session_mut();
                session.cancel_suggest();
                session.cancel_gallery();
            }
        }
    }

    fn smoothing_panel(&mut self, ui: &mut egui::Ui) {
        let mut guard = self.doc.borrow_mut();
        let doc = &mut *guard;
        let timings = doc.timings;
        let mut picker = None;
        let (session, panel) = doc.session_and_panel();
        for action in self.structures.show(ui, session, panel) {
            if let Err(e) = structure_action(doc, action, &mut picker) {
                log::warn!("{e}");
            }
        }
        ui.heading("Smoothing");
        self.controls.filter(ui, doc.session_mut().case_mut());
        self.drag_params.panel(ui, doc.session().case().filter());
        ui.separator();
        self.brush.panel(ui, doc.session_mut().case_mut());
        ui.separator();
        ui.heading("Suggest");
        self.guide.show(ui, doc.session_mut());
        ui.separator();
        ui.heading("Measures");
        controls::measures(ui, doc.session().case(), timings);
        ui.separator();
        ui.heading("Colours");
        controls::coloring(ui, &mut self.coloring, doc.session_mut().case_mut());
        drop(guard);
        if let Some(purpose) = picker {
            self.open_picker(purpose);
        }
    }
}

/// Does what the Structures list asked; a file dialog it asks for is left in `picker`.
fn structure_action(
    doc: &mut Document,
    action: StructureAction,
    picker: &mut Option<FilesFor>,
) -> Result<(), String> {
    match action {
        StructureAction::Add => {
            *picker = Some(FilesFor::Add);
            Ok(())
        }
        StructureAction::AddImage(preset) => {
            *picker = Some(FilesFor::Image(preset));
            Ok(())
        }
        StructureAction::RemoveImage => {
            doc.session_mut().remove_image();
            Ok(())
        }
        StructureAction::Select(i) => doc.select(i),
        StructureAction::Change(i, change) => doc.session_mut().case_mut().set_structure(i, change),
        StructureAction::Solo(i) => doc.session_mut().case_mut().solo_structure(i),
        StructureAction::CaseText(title, description) => {
            doc.session_mut()
                .case_mut()
                .set_case_text(Some(&title), Some(&description));
            Ok(())
        }
        StructureAction::SuggestAll => {
            let tau = doc.session().case().tau();
            let search = crate::case::SuggestAllSearch::default();
            let now = crate::app::document::now_ms();
            doc.session_mut().start_suggest_all(tau, search, None, now)
        }
        StructureAction::Check => doc.session_mut().start_checks(),
        StructureAction::CancelSuggestAll => {
            doc.session_mut().cancel_suggest_all();
            Ok(())
        }
        StructureAction::ExportCase(options) => doc.session_mut().case_export_mut().start(options),
        StructureAction::CancelExport => {
            doc.session_mut().case_export_mut().cancel();
            Ok(())
        }
        StructureAction::SaveCase => {
            let file = doc.session().case().case_file();
            let stem = file.split('.').next().filter(|s| !s.is_empty());
            let name = format!("{}_case.glb", stem.unwrap_or("case"));
            match doc.session().case_export().written() {
                Some(w) => download::save(&name, &w.bytes, "model/gltf-binary"),
                None => Err("the case changed since it was written: write it again".into()),
            }
        }
    }
}

impl eframe::App for Shell {
    fn raw_input_hook(&mut self, ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        let open = self.first_paint.waiting() && self.start_file_open();
        self.first_paint
            .before_frame(open, now_ms(), ctx, raw_input);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.receive_files(&ctx);
        self.take_shortcuts(&ctx);
        // The frame a new model arrives in takes it up; uploading it to the GPU takes the next.
        // While a worker opens a file, the open model is worked on as before.
        self.pictures(&ctx);
        let opening = self.doc.borrow_mut().step_loading();
        let opened = opening == Opening::Done && self.doc.borrow().session().loading().is_none();
        if let Some(link) = self.link.take_if(|_| opened) {
            self.take_up_link(link);
        }
        if opening == Opening::Idle {
            self.take_up_step();
        }
        self.fly(&ctx);
        self.step_case_work();
        let arrived = opening == Opening::Done;
        if arrived {
            // A new case shows widgets egui has not seen; it styles them from their last pass,
            // so it would paint twice more to settle. A second pass now settles them in this
            // frame: frames cost a whole canvas on a software GPU.
            ctx.request_discard("a new case's widgets, seen for the first time");
        }
        let uploading = !arrived && self.compute();
        if crate::AUTHORING && !arrived && !uploading {
            self.step_guidance();
        }
        if crate::AUTHORING {
            self.bottom.update(&ctx, &mut self.doc.borrow_mut());
        }
        // The view takes up a new model once the GPU engine has (a frame later); the CPU
        // engine's take-up is a message to a worker, so the view need not wait a frame.
        let on_gpu = self.doc.borrow().backend() == Backend::WebGpu;
        if (opening != Opening::Done || !on_gpu) && !uploading {
            self.sync_view(&ctx);
        }
        self.tell_and_pace(&ctx);

        egui::Panel::top("top_bar").show(ui, |ui| self.top_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        if reading::reads(&self.doc.borrow()) {
            self.reading_panel(ui);
        } else {
            self.authoring_panels(ui);
        }
        egui::CentralPanel::no_frame().show(ui, |ui| self.view(ui));
        shortcuts::help_window(&ctx, &mut self.help_open);

        if ctx.input(|i| !i.raw.hovered_files.is_empty()) {
            drop_hint(&ctx);
        }
    }
}

impl Shell {
    /// The background's guidance steps on, its runs on the GPU engine when it takes them.
    fn step_guidance(&mut self) {
        let mut doc = self.doc.borrow_mut();
        let vertices = (doc.session().case().model()).map_or(0, |m| m.mesh().vertex_count());
        let offload = engine_of(&mut self.gpu, &doc).and_then(|g| g.evaluator(vertices));
        doc.guidance_on_gpu = offload.is_some();
        doc.compute_guidance(offload);
        if let Some(gpu) = engine_of(&mut self.gpu, &doc) {
            gpu.guidance_sent();
            if let Some(why) = gpu.take_evaluator_failure() {
                doc.session_mut().guidance_engine_failed(&why);
            }
        }
    }

    /// The author's panels: smoothing on the left, graphs below, the mesh report on the right.
    fn authoring_panels(&mut self, ui: &mut egui::Ui) {
        egui::Panel::left("smoothing")
            .resizable(true)
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.smoothing_panel(ui));
            });
        if self.bottom.open {
            egui::Panel::bottom("graphs")
                .resizable(true)
                .default_size(330.0)
                .min_size(240.0)
                .show(ui, |ui| {
                    let mut doc = self.doc.borrow_mut();
                    let doc = &mut *doc;
                    {
                        let (session, panel) = doc.session_and_panel();
                        self.bottom.show(ui, session, panel)
                    }
                });
        } else {
            self.doc.borrow_mut().panel = Default::default();
        }
        egui::Panel::right("report")
            .resizable(true)
            .default_size(260.0)
            .show(ui, |ui| {
                let mut doc = self.doc.borrow_mut();
                doc.panel.lesson.clear();
                ui.horizontal(|ui| {
                    ui.selectable_value(&mut self.lesson_tab, false, "Report");
                    let tab = ui.selectable_value(&mut self.lesson_tab, true, "Lesson");
                    doc.panel
                        .lesson
                        .push(("lesson-tab".into(), tab.rect.into()));
                });
                ui.separator();
                egui::ScrollArea::vertical().show(ui, |ui| match doc.session().case().model() {
                    Some(_) if self.lesson_tab => crate::app::lesson_panel::show(ui, &mut doc),
                    Some(model) => report_view::show(ui, model),
                    None => {}
                });
            });
    }
}

/// The GPU engine, while it is the document's engine.
fn engine_of<'a>(gpu: &'a mut Option<GpuEngine>, doc: &Document) -> Option<&'a mut GpuEngine> {
    gpu.as_mut().filter(|_| doc.backend() == Backend::WebGpu)
}

/// Dims the page while a file is dragged over it.
fn drop_hint(ctx: &egui::Context) {
    let painter = ctx.layer_painter(egui::LayerId::new(
        egui::Order::Foreground,
        egui::Id::unique("drop_hint"),
    ));
    let rect = ctx.content_rect();
    painter.rect_filled(rect, 0.0, egui::Color32::from_black_alpha(160));
    painter.text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        "Drop to open",
        egui::FontId::proportional(28.0),
        egui::Color32::WHITE,
    );
}
