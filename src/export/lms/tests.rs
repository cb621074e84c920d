use std::collections::BTreeMap;
use std::io::{Cursor, Read};

use super::*;
use crate::case::{Lesson, Quiz, QuizMode};

fn case(quiz: bool) -> Case {
    Case {
        title: "Liver & <vessels> \"2\"".into(),
        description: String::new(),
        lesson: Lesson {
            quiz: quiz.then(|| Quiz {
                structures: vec![],
                modes: vec![QuizMode::FindIt],
                pass_mark: 0.8,
            }),
            ..Lesson::default()
        },
        ..Case::default()
    }
}

fn viewer() -> BTreeMap<String, Vec<u8>> {
    let mut files = BTreeMap::new();
    files.insert("index.html".into(), b"<html></html>".to_vec());
    files.insert("meshsmooth-1_bg.wasm".into(), vec![0, 97, 115, 109]);
    files
}

fn files(format: LmsFormat, quiz: bool) -> Vec<(String, Vec<u8>)> {
    let case = case(quiz);
    let viewer = viewer();
    package_files(&LmsPackage {
        format,
        case: &case,
        case_file: ("case.glb", b"glTF"),
        viewer: &viewer,
    })
    .unwrap()
}

fn text(files: &[(String, Vec<u8>)], name: &str) -> String {
    let (_, bytes) = files.iter().find(|(p, _)| p == name).unwrap();
    String::from_utf8(bytes.clone()).unwrap()
}

/// The text of the first element named `name` (any namespace).
fn element<'a>(doc: &'a roxmltree::Document, name: &str) -> Option<roxmltree::Node<'a, 'a>> {
    doc.descendants().find(|n| n.tag_name().name() == name)
}

#[test]
fn a_scorm_manifest_lists_every_file_and_launches_the_launch_page() {
    for format in [LmsFormat::Scorm12, LmsFormat::Scorm2004] {
        let files = files(format, true);
        assert_eq!(
            files[0].0, "imsmanifest.xml",
            "{format}: the manifest first"
        );
        let manifest = text(&files, "imsmanifest.xml");
        let doc = roxmltree::Document::parse(&manifest).unwrap();
        let listed: Vec<&str> = (doc.descendants())
            .filter(|n| n.tag_name().name() == "file")
            .filter_map(|n| n.attribute("href"))
            .collect();
        let packed: Vec<&str> = files[1..].iter().map(|(p, _)| p.as_str()).collect();
        assert_eq!(listed, packed, "{format}");
        for path in ["index.html", "launch.json", "case.glb", "viewer/index.html"] {
            assert!(packed.contains(&path), "{format}: {path} packed");
        }
        let resource = element(&doc, "resource").unwrap();
        assert_eq!(resource.attribute("href"), Some("index.html"));
        let sco = (resource.attributes())
            .find(|a| a.name().eq_ignore_ascii_case("scormtype"))
            .map(|a| a.value());
        assert_eq!(sco, Some("sco"), "{format}");
        let organization = element(&doc, "organization").unwrap();
        let title = (organization.children())
            .find(|n| n.tag_name().name() == "title")
            .and_then(|n| n.text());
        assert_eq!(title, Some("Liver & <vessels> \"2\""), "{format}: escaped");
    }
}

#[test]
fn the_pass_mark_becomes_each_standards_mastery() {
    let doc = text(&files(LmsFormat::Scorm12, true), "imsmanifest.xml");
    let doc = roxmltree::Document::parse(&doc).unwrap();
    assert_eq!(element(&doc, "masteryscore").unwrap().text(), Some("80"));
    assert_eq!(element(&doc, "schemaversion").unwrap().text(), Some("1.2"));

    let doc = text(&files(LmsFormat::Scorm2004, true), "imsmanifest.xml");
    let doc = roxmltree::Document::parse(&doc).unwrap();
    assert_eq!(
        element(&doc, "minNormalizedMeasure").unwrap().text(),
        Some("0.8")
    );
    let objective = element(&doc, "primaryObjective").unwrap();
    assert_eq!(objective.attribute("satisfiedByMeasure"), Some("true"));
    assert_eq!(
        element(&doc, "schemaversion").unwrap().text(),
        Some("2004 4th Edition")
    );

    let doc = text(&files(LmsFormat::Cmi5, true), "cmi5.xml");
    let doc = roxmltree::Document::parse(&doc).unwrap();
    let au = element(&doc, "au").unwrap();
    assert_eq!(au.attribute("moveOn"), Some("CompletedOrPassed"));
    assert_eq!(au.attribute("masteryScore"), Some("0.8"));
    assert_eq!(
        au.attribute("id"),
        Some("urn:meshsmooth:case:Liver----vessels---2-")
    );
    assert_eq!(element(&doc, "url").unwrap().text(), Some("index.html"));
}

#[test]
fn without_a_quiz_there_is_no_mastery_and_seeing_it_is_enough() {
    for format in [LmsFormat::Scorm12, LmsFormat::Scorm2004] {
        let manifest = text(&files(format, false), "imsmanifest.xml");
        assert!(!manifest.contains("masteryscore"), "{format}");
        assert!(!manifest.contains("sequencing"), "{format}");
    }
    let doc = text(&files(LmsFormat::Cmi5, false), "cmi5.xml");
    let doc = roxmltree::Document::parse(&doc).unwrap();
    let au = element(&doc, "au").unwrap();
    assert_eq!(au.attribute("moveOn"), Some("Completed"));
    assert_eq!(au.attribute("masteryScore"), None);
}

#[test]
fn the_launch_facts_name_the_format_steps_and_pass_mark() {
    let launch = text(&files(LmsFormat::Cmi5, true), "launch.json");
    let launch: serde_json::Value = serde_json::from_str(&launch).unwrap();
    assert_eq!(launch["format"], "cmi5");
    assert_eq!(launch["steps"], 0);
    assert_eq!(launch["quiz"]["pass_mark"], 0.8);
    assert_eq!(launch["viewer"], "viewer/index.html");
    assert_eq!(launch["case"], "case.glb");
    let launch = text(&files(LmsFormat::Scorm12, false), "launch.json");
    let launch: serde_json::Value = serde_json::from_str(&launch).unwrap();
    assert!(launch["quiz"].is_null());
}

#[test]
fn the_zip_holds_the_files_as_given_and_is_the_same_each_time() {
    let case = case(true);
    let viewer = viewer();
    let package = LmsPackage {
        format: LmsFormat::Scorm2004,
        case: &case,
        case_file: ("case.glb", b"glTF"),
        viewer: &viewer,
    };
    let zip = write_package(&package).unwrap();
    assert_eq!(
        zip,
        write_package(&package).unwrap(),
        "the same bytes again"
    );
    let mut archive = zip::ZipArchive::new(Cursor::new(zip)).unwrap();
    let files = package_files(&package).unwrap();
    assert_eq!(archive.len(), files.len());
    for (i, (path, bytes)) in files.iter().enumerate() {
        let mut entry = archive.by_index(i).unwrap();
        assert_eq!(entry.name().unwrap(), path.as_str());
        let mut read = Vec::new();
        entry.read_to_end(&mut read).unwrap();
        assert_eq!(&read, bytes, "{path}");
    }
}

#[test]
fn a_viewer_without_its_page_or_with_a_path_out_of_the_folder_is_refused() {
    let case = case(false);
    let mut viewer = viewer();
    viewer.remove("index.html");
    let files_of = |viewer: &BTreeMap<String, Vec<u8>>| {
        package_files(&LmsPackage {
            format: LmsFormat::Scorm12,
            case: &case,
            case_file: ("case.glb", b"glTF"),
            viewer,
        })
    };
    assert_eq!(files_of(&viewer).unwrap_err(), PackageError::NoViewer);
    for bad in ["../escape.js", "a//b.js", "c:/x.js", "a\\b.js", "./x.js"] {
        let mut viewer = self::viewer();
        viewer.insert(bad.into(), vec![]);
        assert!(
            matches!(files_of(&viewer), Err(PackageError::BadPath(_))),
            "{bad}"
        );
    }
}

#[test]
fn formats_are_named_as_the_cli_takes_them() {
    for format in LmsFormat::ALL {
        assert_eq!(LmsFormat::from_name(format.name()), Some(format));
    }
    assert_eq!(LmsFormat::from_name("SCORM12"), Some(LmsFormat::Scorm12));
    assert_eq!(LmsFormat::from_name("scorm"), None);
}

#[test]
fn every_file_of_the_launch_runtime_is_packed() {
    let folder = concat!(env!("CARGO_MANIFEST_DIR"), "/web/lms");
    let mut on_disk: Vec<String> = std::fs::read_dir(folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name != "package.json")
        .collect();
    on_disk.sort();
    let mut packed: Vec<String> = LAUNCH_FILES.iter().map(|(n, _)| n.to_string()).collect();
    packed.sort();
    assert_eq!(packed, on_disk, "LAUNCH_FILES names every file of web/lms");
}
