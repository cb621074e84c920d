//! `meshsmooth case package`: a case as a SCORM 1.2, SCORM 2004 or cmi5 package, built from a
//! label map as `case build` builds it, or from a case glTF as it is.

#[path = "common/cli.rs"]
mod common_cli;

use std::io::{Cursor, Read};
use std::path::Path;

use common_cli::{data, json, meshsmooth, tmp};

/// A stand-in for the viewer's build folder: a page, a script and a module.
fn viewer_folder() -> std::path::PathBuf {
    let dir = tmp("viewer");
    std::fs::create_dir_all(dir.join("assets")).expect("folder");
    std::fs::write(
        dir.join("index.html"),
        "<!DOCTYPE html><title>viewer</title>",
    )
    .unwrap();
    std::fs::write(dir.join("viewer-1.js"), "export default 1;").unwrap();
    std::fs::write(dir.join("assets").join("viewer-1_bg.wasm"), b"\0asm").unwrap();
    dir
}

fn text(path: &Path) -> &str {
    path.to_str().expect("utf-8")
}

/// The phantom's label map, colours, title and lesson: the options both commands take.
fn phantom_options() -> Vec<String> {
    let lesson = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/phantom_lesson.json");
    [
        text(&data("labelmaps/case_phantom_shared.nii.gz")),
        "--colors",
        text(&data("labelmaps/case_phantom_shared_labels.txt")),
        "--lesson",
        text(&lesson),
        "--title",
        "Abdominal phantom",
        "--search",
        "local",
    ]
    .map(String::from)
    .to_vec()
}

fn run(args: &[String]) -> std::process::Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    meshsmooth(&args)
}

/// The zip's files, by name, in order.
fn unzip(path: &Path) -> Vec<(String, Vec<u8>)> {
    let bytes = std::fs::read(path).expect("package written");
    let mut archive = zip::ZipArchive::new(Cursor::new(bytes)).expect("a zip");
    (0..archive.len())
        .map(|i| {
            let mut entry = archive.by_index(i).expect("entry");
            let mut read = Vec::new();
            entry.read_to_end(&mut read).expect("inflates");
            (entry.name().expect("name").to_string(), read)
        })
        .collect()
}

fn file<'a>(files: &'a [(String, Vec<u8>)], name: &str) -> &'a [u8] {
    let found = files.iter().find(|(n, _)| n == name);
    &found.unwrap_or_else(|| panic!("{name} in the package")).1
}

#[test]
fn a_label_map_is_built_as_case_build_builds_it_then_packaged_with_the_viewer() {
    let viewer = viewer_folder();
    let glb = tmp("phantom_for_package.glb");
    let mut build = vec!["case".to_string(), "build".into()];
    build.extend(phantom_options());
    build.extend(["-o".into(), text(&glb).into()]);
    let built = run(&build);
    assert!(
        built.status.success(),
        "{}",
        String::from_utf8_lossy(&built.stderr)
    );

    for (format, manifest) in [
        ("scorm12", "imsmanifest.xml"),
        ("scorm2004", "imsmanifest.xml"),
        ("cmi5", "cmi5.xml"),
    ] {
        let zip = tmp(&format!("phantom_{format}.zip"));
        let mut args = vec!["case".to_string(), "package".into()];
        args.extend(phantom_options());
        args.extend(
            [
                "--format",
                format,
                "--viewer",
                text(&viewer),
                "-o",
                text(&zip),
                "--json",
            ]
            .map(String::from),
        );
        let out = json(&run(&args));
        assert_eq!(out["format"], format);
        assert_eq!(out["structures"], 4);
        let files = unzip(&zip);
        assert_eq!(files[0].0, manifest, "{format}: the manifest first");
        assert_eq!(
            file(&files, "case.glb"),
            std::fs::read(&glb).unwrap(),
            "{format}: the case as `case build` writes it"
        );
        assert_eq!(file(&files, "viewer/assets/viewer-1_bg.wasm"), b"\0asm");
        let launch: serde_json::Value =
            serde_json::from_slice(file(&files, "launch.json")).expect("JSON");
        assert_eq!(launch["format"], format);
        assert_eq!(launch["title"], "Abdominal phantom");
        assert_eq!(launch["quiz"]["pass_mark"], 0.5);
        assert!(launch["steps"].as_u64().expect("steps") > 0);
        assert!(files.iter().any(|(n, _)| n == "index.html"));
    }
}

#[test]
fn a_case_gltf_is_packaged_as_it_is() {
    let viewer = viewer_folder();
    let glb = tmp("phantom_as_is.glb");
    let mut build = vec!["case".to_string(), "build".into()];
    build.extend(phantom_options());
    build.extend(["-o".into(), text(&glb).into()]);
    assert!(run(&build).status.success());
    let zip = tmp("as_is.zip");
    let out = meshsmooth(&[
        "case",
        "package",
        text(&glb),
        "--format",
        "cmi5",
        "--viewer",
        text(&viewer),
        "-o",
        text(&zip),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files = unzip(&zip);
    assert_eq!(file(&files, "case.glb"), std::fs::read(&glb).unwrap());
    let cmi5 = String::from_utf8(file(&files, "cmi5.xml").to_vec()).unwrap();
    assert!(cmi5.contains("Abdominal phantom"), "{cmi5}");
}

#[test]
fn a_missing_viewer_or_a_wrong_name_is_said_before_any_work() {
    let zip = tmp("never.zip");
    let map = data("labelmaps/case_phantom_shared.nii.gz");
    // What `case package` of the phantom says on its standard error.
    let said = |format: &str, viewer: &Path, out: &Path| {
        let run = meshsmooth(&[
            "case",
            "package",
            text(&map),
            "--format",
            format,
            "--viewer",
            text(viewer),
            "-o",
            text(out),
        ]);
        assert!(!run.status.success());
        String::from_utf8_lossy(&run.stderr).into_owned()
    };
    let missing = said("scorm12", &tmp("no_viewer_here"), &zip);
    assert!(missing.contains("no viewer build here"), "{missing}");
    assert!(!zip.exists());

    let viewer = viewer_folder();
    let wrong = said("scorm", &viewer, &zip);
    assert!(wrong.contains("scorm12, scorm2004, cmi5"), "{wrong}");

    let not_zip = said("cmi5", &viewer, &tmp("course.glb"));
    assert!(
        not_zip.contains("a package is written as .zip"),
        "{not_zip}"
    );

    // The app's build, the student's viewer in its viewer/ folder: that folder is named.
    let app = tmp("app_build");
    std::fs::create_dir_all(app.join("viewer")).unwrap();
    for page in [
        app.join("index.html"),
        app.join("viewer").join("index.html"),
    ] {
        std::fs::write(page, "<!DOCTYPE html><title>meshsmooth</title>").unwrap();
    }
    let app_build = said("cmi5", &app, &zip);
    assert!(app_build.contains("its viewer/ folder"), "{app_build}");
    assert!(!zip.exists());
}
