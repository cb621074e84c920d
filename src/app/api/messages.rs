//! The `postMessage` protocol, for a page that embeds this one in an iframe (a learning
//! platform): it calls `window.meshsmooth` by message and hears what happens. Only the origin
//! named in `?parent=ORIGIN` is answered, and only from the embedding window; a message from
//! any other origin is ignored, so no other site can drive the page or read a case from it.
//!
//! - call: `{meshsmooth: "call", id, call, args}`, `call` one of `window.meshsmooth`'s
//!   functions (the viewer's are the reading ones), `args` its arguments as an array;
//! - reply: `{meshsmooth: "reply", id, ok: true, value}` once the call's promise settles, or
//!   `{meshsmooth: "reply", id, ok: false, error}` with the call's message;
//! - events: `{meshsmooth: "event", event, detail}`: `ready` (`{mode, backend, calls}`) once
//!   the page answers; `loaded` (`structures()`) when files handed over are open, or `failed`
//!   (`{error}`); `changed` (`structures()`) when the case changed (a structure shown,
//!   hidden, renamed, selected or smoothed anew) and its results are computed; `step`
//!   (`{step, steps, title, caption, statement}`) when a tour step is shown, `statement` the
//!   xAPI statement a learning record store keeps (verb "experienced", the step as the object;
//!   the actor is the platform's to add); `quizAnswered` (`{structure, mode, given, right, ms,
//!   statement}`, verb "answered", the question a `cmi.interaction` with its right response)
//!   on each answer; `quizFinished` (`{right, questions, score, passed, statement}`, verb
//!   "passed" or "failed", the scaled score) after the last question.

use js_sys::{Array, Function, Object, Promise, Reflect};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_futures::JsFuture;

use super::to_js;
use crate::app::document::Document;
use crate::app::page::js_error_text;

/// The page embedding this one, and what it last heard of the case.
pub struct Embedding {
    parent: String,
    /// What the case was when the parent last heard (see [`case_key`]).
    heard: Option<CaseKey>,
    /// The tour step the parent last heard was shown.
    heard_step: Option<usize>,
    /// How many openings had ended when the parent last heard of one ([`crate::session::Openings::ended`]).
    heard_openings: u64,
}

impl Embedding {
    /// The embedding page named by `?parent=ORIGIN`, if the query names one; an error when it
    /// is not an origin alone.
    pub fn from_query() -> Option<Result<Self, String>> {
        let wanted = crate::app::query::param("parent")?;
        Some(parent_origin(&wanted).map(|parent| Self {
            parent,
            heard: None,
            heard_step: None,
            heard_openings: 0,
        }))
    }

    /// Answers the parent's calls on `api` (`window.meshsmooth`) from now on, and tells it the
    /// page is ready.
    pub fn listen(&self, api: &Object, mode: &str, backend: &str) -> Result<(), String> {
        let window = web_sys::window().ok_or("no window")?;
        let parent = self.parent.clone();
        let calls = Object::keys(api);
        let api = api.clone();
        let listener = Closure::<dyn FnMut(web_sys::MessageEvent)>::new(
            move |event: web_sys::MessageEvent| answer(&api, &parent, &event),
        );
        window
            .add_event_listener_with_callback("message", listener.as_ref().unchecked_ref())
            .map_err(|e| js_error_text(&e))?;
        // It listens as long as the page lives.
        listener.forget();
        let calls: Vec<String> = calls.iter().filter_map(|c| c.as_string()).collect();
        self.post_event(
            "ready",
            &serde_json::json!({"mode": mode, "backend": backend, "calls": calls}),
        );
        Ok(())
    }

    /// Tells the parent what changed since the last frame: files opened, or the case edited.
    pub fn after_frame(&mut self, doc: &mut Document) {
        for (event, detail) in std::mem::take(&mut doc.lesson_events) {
            self.post_event(event, &detail);
        }
        if doc.tour != self.heard_step {
            self.heard_step = doc.tour;
            if let Some(step) = doc.tour {
                self.post_event("step", &doc.step_event(step));
            }
        }
        let openings = doc.session().openings();
        if openings.ended() != self.heard_openings {
            self.heard_openings = openings.ended();
            match openings.last().cloned().unwrap_or(Ok(())) {
                Ok(()) => {
                    self.heard = Some(case_key(doc));
                    self.post_structures("loaded", doc);
                }
                Err(error) => self.post_event("failed", &serde_json::json!({ "error": error })),
            }
            return;
        }
        if doc.session().loading().is_some() || doc.busy() {
            return;
        }
        let key = case_key(doc);
        if self.heard.replace(key).is_some_and(|k| k != key) {
            self.post_structures("changed", doc);
        }
    }

    fn post_structures(&self, event: &str, doc: &Document) {
        let detail = super::json::structures(doc.session().case()).unwrap_or_default();
        self.post_event(event, &detail);
    }

    fn post_event(&self, event: &str, detail: &serde_json::Value) {
        let message = Object::new();
        set(&message, "meshsmooth", &"event".into());
        set(&message, "event", &event.into());
        set(&message, "detail", &to_js(detail));
        post(&self.parent, &message);
    }
}

/// `value` as an origin alone (`https://platform.example:8443`), as `MessageEvent.origin`
/// reads: a path, a query, `*` or an opaque origin are refused.
fn parent_origin(value: &str) -> Result<String, String> {
    let refused = || {
        format!(
            "?parent={value} is not an origin: give the embedding page's scheme, host and \
             port alone, such as https://platform.example"
        )
    };
    let url = web_sys::Url::new(value).map_err(|_| refused())?;
    let origin = url.origin();
    let web = matches!(url.protocol().as_str(), "http:" | "https:");
    if !web || origin == "null" || value.trim_end_matches('/') != origin {
        return Err(refused());
    }
    Ok(origin)
}

/// The session's counters of what the parent's `changed` event follows: the structures'
/// looks and count, which one is open, and the revision of its filter and parameters.
type CaseKey = (u64, Option<usize>, u64);

fn case_key(doc: &Document) -> CaseKey {
    let s = doc.session().case();
    (s.case_version(), s.current_structure(), s.revision())
}

fn set(object: &Object, key: &str, value: &JsValue) {
    // Setting a property on a plain object just made cannot fail.
    let _ = Reflect::set(object, &key.into(), value);
}

fn get(object: &JsValue, key: &str) -> JsValue {
    Reflect::get(object, &key.into()).unwrap_or(JsValue::UNDEFINED)
}

fn post(parent: &str, message: &JsValue) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let target = window.parent().ok().flatten().unwrap_or(window);
    if let Err(e) = target.post_message(message, parent) {
        log::warn!("could not post to {parent}: {}", js_error_text(&e));
    }
}

/// Answers one message: a call from the parent is run and its outcome posted back; anything
/// else is left alone (a message from another origin with a note in the console).
fn answer(api: &Object, parent: &str, event: &web_sys::MessageEvent) {
    let data = event.data();
    if get(&data, "meshsmooth").as_string().as_deref() != Some("call") {
        return;
    }
    let from_parent = web_sys::window()
        .and_then(|w| w.parent().ok().flatten())
        .zip(event.source())
        .is_some_and(|(p, source)| Object::is(&p, &source));
    if event.origin() != parent || !from_parent {
        log::warn!(
            "ignored a meshsmooth call from {}: only the embedding page at {parent} is answered",
            event.origin()
        );
        return;
    }
    let id = get(&data, "id");
    let outcome = call(api, &get(&data, "call"), &get(&data, "args"));
    let parent = parent.to_string();
    wasm_bindgen_futures::spawn_local(async move {
        let settled = match outcome {
            Ok(value) => JsFuture::from(Promise::resolve(&value)).await,
            Err(e) => Err(e),
        };
        let reply = Object::new();
        set(&reply, "meshsmooth", &"reply".into());
        set(&reply, "id", &id);
        set(&reply, "ok", &settled.is_ok().into());
        match settled {
            Ok(value) => set(&reply, "value", &value),
            Err(e) => set(&reply, "error", &js_error_text(&e).into()),
        }
        post(&parent, &reply);
    });
}

/// Runs `api[name](...args)`: its value, or what it threw.
fn call(api: &Object, name: &JsValue, args: &JsValue) -> Result<JsValue, JsValue> {
    let error = |m: String| JsValue::from(js_sys::Error::new(&m));
    let name = name.as_string().unwrap_or_default();
    let known = Object::keys(api).includes(&name.as_str().into(), 0);
    let function = (Reflect::get(api, &name.as_str().into()).ok())
        .filter(|_| known)
        .and_then(|f| f.dyn_into::<Function>().ok())
        .ok_or_else(|| {
            let calls: Vec<String> = Object::keys(api)
                .iter()
                .filter_map(|c| c.as_string())
                .collect();
            error(format!("no call '{name}' here: {}", calls.join(", ")))
        })?;
    let args = if args.is_undefined() || args.is_null() {
        Array::new()
    } else {
        args.clone()
            .dyn_into::<Array>()
            .map_err(|_| error(format!("{name}: args must be an array")))?
    };
    function.apply(api, &args)
}

#[cfg(test)]
mod tests {
    use super::parent_origin;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test]
    fn only_an_origin_alone_names_the_parent() {
        let ok = |v: &str| parent_origin(v).unwrap();
        assert_eq!(ok("https://platform.example"), "https://platform.example");
        assert_eq!(ok("http://127.0.0.1:8081/"), "http://127.0.0.1:8081");
        for bad in [
            "*",
            "null",
            "platform.example",
            "https://platform.example/course",
            "https://platform.example?x=1",
            "file:///home",
            "javascript:alert(1)",
        ] {
            let e = parent_origin(bad).unwrap_err();
            assert!(e.contains("is not an origin"), "{bad}: {e}");
        }
    }
}
