//! "Export for LMS": the case and this page's own build as a package a learning management
//! system imports, by the writer `meshsmooth case package` uses ([`crate::export::lms`]). The
//! page's files are fetched from its own folder: what its server serves is what `trunk build`
//! wrote, so the package equals the CLI's given that build as `--viewer` and the same case glTF.

use std::collections::BTreeMap;

use crate::case::Case;
use crate::export::lms::{self, LmsFormat, LmsPackage};
use crate::export::CaseGltfOptions;
use crate::session::Session;

/// The case as it stands and its glTF: the one "Write case" wrote when it is current, else
/// written now as `exportCase` writes it by default.
pub fn case_and_glb(session: &Session) -> Result<(Case, Vec<u8>), String> {
    let case = session.case().to_case().ok_or("no case is open")?;
    let bytes = match session.written_case() {
        Some(written) => written.bytes.clone(),
        None => session.case().export_case(&CaseGltfOptions {
            local_error: true,
            ..CaseGltfOptions::default()
        })?,
    };
    Ok((case, bytes))
}

/// The package of `case` (its glTF `glb`) in `format`, with this page's build as its viewer.
pub async fn package(format: LmsFormat, case: Case, glb: Vec<u8>) -> Result<Vec<u8>, String> {
    let viewer = own_build().await?;
    lms::write_package(&LmsPackage {
        format,
        case: &case,
        case_file: ("case.glb", &glb),
        viewer: &viewer,
    })
    .map_err(|e| e.to_string())
}

/// Packages the session's case in `format` and saves the zip, off the frame: the page's own
/// files are fetched first. A failure is logged; the case is untouched either way.
pub fn save(session: &Session, format: LmsFormat) {
    let (case, glb) = match case_and_glb(session) {
        Ok(c) => c,
        Err(e) => {
            log::warn!("Export for LMS: {e}");
            return;
        }
    };
    let name = format!("{}_{}.zip", file_stem(&case), format.name());
    wasm_bindgen_futures::spawn_local(async move {
        let saved = match package(format, case, glb).await {
            Ok(zip) => super::download::save(&name, &zip, "application/zip"),
            Err(e) => Err(e),
        };
        if let Err(e) = saved {
            log::warn!("Export for LMS: {e}");
        }
    });
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

/// This page's build, by file name: the page, its wasm-bindgen glue and module (the hashed
/// names the page links), and the engine workers' script.
async fn own_build() -> Result<BTreeMap<String, Vec<u8>>, String> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let base = document
        .base_uri()
        .ok()
        .flatten()
        .ok_or("no base address")?;
    let linked = |selector: &str| {
        document
            .query_selector(selector)
            .ok()
            .flatten()
            .and_then(|e| e.get_attribute("href"))
            .ok_or_else(|| format!("the page links no {selector}"))
    };
    let glue = linked("link[rel=modulepreload][href$='.js']")?;
    let wasm = linked("link[rel=preload][href$='.wasm']")?;
    let mut files = BTreeMap::new();
    for href in ["index.html", "worker.js", glue.as_str(), wasm.as_str()] {
        let url = web_sys::Url::new_with_base(href, &base)
            .map_err(|_| format!("{href}: not an address"))?;
        let name = url
            .pathname()
            .rsplit('/')
            .next()
            .unwrap_or_default()
            .to_string();
        let bytes = super::read_bytes::fetch(&url.href(), Box::new(|_, _| {}))
            .await
            .map_err(|e| format!("the page's {name}: {e}"))?;
        files.insert(name, bytes);
    }
    Ok(files)
}
