//! "Export for LMS": the case and the student's viewer as a package a learning management
//! system imports, by the writer `meshsmooth case package` uses ([`crate::export::lms`]). The
//! viewer's files are fetched from the `viewer/` folder beside this page: what its server serves
//! is what `trunk build` wrote, so the package equals the CLI's given that folder as `--viewer`
//! and the same case glTF.

use std::collections::BTreeMap;

use crate::case::Case;
use crate::export::lms::{self, LmsFormat, LmsPackage};
use crate::export::CaseGltfOptions;
use crate::session::Session;

/// The case as it stands and its glTF: the one "Write case" wrote when it is current, else
/// written now as `exportCase` writes it by default.
pub fn case_and_glb(session: &Session) -> Result<(Case, Vec<u8>), String> {
    let case = session.case().to_case().ok_or("no case is open")?;
    let bytes = match session.case_export().written() {
        Some(written) => written.bytes.clone(),
        None => session.case().export_case(&CaseGltfOptions {
            local_error: true,
            ..CaseGltfOptions::default()
        })?,
    };
    Ok((case, bytes))
}

/// The package of `case` (its glTF `glb`) in `format`, with the student's viewer.
pub async fn package(format: LmsFormat, case: Case, glb: Vec<u8>) -> Result<Vec<u8>, String> {
    let viewer = viewer_build().await?;
    lms::write_package(&LmsPackage {
        format,
        case: &case,
        case_file: ("case.glb", &glb),
        viewer: &viewer,
    })
    .map_err(|e| e.to_string())
}

/// Packages the session's case in `format` and saves the zip, off the frame: the viewer's
/// files are fetched first. The outcome is kept for the panel ([`outcome`]) and logged; the
/// case is untouched either way.
pub fn save(session: &Session, format: LmsFormat, ctx: &eframe::egui::Context) {
    let (case, glb) = match case_and_glb(session) {
        Ok(c) => c,
        Err(e) => return tell(Err(e), ctx),
    };
    let name = format!("{}_{}.zip", file_stem(&case), format.name());
    set_outcome(Ok(format!("Packing {name}…")));
    let ctx = ctx.clone();
    wasm_bindgen_futures::spawn_local(async move {
        let saved = match package(format, case, glb).await {
            Ok(zip) => super::download::save(&name, &zip, "application/zip"),
            Err(e) => Err(e),
        };
        tell(saved.map(|()| format!("Saved {name}")), &ctx);
    });
}

thread_local! {
    /// What the last Export for LMS came to: under way or saved (`Ok`), or why not.
    static OUTCOME: std::cell::RefCell<Option<Result<String, String>>> = Default::default();
}

fn set_outcome(outcome: Result<String, String>) {
    OUTCOME.with(|o| *o.borrow_mut() = Some(outcome));
}

fn tell(outcome: Result<String, String>, ctx: &eframe::egui::Context) {
    if let Err(e) = &outcome {
        log::warn!("Export for LMS: {e}");
    }
    set_outcome(outcome);
    super::wake(ctx);
}

/// What the last Export for LMS came to, for the Lesson panel to say.
pub fn outcome() -> Option<Result<String, String>> {
    OUTCOME.with(|o| o.borrow().clone())
}

/// The case's title as a file name: letters, digits, `-` and `_`.
fn file_stem(case: &Case) -> String {
    let stem: String = (case.title.trim().chars())
        .map(|c| {
            if c.is_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() {
        "case".into()
    } else {
        stem
    }
}

/// The student's viewer, by file name: its page, the wasm-bindgen glue and module the page
/// links (hashed names), and the engine workers' script, fetched from the `viewer/` folder
/// beside this page, where the web build puts it (`web/build_viewer.sh`).
async fn viewer_build() -> Result<BTreeMap<String, Vec<u8>>, String> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let base = document
        .base_uri()
        .ok()
        .flatten()
        .ok_or("no base address")?;
    let folder = web_sys::Url::new_with_base(VIEWER_FOLDER, &base)
        .map_err(|_| format!("{VIEWER_FOLDER}: not an address"))?
        .href();
    let mut files = BTreeMap::new();
    let (_, page) = fetch_file(&folder, "index.html").await?;
    let text = String::from_utf8_lossy(&page).into_owned();
    files.insert("index.html".to_string(), page);
    let parsed = web_sys::DomParser::new()
        .and_then(|p| p.parse_from_string(&text, web_sys::SupportedType::TextHtml))
        .map_err(|e| super::page::js_error_text(&e))?;
    let linked = |selector: &str| {
        (parsed.query_selector(selector).ok().flatten())
            .and_then(|e| e.get_attribute("href"))
            .ok_or_else(|| format!("the viewer's page links no {selector}"))
    };
    let glue = linked("link[rel=modulepreload][href$='.js']")?;
    let wasm = linked("link[rel=preload][href$='.wasm']")?;
    for href in ["worker.js", glue.as_str(), wasm.as_str()] {
        let (name, bytes) = fetch_file(&folder, href).await?;
        files.insert(name, bytes);
    }
    Ok(files)
}

/// Where the web build puts the student's viewer, beside the app's page.
const VIEWER_FOLDER: &str = "viewer/";

/// The file of the viewer's build that `href` names in `folder` (an absolute address): its
/// name there and its bytes.
async fn fetch_file(folder: &str, href: &str) -> Result<(String, Vec<u8>), String> {
    let url =
        web_sys::Url::new_with_base(href, folder).map_err(|_| format!("{href}: not an address"))?;
    let name = (url.pathname().rsplit('/').next())
        .unwrap_or_default()
        .to_string();
    let bytes = super::read_bytes::fetch(&url.href(), Box::new(|_, _| {}))
        .await
        .map_err(|e| format!("the viewer's {name} ({VIEWER_FOLDER} beside this page): {e}"))?;
    Ok((name, bytes))
}
