//! Saving bytes as a file the browser downloads (a Blob URL on a temporary link). Nothing
//! leaves the machine: the Blob lives in this page's memory.

use wasm_bindgen::JsCast;

pub fn save(name: &str, bytes: &[u8], mime: &str) -> Result<(), String> {
    let text = |e: wasm_bindgen::JsValue| super::page::js_error_text(&e);
    let window = web_sys::window().ok_or("no window")?;
    let document = window.document().ok_or("no document")?;
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes).into());
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(mime);
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(text)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(text)?;
    let link = document
        .create_element("a")
        .map_err(text)?
        .dyn_into::<web_sys::HtmlAnchorElement>()
        .map_err(|_| "created element is not a link")?;
    link.set_href(&url);
    link.set_download(name);
    link.click();
    web_sys::Url::revoke_object_url(&url).map_err(text)?;
    Ok(())
}
