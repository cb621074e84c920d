//! `?model=URL` (or `?case=URL`): open a mesh or a case from the page's own origin at start. Any other origin is refused,
//! so the page never sends a request beyond loading itself (patient data stays here).

/// A model named in the page's query: its absolute URL and a file name for the format.
#[derive(Debug)]
pub struct ModelUrl {
    pub url: String,
    pub name: String,
}

/// The page's query string (`?a=b&...`, empty without one).
pub fn search() -> String {
    (web_sys::window().and_then(|w| w.location().search().ok())).unwrap_or_default()
}

/// The page's query parameter `name` (the first one), if it has one.
pub fn param(name: &str) -> Option<String> {
    web_sys::UrlSearchParams::new_with_str(&search())
        .ok()?
        .get(name)
}

/// Whether the page is the student's viewer: the viewer's build, or `?mode=viewer` (read once:
/// it holds for the page's life). The viewer's build answers at compile time, so what only the
/// author's page reaches is left out of it.
pub fn is_viewer() -> bool {
    thread_local!(static ASKED: bool = param("mode").as_deref() == Some("viewer"));
    !crate::AUTHORING || ASKED.with(|asked| *asked)
}

/// The viewer's address that opens the case as `link` shows it, where the case came from an
/// address (`?case=`); `None` for a file dropped or handed over.
pub fn viewer_url(link: &crate::view::ViewLink) -> Option<String> {
    let (_, case) = case_param()?;
    let location = web_sys::window()?.location();
    let page = format!("{}{}", location.origin().ok()?, location.pathname().ok()?);
    let case = String::from(js_sys::encode_uri_component(&case));
    let link = link.to_query();
    let sep = if link.is_empty() { "" } else { "&" };
    Some(format!("{page}?mode=viewer&case={case}{sep}{link}"))
}

/// The page's mode as `state()` and the embedding's `ready` event name it.
pub fn mode_name() -> &'static str {
    match is_viewer() {
        true => "viewer",
        false => "author",
    }
}

/// The reader's languages, most wanted first: `?lang=de` (or `de,fr`) where the embedding
/// platform knows the student's, else the browser's.
pub fn languages() -> Vec<String> {
    if let Some(list) = param("lang") {
        let tags = list.split(',').map(str::trim).filter(|t| !t.is_empty());
        return tags.map(str::to_string).collect();
    }
    let Some(window) = web_sys::window() else {
        return Vec::new();
    };
    (window.navigator().languages().iter())
        .filter_map(|tag| tag.as_string())
        .collect()
}

/// The `case` or else the `model` query parameter (its key and value), if there is one.
pub fn case_param() -> Option<(&'static str, String)> {
    (param("case").map(|c| ("case", c))).or_else(|| param("model").map(|m| ("model", m)))
}

/// The `case` or else the `model` query parameter, if there is one; an error when it names
/// another origin.
pub fn model_url() -> Option<Result<ModelUrl, String>> {
    let location = web_sys::window()?.location();
    let (key, wanted) = case_param()?;
    Some(resolve(
        key,
        &wanted,
        &location.href().ok()?,
        &location.origin().ok()?,
    ))
}

fn resolve(key: &str, wanted: &str, page: &str, origin: &str) -> Result<ModelUrl, String> {
    let url = web_sys::Url::new_with_base(wanted, page)
        .map_err(|_| format!("?{key}={wanted} is not a URL"))?;
    if url.origin() != origin {
        return Err(format!(
            "?{key}={wanted} is on another site ({}); only files from this page's own \
             origin ({origin}) are opened, so nothing is requested from elsewhere",
            url.origin()
        ));
    }
    let name = url
        .pathname()
        .rsplit('/')
        .next()
        .filter(|n| !n.is_empty())
        .unwrap_or("model")
        .to_string();
    Ok(ModelUrl {
        url: url.href(),
        name,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test]
    fn only_the_pages_own_origin_is_opened() {
        let page = "http://localhost:8080/app/index.html?model=x";
        let origin = "http://localhost:8080";
        let ok = resolve("model", "models/liver.stl", page, origin).unwrap();
        assert_eq!(ok.url, "http://localhost:8080/app/models/liver.stl");
        assert_eq!(ok.name, "liver.stl");
        let e = resolve("case", "https://example.org/liver.stl", page, origin).unwrap_err();
        assert!(e.contains("another site") && e.starts_with("?case="), "{e}");
        assert!(resolve("model", "//evil.test/a.ply", page, origin).is_err());
    }
}
