//! A structure's names in other languages: given to `case build` as a table or set in the page's
//! session, carried in the case glTF's record (compressed or not), read back by `case info`, and
//! refused, naming what is wrong, from a lying table or file.

use meshsmooth::case::{from_gltf_scene, names::Names};
use meshsmooth::export::CaseGltfOptions;
use meshsmooth::io::load_gltf_scene;
use meshsmooth::session::{Session, StructureChange};
use serde_json::json;

#[path = "common/glb.rs"]
mod glb;

#[path = "common/cli.rs"]
mod common_cli;
mod common_session;
use common_session::smooth_cpu;

fn names(pairs: &[(&str, &str)]) -> Names {
    (pairs.iter())
        .map(|(t, n)| (t.to_string(), n.to_string()))
        .collect()
}

#[test]
fn case_build_takes_a_names_table_and_case_info_reads_them_back() {
    let data = |rel: &str| common_cli::data(rel).display().to_string();
    let (map, table) = (
        data("labelmaps/case_phantom_shared.nii.gz"),
        data("labelmaps/case_phantom_shared_labels.txt"),
    );
    let names_file = common_cli::tmp("phantom_names.json");
    let glb = common_cli::tmp("phantom_names_case.glb");
    let (names_path, glb) = (
        names_file.to_str().expect("utf-8"),
        glb.to_str().expect("utf-8"),
    );
    let build = |table_text: &str, extra: &[&str]| {
        std::fs::write(&names_file, table_text).expect("written");
        let mut args = vec![
            "case", "build", &map, "--colors", &table, "--search", "local",
        ];
        args.extend_from_slice(&["--names", names_path, "-o", glb]);
        args.extend_from_slice(extra);
        common_cli::meshsmooth(&args)
    };
    let given = json!({
        "liver": {"de": "Leber", "FR": "Foie"},
        "right_kidney": {"de": "Rechte Niere", "pt-br": "Rim direito"},
    });
    for extra in [&[][..], &["--uncompressed"]] {
        let out = build(&given.to_string(), extra);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{extra:?}: {stderr}");
        let info = common_cli::json(&common_cli::meshsmooth(&["case", "info", glb, "--json"]));
        let by_name = |name: &str| {
            let list = info["structures"].as_array().expect("structures");
            let s = list.iter().find(|s| s["name"] == name).expect(name);
            serde_json::from_value::<Names>(s["names"].clone()).unwrap_or_default()
        };
        assert_eq!(by_name("liver"), names(&[("de", "Leber"), ("fr", "Foie")]));
        let kidney = names(&[("de", "Rechte Niere"), ("pt-BR", "Rim direito")]);
        assert_eq!(by_name("right_kidney"), kidney);
        assert_eq!(
            by_name("tumor"),
            Names::new(),
            "{extra:?}: no names, none written"
        );
    }

    // A table naming a structure the case lacks, or with a bad tag, stops the build before
    // any work, naming the file and what is wrong; the case written before stays.
    let before = std::fs::read(glb).expect("the case");
    for (text, why) in [
        (
            r#"{"spleen": {"de": "Milz"}}"#,
            "no structure is named 'spleen' in the case",
        ),
        (
            r#"{"liver": {"Leber": "de"}}"#,
            "'liver': 'Leber' is not a language tag",
        ),
        (
            r#"{"liver": {"de": ""}}"#,
            "'liver': the name in 'de' is empty",
        ),
        (r#"["liver"]"#, "not a table of names"),
    ] {
        let out = build(text, &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{text}");
        assert!(
            stderr.contains(&format!("phantom_names.json: {why}")),
            "{text}: {stderr}"
        );
    }
    assert_eq!(std::fs::read(glb).expect("the case"), before);
}

/// The page's session: names set there are checked, travel in the case glTF it writes, and a
/// file whose names were edited into nonsense is refused naming the structure.
#[test]
fn the_session_sets_names_that_travel_and_a_lying_record_is_refused() {
    let mut session = Session::default();
    let bytes = std::fs::read(common_cli::data("labelmaps/case_phantom_shared.seg.nrrd"))
        .expect("the phantom");
    session.begin_open("case_phantom_shared.seg.nrrd", bytes);
    session.poll_opening().expect("done").expect("opens");
    let set = |session: &mut Session, n: Names| {
        let change = StructureChange {
            names: Some(n),
            ..Default::default()
        };
        session.case_mut().set_structure(0, change)
    };
    let error = set(&mut session, names(&[("deutsch", "Leber")])).expect_err("a bad tag");
    assert!(error.contains("'deutsch' is not a language tag"), "{error}");
    assert!(
        session.case().as_case().structures[0].names.is_empty(),
        "kept"
    );
    let version = session.case().case_version();
    set(&mut session, names(&[("DE", " Leber "), ("fr", "Foie")])).expect("set");
    let kept = names(&[("de", "Leber"), ("fr", "Foie")]);
    assert_eq!(session.case().as_case().structures[0].names, kept);
    assert!(
        session.case().case_version() > version,
        "the page redraws its names"
    );
    smooth_cpu(&mut session);
    for compressed in [true, false] {
        let options = CaseGltfOptions {
            compressed,
            ..Default::default()
        };
        let bytes = session.case().export_case(&options).expect("writes");
        let scene = load_gltf_scene(&bytes, "page.glb").expect("reads");
        let case = from_gltf_scene(scene, "page.glb").expect("a case");
        assert_eq!(case.structures[0].names, kept, "compressed: {compressed}");
        assert!(case.structures[1].names.is_empty());

        let (mut doc, bin) = glb::parts(&bytes);
        let nodes = doc["nodes"].as_array_mut().expect("nodes");
        let node = (nodes.iter_mut())
            .find(|n| n["extras"]["meshsmooth"]["names"].is_object())
            .expect("the liver's node");
        node["extras"]["meshsmooth"]["names"] = json!({"de": 7});
        let lie = glb::glb(&doc, &bin);
        let scene = load_gltf_scene(&lie, "lie.glb").expect("reads");
        let error = from_gltf_scene(scene, "lie.glb").expect_err("lying names");
        let error = error.to_string();
        assert!(error.contains("the name in 'de' is not text"), "{error}");
    }
}
