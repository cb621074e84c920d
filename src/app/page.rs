//! The HTML page around the canvas: the loading text, the crash message, the canvas itself.
//! Element ids match `index.html`.

use wasm_bindgen::JsCast;

const CANVAS_ID: &str = "meshsmooth_canvas";
const LOADING_ID: &str = "loading_text";
const CRASH_ID: &str = "crash_message";

fn document() -> Option<web_sys::Document> {
    web_sys::window()?.document()
}

/// The canvas eframe draws on.
pub fn canvas() -> Result<web_sys::HtmlCanvasElement, String> {
    let document = document().ok_or("no document")?;
    document
        .get_element_by_id(CANVAS_ID)
        .ok_or_else(|| format!("the page has no element with id '{CANVAS_ID}'"))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| format!("the element '{CANVAS_ID}' is not a canvas"))
}

pub fn remove_loading_text() {
    if let Some(element) = document().and_then(|d| d.get_element_by_id(LOADING_ID)) {
        element.remove();
    }
}

/// Replaces the page's content with a visible crash message (the canvas is hidden: after a
/// panic eframe stops drawing and the last frame would look alive).
pub fn show_crash_message(message: &str) {
    let Some(document) = document() else {
        return;
    };
    remove_loading_text();
    if let Some(canvas) = document.get_element_by_id(CANVAS_ID) {
        let _ = canvas.set_attribute("hidden", "");
    }
    if let Some(crash) = document.get_element_by_id(CRASH_ID) {
        if let Some(text) = crash.query_selector("pre").ok().flatten() {
            text.set_text_content(Some(message));
        }
        let _ = crash.remove_attribute("hidden");
    }
}

/// Shows every panic on the page. Installed before eframe's hook, which logs the panic to the
/// console and then calls this one.
pub fn install_crash_message_hook() {
    std::panic::set_hook(Box::new(|info| {
        show_crash_message(&format!("meshsmooth crashed: {info}"));
    }));
}

/// True when the page's URL sets the flag `name` in its query: `?name`, `?name=1` or
/// `?name=true` (for example `?wireframe=1`, which screenshots and tests use).
pub fn query_flag(name: &str) -> bool {
    query_has_flag(&super::query::search(), name)
}

fn query_has_flag(search: &str, name: &str) -> bool {
    search
        .trim_start_matches('?')
        .split('&')
        .any(|pair| match pair.split_once('=') {
            Some((key, value)) => key == name && matches!(value, "1" | "true"),
            None => pair == name,
        })
}

/// What index.html's script left on the window under `key` for the app, taken once (the key is
/// removed): work it began before the app's module ran.
pub fn take_from_window(key: &str) -> Option<wasm_bindgen::JsValue> {
    let window = web_sys::window()?;
    let key = wasm_bindgen::JsValue::from_str(key);
    let value = js_sys::Reflect::get(&window, &key).ok()?;
    let _ = js_sys::Reflect::delete_property(&window, &key);
    Some(value)
}

/// Best-effort text of a JavaScript error value.
pub fn js_error_text(value: &wasm_bindgen::JsValue) -> String {
    if let Some(error) = value.dyn_ref::<js_sys::Error>() {
        return String::from(error.message());
    }
    value.as_string().unwrap_or_else(|| format!("{value:?}"))
}

#[cfg(test)]
mod tests {
    use super::query_has_flag;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test]
    fn query_flags_are_read_from_the_search_string() {
        assert!(query_has_flag("?wireframe=1", "wireframe"));
        assert!(query_has_flag("?a=2&wireframe", "wireframe"));
        assert!(query_has_flag("?wireframe=true&b", "wireframe"));
        assert!(!query_has_flag("?wireframe=0", "wireframe"));
        assert!(!query_has_flag("?wireframes=1", "wireframe"));
        assert!(!query_has_flag("", "wireframe"));
    }
}
