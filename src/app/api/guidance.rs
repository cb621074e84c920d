//! The API's calls on background work: `suggest`, `sweep`, `suggestAll`, `checkStructures`
//! and `gallery`, each a promise settled once its work is done.

use eframe::egui;
use js_sys::Promise;
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsValue;

use super::{from_js, settled, started_work, to_js, when_ready, Api};
use crate::app::document::SharedDocument;
use crate::case::SuggestAllSearch;
use crate::session::Session;
use crate::suggest::SearchMethod;

pub(super) fn define(api: &Api, doc: &SharedDocument, ctx: &egui::Context) -> Result<(), String> {
    api.define("suggest", suggest(doc, ctx))?;
    api.define("sweep", sweep(doc, ctx))?;
    api.define("suggestAll", suggest_all(doc, ctx))?;
    api.define("checkStructures", check_structures(doc, ctx))?;
    api.define("gallery", gallery(doc, ctx))?;
    Ok(())
}

/// `suggest({tau, search})`: the suggestion for the active filter, once searched.
fn suggest(doc: &SharedDocument, ctx: &egui::Context) -> Closure<dyn FnMut(JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move |options: JsValue| match start_suggest(&d, &options) {
        Ok((tau, method)) => when_ready(
            &d,
            &c,
            |s| !s.background().suggesting(),
            move |s| match s.background().suggestion() {
                Some(x) if x.suggestion.tau == tau && x.suggestion.search == method => {
                    Ok(to_js(&x.suggestion.to_json(x.elapsed_ms / 1000.0)))
                }
                _ => Err(s
                    .background()
                    .guidance_problem()
                    .unwrap_or("the suggestion was cancelled or replaced")
                    .to_string()),
            },
        ),
        Err(e) => settled(Err(e)),
    })
}

/// `sweep()`: the quality graphs around the current parameters, once computed.
fn sweep(doc: &SharedDocument, ctx: &egui::Context) -> Closure<dyn FnMut() -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move || {
        if d.borrow().session().case().model().is_none() {
            return settled(Err("no mesh is open: call loadMesh first".into()));
        }
        d.borrow_mut().session_mut().set_graphs_wanted(true);
        when_ready(
            &d,
            &c,
            |s| s.background().graphs_current(),
            |s| {
                super::json::graphs(&s.background())
                    .map(|v| to_js(&v))
                    .ok_or_else(|| "no quality graphs".to_string())
            },
        )
    })
}

/// `suggestAll({tau, search, structures})`: every structure's suggestion (or those of the
/// indices in `structures`), once all are searched.
fn suggest_all(
    doc: &SharedDocument,
    ctx: &egui::Context,
) -> Closure<dyn FnMut(JsValue) -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move |options: JsValue| {
        let started = {
            let mut doc = d.borrow_mut();
            let which = which_structures(&options);
            suggest_all_search(doc.session(), &options).and_then(|(tau, search)| {
                let now = crate::app::document::now_ms();
                let which = which?;
                doc.session_mut()
                    .start_suggest_all(tau, search, which.as_deref(), now)
            })
        };
        started_work(
            &d,
            &c,
            started,
            |s| !s.background().suggesting_all(),
            |s| super::json::suggest_all(&s.background(), crate::app::document::now_ms()),
        )
    })
}

/// `checkStructures()`: the checks between the structures as they stand.
fn check_structures(doc: &SharedDocument, ctx: &egui::Context) -> Closure<dyn FnMut() -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move || {
        let started = d.borrow_mut().session_mut().start_checks();
        started_work(
            &d,
            &c,
            started,
            |s| !s.background().checking(),
            |s| Some(super::json::checks(&s.background())),
        )
    })
}

/// `gallery()`: the gallery of the active filter, shown, once made.
fn gallery(doc: &SharedDocument, ctx: &egui::Context) -> Closure<dyn FnMut() -> Promise> {
    let (d, c) = (doc.clone(), ctx.clone());
    Closure::new(move || {
        {
            let mut doc = d.borrow_mut();
            if doc.session().case().model().is_none() {
                return settled(Err("no mesh is open: call loadMesh first".into()));
            }
            doc.session_mut().start_gallery();
            doc.show_gallery = true;
        }
        when_ready(
            &d,
            &c,
            |s| !s.background().making_gallery(),
            |s| {
                if s.background().gallery().is_empty() {
                    return Err(s
                        .background()
                        .guidance_problem()
                        .unwrap_or("the gallery was cancelled")
                        .to_string());
                }
                Ok(to_js(&super::json::guidance(&s.background())["gallery"]))
            },
        )
    })
}

/// `suggest({tau, search})`: sets tau (default: the current one) and starts the search
/// (default: grid, as the CLI); returns what the answer must match.
fn start_suggest(doc: &SharedDocument, options: &JsValue) -> Result<(f64, SearchMethod), String> {
    let mut doc = doc.borrow_mut();
    let session = doc.session_mut();
    let (tau, search) = tau_and_search(session, options, "suggest")?;
    let method = match search.as_deref() {
        None => SearchMethod::Grid,
        Some("learned") => {
            return Err("suggest: the learned search is Suggest all's: use grid or local".into())
        }
        Some(name) => SearchMethod::from_name(name)
            .ok_or_else(|| format!("suggest: unknown search {name}: use grid or local"))?,
    };
    session.case_mut().set_tau(tau)?;
    session.start_suggest(method);
    Ok((tau, method))
}

/// `{tau, search}` of `suggest` and `suggestAll` (tau: the session's, search: grid by default).
/// The `structures` option: indices into the case, or `None` (absent: every structure).
fn which_structures(options: &JsValue) -> Result<Option<Vec<usize>>, String> {
    if options.is_undefined() || options.is_null() {
        return Ok(None);
    }
    let bad =
        |v: &serde_json::Value| format!("suggestAll: structures {v} must be a list of indices");
    match from_js(options)?.get("structures") {
        None | Some(serde_json::Value::Null) => Ok(None),
        Some(serde_json::Value::Array(list)) => (list.iter())
            .map(|v| v.as_u64().map(|i| i as usize).ok_or_else(|| bad(v)))
            .collect::<Result<Vec<_>, _>>()
            .map(Some),
        Some(v) => Err(bad(v)),
    }
}

/// `{tau, search}` of `suggest` and `suggestAll`: tau (default: the session's) and the search's
/// name, if given.
fn tau_and_search(
    session: &Session,
    options: &JsValue,
    what: &str,
) -> Result<(f64, Option<String>), String> {
    let options = if options.is_undefined() || options.is_null() {
        serde_json::json!({})
    } else {
        from_js(options)?
    };
    if session.case().model().is_none() {
        return Err("no mesh is open: call loadMesh first".into());
    }
    let tau = match options.get("tau") {
        None | Some(serde_json::Value::Null) => session.case().tau(),
        Some(v) => v
            .as_f64()
            .ok_or_else(|| format!("{what}: tau must be a number in [0, 1], got {v}"))?,
    };
    let search = match options.get("search") {
        None | Some(serde_json::Value::Null) => None,
        Some(serde_json::Value::String(name)) => Some(name.clone()),
        Some(v) => return Err(format!("{what}: search must be a name, got {v}")),
    };
    Ok((tau, search))
}

/// `{tau, search}` of `suggestAll`: the search by default is Suggest all's, as in `case build`.
fn suggest_all_search(
    session: &Session,
    options: &JsValue,
) -> Result<(f64, SuggestAllSearch), String> {
    let (tau, search) = tau_and_search(session, options, "suggestAll")?;
    let search = match search {
        None => SuggestAllSearch::default(),
        Some(name) => SuggestAllSearch::from_name(&name).ok_or_else(|| {
            format!("suggestAll: unknown search {name}: use grid, local or learned")
        })?,
    };
    Ok((tau, search))
}
