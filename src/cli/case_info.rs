//! What `meshsmooth case info` and `case build` print of a case: its structures' table and
//! records, its image and lesson in a line each, and the file's own records (`case info`).

use std::path::Path;

use crate::case::{self, Case};

pub(super) fn info(file: &Path, json: bool) -> Result<(), String> {
    let bytes = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let name = file.display().to_string();
    let scene = crate::io::load_gltf_scene(&bytes, &name).map_err(|e| format!("{name}: {e}"))?;
    // What the file states of how it was written, which the case does not hold.
    let written: Vec<serde_json::Value> = (scene.nodes.iter())
        .map(|n| {
            let record = n.extras.as_ref().and_then(|e| e.get(case::CASE_KEY));
            let mut w = serde_json::json!({});
            for key in ["quantization", "simplification"] {
                if let Some(v) = record.and_then(|r| r.get(key)) {
                    w[key] = v.clone();
                }
            }
            w
        })
        .collect();
    let case = case::from_gltf_scene(scene, &name).map_err(|e| format!("{name}: {e}"))?;
    if json {
        let mut out = case_json(&case);
        if let Some(list) = out["structures"].as_array_mut() {
            for (s, w) in list.iter_mut().zip(&written) {
                s["file"] = w.clone();
            }
        }
        outln!("{}", super::to_json(&out)?);
    } else {
        if !case.title.is_empty() {
            outln!("{}", case.title);
        }
        if !case.description.is_empty() {
            outln!("{}", case.description);
        }
        out!("{}", table(&case));
        out!("{}", image_line(&case));
        out!("{}", lesson_line(&case));
        let simplified: Vec<&serde_json::Value> = (written.iter())
            .map(|w| &w["simplification"])
            .filter(|r| r["simplified"] == true)
            .collect();
        if !simplified.is_empty() {
            let count =
                |key: &str| -> u64 { simplified.iter().filter_map(|r| r[key].as_u64()).sum() };
            let worst = (simplified.iter())
                .filter_map(|r| r["max_deviation_voxel_diagonals"].as_f64())
                .fold(0.0, f64::max);
            outln!(
                "{} structures simplified: {} -> {} triangles, at most {worst:.3} voxel diagonals \
                 from the smoothed surfaces",
                simplified.len(),
                count("triangles_before"),
                count("triangles")
            );
        }
    }
    Ok(())
}

/// The case as JSON: title, description and each structure's record with its name.
pub(super) fn case_json(case: &Case) -> serde_json::Value {
    let structures: Vec<_> = case
        .structures
        .iter()
        .map(|s| {
            let mut r = case::structure_record(s);
            r["name"] = serde_json::json!(s.name);
            r
        })
        .collect();
    let image = case.image.as_ref().map(|i| {
        serde_json::json!({
            "source": i.source,
            "dims": i.dims,
            "affine": i.affine.0,
            "preset": i.preset,
            "window": i.window,
            "bytes": i.bytes(),
        })
    });
    serde_json::json!({
        "title": case.title,
        "description": case.description,
        "structures": structures,
        "image": image,
        "lesson": case.lesson,
    })
}

/// What the case's lesson holds, in a line (empty when it has none).
pub(super) fn lesson_line(case: &Case) -> String {
    let lesson = &case.lesson;
    if lesson.is_empty() {
        return String::new();
    }
    let quiz = match &lesson.quiz {
        Some(q) => {
            let modes: Vec<&str> = (q.modes.iter())
                .map(|m| match m {
                    case::QuizMode::FindIt => "find it",
                    case::QuizMode::NameIt => "name it",
                })
                .collect();
            let asked = match q.structures.len() {
                0 => "every structure shown".to_string(),
                n => format!("{n} structures"),
            };
            format!(
                ", a quiz ({}) on {asked}, passed at {:.0}%",
                modes.join(", "),
                q.pass_mark * 100.0
            )
        }
        None => String::new(),
    };
    format!(
        "lesson: {} tour steps, {} labels{quiz}\n",
        lesson.steps.len(),
        lesson.labels.len()
    )
}

/// The image the case carries, in a line (empty when it has none).
pub(super) fn image_line(case: &Case) -> String {
    let Some(i) = &case.image else {
        return String::new();
    };
    format!(
        "image: {}, {} x {} x {} voxels, window {} (centre {}, width {}), {} bytes\n",
        i.source,
        i.dims[0],
        i.dims[1],
        i.dims[2],
        i.preset,
        i.window.center,
        i.window.width,
        i.bytes()
    )
}

pub(super) fn table(case: &Case) -> String {
    let mut out = format!(
        "{:<28} {:<7} {:>5} {:>8} {:>9} {:>16} {:>16} {:>8}\n",
        "structure",
        "filter",
        "iter",
        "bound mm",
        "volume %",
        "mean error mm/vd",
        "max error mm/vd",
        "vertices"
    );
    for s in &case.structures {
        let bound = s
            .params
            .max_displacement
            .map_or("-".into(), |b| format!("{b:.3}"));
        let (volume, mean, max) = match s.smoothed_now() {
            Some(m) => {
                let vd = s.voxel_diagonal();
                let both = |mm: f64| match vd {
                    Some(d) => format!("{mm:.3}/{:.2}", mm / d),
                    None => format!("{mm:.3}"),
                };
                (
                    m.metrics
                        .volume_change
                        .map_or("-".into(), |v| format!("{:+.2}", 100.0 * v)),
                    both(m.metrics.mean_error),
                    both(m.metrics.max_error),
                )
            }
            None => ("-".into(), "-".into(), "-".into()),
        };
        out += &format!(
            "{:<28} {:<7} {:>5} {:>8} {:>9} {:>16} {:>16} {:>8}\n",
            s.name,
            s.params.filter.name(),
            s.params.iterations,
            bound,
            volume,
            mean,
            max,
            s.original.vertex_count()
        );
    }
    out
}
