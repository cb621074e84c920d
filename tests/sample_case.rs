//! The bundled sample (`web/sample/abdomen_phantom.glb`, what the pages open at start): what
//! its build script gives from its label map and lesson, and a case with its lesson when opened.

#[path = "common/cli.rs"]
mod common_cli;

use meshsmooth::case::Lesson;
use meshsmooth::session::Session;
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn sample(file: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/web/sample")).join(file)
}

/// Where `a` and `b` differ: numbers beyond a relative `1e-6`, anything else at all.
fn differences(a: &Value, b: &Value, at: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (
                x.as_f64().unwrap_or(f64::NAN),
                y.as_f64().unwrap_or(f64::NAN),
            );
            if (x - y).abs() > 1e-6 * x.abs().max(y.abs()).max(1e-9) {
                out.push(format!("{at}: {x} vs {y}"));
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            for key in x.keys().chain(y.keys().filter(|k| !x.contains_key(*k))) {
                let (u, v) = (x.get(key), y.get(key));
                differences(
                    u.unwrap_or(&Value::Null),
                    v.unwrap_or(&Value::Null),
                    &format!("{at}.{key}"),
                    out,
                );
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (k, (u, v)) in x.iter().zip(y).enumerate() {
                differences(u, v, &format!("{at}[{k}]"), out);
            }
        }
        _ if a != b => out.push(format!("{at}: {a} vs {b}")),
        _ => {}
    }
}

#[test]
fn the_committed_sample_is_what_its_build_script_gives() {
    // The sample's label map is the shared phantom, whose shapes are known exactly.
    let map = std::fs::read(sample("abdomen_phantom.seg.nrrd")).expect("the label map");
    let phantom = common_cli::data("labelmaps/case_phantom_shared.seg.nrrd");
    assert!(map == std::fs::read(phantom).expect("the shared phantom"));
    let fresh = common_cli::tmp("abdomen_phantom.glb");
    let out = Command::new("bash")
        .arg(sample("build.sh"))
        .arg(&fresh)
        .env("MESHSMOOTH", env!("CARGO_BIN_EXE_meshsmooth"))
        .output()
        .expect("bash runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let info = |glb: &PathBuf| {
        let glb = glb.to_str().expect("utf-8");
        common_cli::json(&common_cli::meshsmooth(&["case", "info", glb, "--json"]))
    };
    let (committed, built) = (info(&sample("abdomen_phantom.glb")), info(&fresh));
    let mut found = Vec::new();
    differences(&committed, &built, "case", &mut found);
    assert!(
        found.is_empty(),
        "web/sample/abdomen_phantom.glb is not what web/sample/build.sh gives (run it):\n{}",
        found.join("\n")
    );
    // What the newcomer is shown: every structure smoothed, and the lesson.
    let structures = committed["structures"].as_array().expect("structures");
    let names: Vec<&str> = structures
        .iter()
        .filter_map(|s| s["name"].as_str())
        .collect();
    assert_eq!(names, ["liver", "portal_vein", "tumor", "right_kidney"]);
    assert!(
        structures.iter().all(|s| s["smoothed"] == true),
        "{committed}"
    );
}

/// The page opens the sample as the author's case: its four structures with their colours and
/// smoothing records, and the lesson as its file holds it.
#[test]
fn the_sample_opens_as_a_case_with_its_lesson() {
    let bytes = std::fs::read(sample("abdomen_phantom.glb")).expect("the sample");
    let mut session = Session::default();
    session.open("abdomen_phantom.glb", &bytes).expect("opens");
    let case = session.case();
    assert_eq!(
        case.as_case().names(),
        ["liver", "portal_vein", "tumor", "right_kidney"]
    );
    let lesson: Lesson = serde_json::from_slice(
        &std::fs::read(sample("abdomen_phantom_lesson.json")).expect("the lesson"),
    )
    .expect("a lesson");
    assert_eq!(case.lesson(), &lesson);
    assert_eq!(
        (lesson.steps.len(), lesson.labels.len()),
        (3, 4),
        "a short tour and a label on each structure"
    );
    assert!(lesson.quiz.is_some());
}
