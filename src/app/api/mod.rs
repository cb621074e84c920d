//! The embedding API, `window.meshsmooth`, for the authoring page and for tests. Installed when
//! the app has started, announced by a `meshsmooth-ready` event on `window`. The viewer
//! (`?mode=viewer`) offers the calls that read a case ([`READING_CALLS`]). An embedding page
//! in another origin makes the same calls by `postMessage` (see `messages`).
//!
//! - `loadMesh(bytes: Uint8Array, name): Promise<info>` (the CLI's `info --json` keys), once the
//!   file is open: a worker opens it (`state().loading` tells the stage), the current model
//!   staying open until then; a later `loadMesh` before it is open replaces it (its promise
//!   rejects). Every file opens as a case: a label map (`.nii`, `.nii.gz`, `.nrrd`,
//!   `.seg.nrrd`, `.mgz`, `.mgh`, DICOM SEG `.dcm`) with its structures extracted, a case glTF with its structures, a surface as
//!   a case of one; the first structure becomes the model
//! - `loadCase(bytes, name): Promise<structures>`: `loadMesh` resolving with `structures()`,
//!   for a case glTF written here (reopened as it was: names, colours, groups, parameters,
//!   smoothed surfaces) or any file above
//! - `addFile(bytes, name): Promise<structures>`: adds the file's structures to the open case
//!   (after a file still opening); the model stays
//! - `addImage(bytes, name, preset): Promise<structures>`: the image the segmentation was drawn
//!   on (NIfTI, NRRD, MGH/MGZ, or a DICOM series as arrays of its slices' bytes and names; on the
//!   voxel grid of every label map the structures came from),
//!   windowed by `preset` (`ct-soft-tissue`, the default, `ct-bone`, `ct-lung`, `ct-brain`,
//!   `mri-auto`), read by a worker; replaces the case's image; rejects with the offset found
//!   when it lies elsewhere, the image the case had staying. `removeImage()` takes it away
//! - `structures()`: `{file, current, title, description, structures: [{label, name, color,
//!   opacity, visible, group, description, names, source, voxels, voxel_size, codes, vertices,
//!   triangles, volume, metrics, shown_as_read}]}` of the open case, or null with nothing open (`metrics`: its last
//!   smoothing's measures, or null; `shown_as_read`: the viewer shows it as its file holds it,
//!   the file holding no smoothing of it; `label`, `voxels`, `voxel_size`: null where it came
//!   from no label map;
//!   `codes`: `{category, type, modifier}` in standard codes, as the case glTF's record, or null;
//!   `names`: its names in other languages by language tag, `{"de": "Leber"}`, maybe empty)
//! - `selectStructure(index): Promise<info>`: opens that structure as the model, as `loadMesh`
//!   (a large one's model is built by a worker first: the promise waits for it); the structure
//!   left keeps its smoothing, one coming back gets its own back
//! - `setStructure({index, name, color, opacity, visible, group, description, names})`: changes
//!   how a structure (by default the model's) is shown, grouped and named (`group` null or ""
//!   ungroups; `names` replaces its names in other languages); throws on a bad value;
//!   `soloStructure(index)` shows that structure alone (again: all of them)
//! - `setFilter(name)`, `setParams(object)` (keys `lambda mu alpha beta passband iterations
//!   max_displacement`); both throw with the engine's message on a bad name or value
//! - `metrics(): Promise<object>` (the CLI's `measure --json` keys), once the current
//!   parameters' result is computed
//! - `exportMesh(format): Promise<Uint8Array>` for `glb stl ply obj`
//! - `suggestAll({tau, search, structures}): Promise<object>`: the suggestion for every
//!   structure (or those whose indices `structures` lists), each
//!   with its own filter and bound, one structure per engine worker, each then smoothed with
//!   it; resolves with `{tau, search, structures: [{name, params, evaluations, metrics}],
//!   done, total, work_done, seconds_left, cancelled}` (`state().suggest_all` is the same
//!   while it runs)
//! - `checkStructures(): Promise<object>`: the checks between the structures as they stand,
//!   the CLI's `case build --json` `checks` (`pairs`, `left_inside`, `new_crossings`) with
//!   `text` (the report's lines), `flagged` (the structures of its warnings, by index),
//!   `marked_vertices` (per structure, how many of its vertices the view marks) and `ms`
//! - `exportCase(format, {simplify, triangle_budget, compressed}): Promise<Uint8Array>`: the
//!   case glTF (`glb`, the default, or `gltf`) of every structure as shown and smoothed (a mesh
//!   alone is a case of one), once the current parameters' result is computed: compressed
//!   unless `compressed` is false, simplified within `simplify` voxel diagonals or to about
//!   `triangle_budget` triangles when given (the file `writeCase` wrote when it is current);
//!   `setCase({title, description})` names the case
//! - `writeCase({simplify, triangle_budget}): Promise<{bytes, triangles}>`: writes the
//!   compressed case glTF a structure per frame, as the page's "Write case" does (its progress
//!   in `state().case_export`), and resolves with its size and triangles
//! - `exportLms(format): Promise<Uint8Array>`: the package for an LMS (`scorm12`, `scorm2004`
//!   or `cmi5`) the Lesson panel's "Export for LMS" saves: the case glTF (`writeCase`'s when
//!   current, else `exportCase`'s), its lesson and the student's viewer (the `viewer/` folder
//!   beside this page), what `meshsmooth case package` writes for that glTF with that folder as
//!   `--viewer`
//! - `suggest({tau, search}): Promise<object>`: sets tau and searches (`grid`, the default, or
//!   `local`) for the active filter; resolves with the CLI's `suggest --json` keys (the
//!   suggestion is shown, not applied)
//! - `gallery(): Promise<array>`: makes the gallery of the active filter and shows it;
//!   resolves with `{tau, params, terms, volume_change}` per picture (`terms.volume_change` is
//!   the size `|V - V0| / V0` the score uses; `volume_change` is signed, negative = shrunk)
//! - `sweep(): Promise<object>`: the quality graphs of the active filter around the current
//!   parameters, the CLI's `sweep --json` keys, once computed
//! - `backend()`: `"webgpu"` or `"cpu"`
//! - `state()`: `{model, vertices, faces, error, filter, params, tau, busy, weights, loading,
//!   open_stages, backend, mode, timings, brush, view, layout, checks, guidance,
//!   case_export}` (`mode`:
//!   `"viewer"` with `?mode=viewer`, else `"author"`) (`loading`: `{name, stage, stages,
//!   doing}` while a file opens, else null; `open_stages`: `[{doing, ms}]`, the latest opening's
//!   stages and their times in the worker; `timings`: the last result's `smooth_ms` and `measure_ms`
//!   of the CPU engine's own work, or `gpu_run_ms` from submitting a GPU run to having its
//!   results back; `weights`: `{painted, locked, min, mean}` of the painted weights, or null;
//!   `brush`: `{on, pick_ms}`, whether the weight brush is on and how long its latest pick took;
//!   `view`: `{x, y, width, height, clip, pointed}`, the 3D view's rectangle in CSS pixels,
//!   its clipping plane (as `setView` takes it, or null) and the name of the structure under
//!   the pointer (or null); `layout`:
//!   `{graphs: [{param, strips: [{x, y, width, height, x0, x1}]}], gallery: [{x, y, width,
//!   height}], structures: [{index, visible, solo, name}], structure_name, structure_filter}`,
//!   where the graphs' plot areas (with the parameter values at their left and right edges),
//!   the gallery's visible cards, the Structures list's rows (their show box, S button and
//!   name), its Name field and its filter field (lists of more than 8) were drawn; `checks`:
//!   the last checks' report with `current` (every structure shows the surface checked:
//!   hiding or selecting one keeps it, smoothing one anew does not), or null; `guidance`:
//!   background work under way, whether the graphs are current, the suggestion and the gallery)
//! - `clearWeights()`: every vertex free again (undoes the weight brush)
//! - `screenshot(): Promise<Uint8Array>`: a PNG of the 3D view as the next frame draws it
//!   (without the view's tools); `setShortcuts(on)`: keys act or not (`?shortcuts=off` at
//!   start), for an embedding page that keeps its own; `state().shortcuts` reads it
//! - `state().view.link`: the viewer's address that opens the case as shown now (camera,
//!   hidden and see-through structures, the selected one, clip, slide), where the case came
//!   from `?case=`; else null
//! - `setView({from, clip})`: looks from a standard side (`"A" "P" "L" "R" "S" "I"`) and sets
//!   the clipping plane that cuts every structure (`{axis: "axial" | "coronal" | "sagittal",
//!   at: 0..1 across the scene, flip}`, or null for none) and `toward_segmentation` (0: the
//!   smoothed surfaces, 1: the segmentation's); `state().view` reads them back
//! - `showStep(index)`: shows the case's tour step (from 0: its structures, clip, slide and
//!   selection at once, the camera flying to its view); `leaveTour()` leaves the tour, the view
//!   staying; `state().tour` is `{step, steps, title, caption, left}` (`step` null outside
//!   the tour, `left` the step it was left at), or null when the case has no tour;
//!   `state().layout.lesson` where its buttons, the quiz's and the labels' switch are;
//!   `state().view.labels` the labels drawn (`[{text, x, y, faded, plate, note, open}]`, their
//!   points on the page, `faded` where a surface lies in front of the point, `plate` the
//!   rectangle of the text, a click on which shows or hides the `note` (in the reader's
//!   language; empty when it has none), `open` while it is shown)
//! - `startQuiz()` starts the case's quiz (again; the tour left, the structures it asks shown):
//!   "Find it" questions are answered by clicking the structure in the view, "Name it" ones
//!   by one of the offered names; `nextQuestion()` moves on once the question is answered;
//!   `endQuiz()` ends it. `state().quiz` is null without a quiz in the case, else `{running,
//!   modes, pass_mark}` and, while it runs, `{question, questions, mode, asked, choices,
//!   answer: {given, right} | null, right, answered, finished, score, passed}` (`question`
//!   null once finished)
//! - `lesson()`, `setLesson(lesson)` and `recordStep({title, caption})` (the authoring page):
//!   the case's lesson as `case build --lesson` reads it; setting one checks it against the
//!   case; recording adds the view as it stands as the tour's last step
//!
//! Every call goes through the same [`crate::session::Session`] the UI edits, so the page shows
//! what the API did and the numbers equal the CLI's for the same mesh and parameters.

mod case;
mod export;
mod files;
mod guidance;
pub(crate) mod json;
mod messages;
mod view;

pub use messages::Embedding;

use super::document::SharedDocument;

use eframe::egui;
use files::{file_call, FileCall};
use js_sys::{Function, Promise};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::{JsCast, JsValue};

const READY_EVENT: &str = "meshsmooth-ready";

fn to_js(value: &serde_json::Value) -> JsValue {
    js_sys::JSON::parse(&value.to_string()).unwrap_or(JsValue::NULL)
}

fn from_js(value: &JsValue) -> Result<serde_json::Value, String> {
    let text = js_sys::JSON::stringify(value)
        .map_err(|e| super::page::js_error_text(&e))?
        .as_string()
        .ok_or("the value cannot be written as JSON")?;
    serde_json::from_str(&text).map_err(|e| e.to_string())
}

fn error(message: &str) -> JsValue {
    js_sys::Error::new(message).into()
}

/// A promise settled with `result`.
fn settled(result: Result<JsValue, String>) -> Promise {
    match result {
        Ok(v) => Promise::resolve(&v),
        Err(e) => Promise::reject(&error(&e)),
    }
}

/// A promise resolved by the document once the current result is there, with `answer` applied
/// to the session.
fn when_current(
    doc: &SharedDocument,
    ctx: &egui::Context,
    answer: impl Fn(&crate::session::Session) -> Result<JsValue, String> + 'static,
) -> Promise {
    if doc.borrow().session().case().model().is_none() {
        return Promise::reject(&error("no mesh is open: call loadMesh first"));
    }
    let doc = doc.clone();
    let ctx = ctx.clone();
    let mut answer = Some(answer);
    Promise::new(&mut |resolve: Function, reject: Function| {
        let Some(answer) = answer.take() else { return };
        doc.borrow_mut().when_current(Box::new(move |session| {
            let _ = match answer(session) {
                Ok(v) => resolve.call1(&JsValue::NULL, &v),
                Err(e) => reject.call1(&JsValue::NULL, &error(&e)),
            };
        }));
        crate::app::wake(&ctx);
    })
}

/// A promise resolved by the document once `ready` holds, with `answer` applied to the session.
fn when_ready(
    doc: &SharedDocument,
    ctx: &egui::Context,
    ready: super::document::Ready,
    answer: impl FnOnce(&crate::session::Session) -> Result<JsValue, String> + 'static,
) -> Promise {
    let doc = doc.clone();
    let ctx = ctx.clone();
    let mut answer = Some(answer);
    Promise::new(&mut |resolve: Function, reject: Function| {
        let Some(answer) = answer.take() else { return };
        doc.borrow_mut().when(
            ready,
            Box::new(move |session| {
                let _ = match answer(session) {
                    Ok(v) => resolve.call1(&JsValue::NULL, &v),
                    Err(e) => reject.call1(&JsValue::NULL, &error(&e)),
                };
            }),
        );
        crate::app::wake(&ctx);
    })
}

/// Work started in the background (`started`), and a promise settled once `ready` holds with
/// the session's `report`, or at once with why it did not start.
fn started_work(
    doc: &SharedDocument,
    ctx: &egui::Context,
    started: Result<(), String>,
    ready: super::document::Ready,
    report: fn(&crate::session::Session) -> Option<serde_json::Value>,
) -> Promise {
    if let Err(e) = started {
        return settled(Err(e));
    }
    crate::app::wake(ctx);
    when_ready(doc, ctx, ready, move |s| {
        report(s)
            .map(|v| to_js(&v))
            .ok_or_else(|| "no report".to_string())
    })
}

/// A function of one argument that edits the session, throwing the engine's message when it
/// refuses, and redraws the page when it accepts.
fn setter(
    doc: &SharedDocument,
    ctx: &egui::Context,
    edit: impl Fn(&mut crate::session::Session, JsValue) -> Result<(), String> + 'static,
) -> Closure<dyn FnMut(JsValue) -> Result<(), JsValue>> {
    let (doc, ctx) = (doc.clone(), ctx.clone());
    Closure::new(move |value: JsValue| {
        let mut doc = doc.borrow_mut();
        edit(doc.session_mut(), value).map_err(|e| error(&e))?;
        doc.step_cpu_engine();
        // With the work in the CPU engine's workers, their reply wakes the page: a frame now
        // would only draw the old surface while the new one is computed.
        if !doc.working_elsewhere() || !doc.busy() {
            crate::app::wake(&ctx);
        }
        Ok(())
    })
}

/// The calls the viewer offers: those that read a case and change only how it is shown.
const READING_CALLS: [&str; 15] = [
    "loadCase",
    "screenshot",
    "structures",
    "selectStructure",
    "setStructure",
    "soloStructure",
    "setView",
    "showStep",
    "leaveTour",
    "startQuiz",
    "nextQuestion",
    "endQuiz",
    "setShortcuts",
    "backend",
    "state",
];

/// `window.meshsmooth` as it is built: in the viewer, only [`READING_CALLS`] are defined.
struct Api {
    object: js_sys::Object,
}

impl Api {
    /// Sets `f` as `object[name]` for the page's lifetime (unless the viewer lacks the call).
    fn define<F: ?Sized + wasm_bindgen::closure::WasmClosure>(
        &self,
        name: &str,
        f: Closure<F>,
    ) -> Result<(), String> {
        if crate::app::query::is_viewer() && !READING_CALLS.contains(&name) {
            return Ok(());
        }
        js_sys::Reflect::set(&self.object, &name.into(), f.as_ref().unchecked_ref())
            .map_err(|e| super::page::js_error_text(&e))?;
        // The API lives as long as the page.
        f.forget();
        Ok(())
    }
}

/// Creates `window.meshsmooth`, fires `meshsmooth-ready` and returns the API.
pub fn install(doc: &SharedDocument, ctx: &egui::Context) -> Result<js_sys::Object, String> {
    let window = web_sys::window().ok_or("no window")?;
    let api = Api {
        object: js_sys::Object::new(),
    };

    // The student's viewer has only the reading calls in its build (crate::AUTHORING).
    if crate::AUTHORING {
        define_authors_files(&api, doc, ctx)?;
    } else {
        api.define(FileCall::Case.name(), file_call(doc, ctx, FileCall::Case))?;
    }
    api.define("setView", view::set_view(doc, ctx))?;
    view::define_screenshot(&api, doc, ctx)?;
    view::define_tour(&api, doc, ctx)?;
    case::define(&api, doc, ctx)?;
    if crate::AUTHORING {
        guidance::define(&api, doc, ctx)?;
        define_smoothing(&api, doc, ctx)?;
        export::define_export(&api, doc, ctx)?;
    }
    define_page(&api, doc)?;

    js_sys::Reflect::set(&window, &"meshsmooth".into(), &api.object)
        .map_err(|e| super::page::js_error_text(&e))?;
    let event = web_sys::Event::new(READY_EVENT).map_err(|e| super::page::js_error_text(&e))?;
    window
        .dispatch_event(&event)
        .map_err(|e| super::page::js_error_text(&e))?;
    Ok(api.object)
}

/// `loadMesh`, `loadCase`, `addFile`, `addImage` and `removeImage`: the author's files.
fn define_authors_files(
    api: &Api,
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Result<(), String> {
    for call in [FileCall::Mesh, FileCall::Case, FileCall::Add] {
        api.define(call.name(), file_call(doc, ctx, call))?;
    }
    api.define("addImage", files::image_call(doc, ctx))?;
    let (d, c) = (doc.clone(), ctx.clone());
    let remove_image = Closure::<dyn FnMut()>::new(move || {
        d.borrow_mut().session_mut().remove_image();
        crate::app::wake(&c);
    });
    api.define("removeImage", remove_image)
}

/// `setFilter`, `setParams`, `metrics` and `clearWeights`: the current structure's smoothing.
fn define_smoothing(api: &Api, doc: &SharedDocument, ctx: &egui::Context) -> Result<(), String> {
    api.define(
        "setFilter",
        setter(doc, ctx, |session, name| {
            session
                .case_mut()
                .set_filter_name(&name.as_string().unwrap_or_default())
        }),
    )?;
    api.define(
        "setParams",
        setter(doc, ctx, |session, values| {
            session.case_mut().set_params_json(&from_js(&values)?)
        }),
    )?;

    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "metrics",
        Closure::<dyn FnMut() -> Promise>::new(move || {
            when_current(&d, &c, |session| {
                json::metrics(session.case())
                    .map(|v| to_js(&v))
                    .ok_or_else(|| "no measures".to_string())
            })
        }),
    )?;

    let (d, c) = (doc.clone(), ctx.clone());
    api.define(
        "clearWeights",
        Closure::<dyn FnMut()>::new(move || {
            d.borrow_mut().session_mut().case_mut().clear_weights();
            crate::app::wake(&c);
        }),
    )
}

/// `backend`, `setShortcuts` and `state`: the page itself.
fn define_page(api: &Api, doc: &SharedDocument) -> Result<(), String> {
    let d = doc.clone();
    api.define(
        "backend",
        Closure::<dyn FnMut() -> JsValue>::new(move || d.borrow().backend().name().into()),
    )?;

    let d = doc.clone();
    api.define(
        "setShortcuts",
        Closure::<dyn FnMut(JsValue) -> Result<(), JsValue>>::new(move |on: JsValue| {
            let on = on
                .as_bool()
                .ok_or_else(|| error("setShortcuts(on): on must be true or false"))?;
            d.borrow_mut().shortcuts = on;
            Ok(())
        }),
    )?;

    let d = doc.clone();
    api.define(
        "state",
        Closure::<dyn FnMut() -> JsValue>::new(move || to_js(&d.borrow().state_json())),
    )
}
