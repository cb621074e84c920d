//! A case as a package a learning management system imports: SCORM 1.2, SCORM 2004 (4th
//! edition) or cmi5. One zip holding the manifest (`imsmanifest.xml` or `cmi5.xml`), the launch
//! page and its runtime (`web/lms/`, which talks to the LMS's SCORM API or record store), the
//! student viewer's files under `viewer/`, the case glTF and `launch.json`, the lesson facts
//! the runtime needs before the viewer has opened the case. Every path is relative, so the
//! package plays from whatever folder the LMS serves it.
//!
//! The same bytes for the same inputs (fixed file times and order), so the page's "Export for
//! LMS" and `meshsmooth case package` can be compared.

mod cmi5;
mod scorm;
mod zip_file;

use std::collections::BTreeMap;

use crate::case::{xapi, Case};

/// The standard a package follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LmsFormat {
    Scorm12,
    Scorm2004,
    Cmi5,
}

impl LmsFormat {
    pub const ALL: [LmsFormat; 3] = [LmsFormat::Scorm12, LmsFormat::Scorm2004, LmsFormat::Cmi5];

    /// `scorm12`, `scorm2004` or `cmi5`, as the CLI and the page name it.
    pub fn name(self) -> &'static str {
        match self {
            LmsFormat::Scorm12 => "scorm12",
            LmsFormat::Scorm2004 => "scorm2004",
            LmsFormat::Cmi5 => "cmi5",
        }
    }

    pub fn from_name(name: &str) -> Option<LmsFormat> {
        Self::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(name))
    }
}

impl std::fmt::Display for LmsFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The launch page and its runtime, copied beside the manifest as they are.
/// The launch page and its runtime (`web/lms/`, but for the `package.json` that tells Node its
/// tests read ES modules), copied beside the manifest as they are.
const LAUNCH_FILES: [(&str, &str); 11] = [
    ("index.html", include_str!("../../../web/lms/index.html")),
    ("lms.js", include_str!("../../../web/lms/lms.js")),
    ("cmi5.js", include_str!("../../../web/lms/cmi5.js")),
    ("find_api.js", include_str!("../../../web/lms/find_api.js")),
    ("formats.js", include_str!("../../../web/lms/formats.js")),
    ("notice.js", include_str!("../../../web/lms/notice.js")),
    ("outbox.js", include_str!("../../../web/lms/outbox.js")),
    ("progress.js", include_str!("../../../web/lms/progress.js")),
    (
        "record_store.js",
        include_str!("../../../web/lms/record_store.js"),
    ),
    ("scorm.js", include_str!("../../../web/lms/scorm.js")),
    (
        "viewer_link.js",
        include_str!("../../../web/lms/viewer_link.js"),
    ),
];

/// The folder of the package the viewer's files go in.
pub const VIEWER_FOLDER: &str = "viewer";

/// What goes into a package.
pub struct LmsPackage<'a> {
    pub format: LmsFormat,
    /// Its title, description and lesson name the package and set its pass mark.
    pub case: &'a Case,
    /// The case glTF's file name in the package (`case.glb` or `case.gltf`) and its bytes.
    pub case_file: (&'a str, &'a [u8]),
    /// The student viewer's build (its `index.html`, script, wasm and worker), by path within
    /// the viewer's folder.
    pub viewer: &'a BTreeMap<String, Vec<u8>>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PackageError {
    #[error("the viewer has no index.html: give the folder the viewer's build wrote")]
    NoViewer,
    #[error("{0}: a file in a package needs a relative path of plain names")]
    BadPath(String),
    #[error("cannot write the zip: {0}")]
    Zip(String),
}

/// The package's zip file.
pub fn write_package(package: &LmsPackage) -> Result<Vec<u8>, PackageError> {
    let files = package_files(package)?;
    zip_file::write(&files).map_err(PackageError::Zip)
}

/// Every file of the package, the manifest first, by its path in the package.
pub fn package_files(package: &LmsPackage) -> Result<Vec<(String, Vec<u8>)>, PackageError> {
    if !package.viewer.contains_key("index.html") {
        return Err(PackageError::NoViewer);
    }
    let (case_name, case_bytes) = package.case_file;
    let mut content: Vec<(String, Vec<u8>)> = LAUNCH_FILES
        .iter()
        .map(|(name, text)| (name.to_string(), text.as_bytes().to_vec()))
        .collect();
    let about = About::of(package.case);
    content.push((
        "launch.json".into(),
        launch_json(package, &about).into_bytes(),
    ));
    content.push((case_name.to_string(), case_bytes.to_vec()));
    for (path, bytes) in package.viewer {
        content.push((format!("{VIEWER_FOLDER}/{path}"), bytes.clone()));
    }
    if let Some((bad, _)) = content.iter().find(|(p, _)| !plain_path(p)) {
        return Err(PackageError::BadPath(bad.clone()));
    }
    let listed: Vec<&str> = content.iter().map(|(p, _)| p.as_str()).collect();
    let manifest = match package.format {
        LmsFormat::Scorm12 => ("imsmanifest.xml", scorm::manifest_12(&about, &listed)),
        LmsFormat::Scorm2004 => ("imsmanifest.xml", scorm::manifest_2004(&about, &listed)),
        LmsFormat::Cmi5 => ("cmi5.xml", cmi5::course_structure(&about)),
    };
    let mut files = vec![(manifest.0.to_string(), manifest.1.into_bytes())];
    files.extend(content);
    Ok(files)
}

/// A path of plain names under the package's root: no `..`, no root, no backslash, nothing
/// an unzipping tool would place outside the folder.
fn plain_path(path: &str) -> bool {
    !path.is_empty()
        && !path.contains('\\')
        && path
            .split('/')
            .all(|part| !part.is_empty() && part != "." && part != ".." && !part.contains(':'))
}

/// What a manifest says of the case.
pub(crate) struct About {
    /// The activity the package is (the xAPI statements' objects lie under it).
    pub id: String,
    pub title: String,
    pub description: String,
    /// The quiz's pass mark in [0, 1], if the case has a quiz.
    pub mastery: Option<f32>,
}

impl About {
    fn of(case: &Case) -> Self {
        let title = match case.title.trim() {
            "" => "Anatomy case".to_string(),
            t => t.to_string(),
        };
        let description = match case.description.trim() {
            "" => title.clone(),
            d => d.to_string(),
        };
        Self {
            id: xapi::case_activity(case),
            title,
            description,
            mastery: case
                .lesson
                .quiz
                .as_ref()
                .map(|q| q.pass_mark.clamp(0.0, 1.0)),
        }
    }
}

/// The lesson facts the launch page reads first: which standard to speak, how many tour
/// steps there are (the last one seen completes the lesson) and the quiz's pass mark.
fn launch_json(package: &LmsPackage, about: &About) -> String {
    let lesson = &package.case.lesson;
    let quiz = lesson
        .quiz
        .as_ref()
        .map(|q| serde_json::json!({ "pass_mark": decimal(q.pass_mark) }));
    let launch = serde_json::json!({
        "format": package.format.name(),
        "title": about.title,
        "steps": lesson.steps.len(),
        "quiz": quiz,
        "viewer": format!("{VIEWER_FOLDER}/index.html"),
        "case": package.case_file.0,
    });
    serde_json::to_string_pretty(&launch).unwrap_or_default()
}

/// A pass mark as a short decimal (0.8, not 0.800000011920929).
fn decimal(value: f32) -> f64 {
    (f64::from(value) * 10_000.0).round() / 10_000.0
}

/// `text` with XML's five special characters escaped, for element text and attributes.
pub(crate) fn xml_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters XML 1.0 cannot hold at all.
            c if (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests;
