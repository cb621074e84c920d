//! Reading a file's bytes in the browser, chunk by chunk, so a large file shows how far the
//! reading got: a local file (the picker or a drop) or a response from the page's own origin.

use js_sys::{Reflect, Uint8Array};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_futures::JsFuture;

/// Wasm32 memory is 4 GiB at most: refuse a larger file early rather than fail inside a copy.
const MAX_BYTES: u64 = u32::MAX as u64;

fn text(e: &JsValue) -> String {
    super::page::js_error_text(e)
}

/// Bytes read so far, and the total when it is known (a file's size, a `Content-Length`).
pub type OnProgress = Box<dyn FnMut(u64, Option<u64>)>;

/// Reads a local file.
pub async fn read_file(file: &web_sys::File, mut progress: OnProgress) -> Result<Vec<u8>, String> {
    let size = file.size();
    if size > MAX_BYTES as f64 {
        return Err(too_large(size as u64));
    }
    let total = Some(size as u64);
    progress(0, total);
    read_stream(&file.stream(), total, progress)
        .await
        .map_err(|e| format!("the browser could not read it: {e}"))
}

/// Fetches `url`'s bytes (same origin, checked by `query::model_url`).
pub async fn fetch(url: &str, mut progress: OnProgress) -> Result<Vec<u8>, String> {
    let window = web_sys::window().ok_or("no window")?;
    if let Some(early) = early_read(url) {
        return read_early(&early, progress).await;
    }
    let response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(|e| format!("cannot fetch it: {}", text(&e)))?
        .dyn_into::<web_sys::Response>()
        .map_err(|_| "the fetch did not give a response")?;
    if !response.ok() {
        return Err(format!("the server answered {}", response.status()));
    }
    // Only for the progress bar: the bytes themselves decide how much is kept.
    let total = response
        .headers()
        .get("content-length")
        .ok()
        .flatten()
        .and_then(|v| v.trim().parse::<u64>().ok());
    progress(0, total);
    let body = response.body().ok_or("the response has no body")?;
    read_stream(&body, total, progress)
        .await
        .map_err(|e| format!("cannot read it: {e}"))
}

/// The reading index.html began for `url` (the page's `?case=` or `?model=`) while the app's
/// module was still loading, taken once: the file downloads beside the app's start.
fn early_read(url: &str) -> Option<JsValue> {
    let early = super::page::take_from_window("meshsmoothEarly").filter(JsValue::is_object)?;
    let same = Reflect::get(&early, &"url".into()).ok()?.as_string()? == url;
    same.then_some(early)
}

/// Waits for index.html's reading (`early`), reporting its progress meanwhile.
async fn read_early(early: &JsValue, progress: OnProgress) -> Result<Vec<u8>, String> {
    let progress = std::rc::Rc::new(std::cell::RefCell::new(progress));
    let number = |key: &str| {
        Reflect::get(early, &key.into())
            .ok()
            .and_then(|v| v.as_f64())
    };
    let report = {
        let progress = progress.clone();
        move |read: f64, total: Option<f64>| {
            if let Ok(mut p) = progress.try_borrow_mut() {
                p(read as u64, total.map(|t| t as u64));
            }
        }
    };
    report(number("read").unwrap_or(0.0), number("total"));
    let hear = wasm_bindgen::closure::Closure::<dyn FnMut(f64, JsValue)>::new({
        let report = report.clone();
        move |read: f64, total: JsValue| report(read, total.as_f64())
    });
    let _ = Reflect::set(early, &"progress".into(), hear.as_ref());
    let bytes = Reflect::get(early, &"bytes".into())
        .ok()
        .and_then(|b| b.dyn_into::<js_sys::Promise>().ok())
        .ok_or("the page's early reading has no bytes")?;
    let outcome = JsFuture::from(bytes).await;
    let _ = Reflect::set(early, &"progress".into(), &JsValue::NULL);
    drop(hear);
    let bytes = outcome
        .map_err(|e| format!("cannot fetch it: {}", text(&e)))?
        .dyn_into::<Uint8Array>()
        .map_err(|_| "the early reading gave something other than bytes".to_string())?;
    report(f64::from(bytes.length()), number("total"));
    Ok(bytes.to_vec())
}

fn too_large(bytes: u64) -> String {
    format!(
        "the file is too large ({:.1} GB) to read in the browser",
        bytes as f64 / 1e9
    )
}

/// Reads `stream` (chunks of bytes) to its end, reporting the bytes read after each chunk.
async fn read_stream(
    stream: &web_sys::ReadableStream,
    total: Option<u64>,
    mut progress: OnProgress,
) -> Result<Vec<u8>, String> {
    let reader: web_sys::ReadableStreamDefaultReader = stream.get_reader().unchecked_into();
    let mut bytes = Vec::new();
    loop {
        let chunk = JsFuture::from(reader.read()).await.map_err(|e| text(&e))?;
        let done = Reflect::get(&chunk, &"done".into())
            .ok()
            .and_then(|d| d.as_bool())
            .unwrap_or(true);
        if done {
            return Ok(bytes);
        }
        let value = Reflect::get(&chunk, &"value".into())
            .map_err(|e| text(&e))?
            .dyn_into::<Uint8Array>()
            .map_err(|_| "the stream gave something other than bytes".to_string())?;
        let end = bytes.len() as u64 + u64::from(value.length());
        if end > MAX_BYTES {
            let _ = reader.cancel();
            return Err(too_large(end));
        }
        let start = bytes.len();
        bytes.resize(end as usize, 0);
        value.copy_to(&mut bytes[start..]);
        progress(end, total);
    }
}
