//! The JSON the embedding API returns, written from the session's data: `state()` and its
//! parts, the structures, a model's info and measures, the guidance and the checks. Where the
//! CLI prints the same thing (`info --json`, `measure --json`, `sweep --json`, `case check
//! --json`) the shape is the CLI's.

use crate::session::{Background, CaseDocument, Session, StructureChange, StructureOutcome};
use serde_json::{json, Value};

/// The model's mesh report, as `info --json` prints it.
pub(crate) fn info(case: &CaseDocument) -> Option<Value> {
    (case.model()).and_then(|m| serde_json::to_value(&m.report).ok())
}

/// The current result's measures, as `measure --json` prints them.
pub(crate) fn metrics(case: &CaseDocument) -> Option<Value> {
    (case.result()).and_then(|r| serde_json::to_value(&r.metrics).ok())
}

/// The open case's structures: what each is, how it is shown and, where it was smoothed, its
/// measures.
pub(crate) fn structures(case: &CaseDocument) -> Option<Value> {
    let current = case.current_structure()?;
    let list: Vec<_> = (case.as_case().structures.iter().enumerate())
        .map(|(i, s)| {
            json!({
                "label": s.label,
                "name": s.name,
                "color": [s.color[0], s.color[1], s.color[2]],
                "opacity": s.color[3],
                "visible": s.visible,
                "group": s.group,
                "description": s.description,
                "names": s.names,
                "source": s.source,
                "voxels": s.voxels,
                "voxel_size": s.voxel_size,
                "codes": s.codes,
                "vertices": s.original.vertex_count(),
                "triangles": s.original.triangle_count(),
                "volume": s.original.signed_volume(),
                "metrics": case.structure_metrics(i),
                "shown_as_read": case.shown_as_read(i),
            })
        })
        .collect();
    Some(json!({
        "file": case.case_file(),
        "current": current,
        "title": case.as_case().title.as_str(),
        "description": case.as_case().description.as_str(),
        "structures": list,
        "image": case.as_case().image.as_ref().map(|i| json!({
            "source": i.source,
            "dims": i.dims,
            "preset": i.preset,
            "window": i.window,
        })),
    }))
}

/// `{index, name, color: [r, g, b], opacity, visible, group, description}` as `setStructure`
/// takes it (every key optional; `index` defaults to the model's structure; `group` null or ""
/// ungroups). Unknown keys and values of the wrong kind are refused, naming the key.
pub(crate) fn structure_change(value: &Value) -> Result<(Option<usize>, StructureChange), String> {
    let object = value.as_object().ok_or(
        "setStructure takes an object: {index, name, color, opacity, visible, group, description}",
    )?;
    let mut change = StructureChange::default();
    let mut index = None;
    for (key, v) in object {
        let wrong = |what: &str| format!("setStructure: {key} must be {what}, not {v}");
        let text = || {
            v.as_str()
                .map(str::to_string)
                .ok_or_else(|| wrong("a string"))
        };
        match key.as_str() {
            "index" => {
                let i = v.as_u64().ok_or_else(|| wrong("a whole number >= 0"))?;
                index = Some(usize::try_from(i).map_err(|_| wrong("a structure's index"))?);
            }
            "name" => change.name = Some(text()?),
            "color" => {
                let c: Vec<f32> = (v.as_array().into_iter().flatten())
                    .filter_map(|c| c.as_f64().map(|c| c as f32))
                    .collect();
                let rgb: [f32; 3] = c.try_into().map_err(|_| wrong("three numbers in [0, 1]"))?;
                change.color = Some(rgb);
            }
            "opacity" => change.opacity = Some(v.as_f64().ok_or_else(|| wrong("a number"))? as f32),
            "visible" => change.visible = Some(v.as_bool().ok_or_else(|| wrong("true or false"))?),
            "group" => {
                let group = match v {
                    Value::Null => None,
                    v => Some(v.as_str().ok_or_else(|| wrong("a string or null"))?.into()),
                };
                change.group = Some(group);
            }
            "description" => change.description = Some(text()?),
            "names" => {
                let names = crate::case::names::from_json(v).map_err(|e| format!("setStructure: {e}"))?;
                change.names = Some(names);
            }
            other => {
                return Err(format!(
                    "setStructure: unknown key {other} (index, name, color, opacity, visible, group, description, names)"
                ))
            }
        }
    }
    Ok((index, change))
}

/// The session's part of `state()`: the model, its settings, the engines and the openings.
pub(crate) fn session_state(session: &Session, busy: bool) -> Value {
    let case = session.case();
    let model = case.model();
    json!({
        "model": model.map(|m| m.name.as_str()),
        "vertices": model.map(|m| m.report.vertices),
        "faces": model.map(|m| m.report.faces),
        "error": session.error(),
        "filter": case.filter().name(),
        "params": case.params().to_json(),
        "tau": case.tau(),
        "busy": busy,
        "cpu_engine": cpu_engine(session.cpu_engine()),
        "weights": crate::session::WeightsSummary::of(case.weights()),
        "structures": structures(case),
        "loading": session.loading().map(|l| json!({
            "name": l.name, "stage": l.stage, "stages": l.total, "doing": l.doing,
        })),
        "open_stages": (session.open_stages().iter())
            .map(|(doing, ms)| json!({"doing": doing, "ms": ms}))
            .collect::<Vec<_>>(),
        "guidance": guidance(&session.background()),
        "checks": checks(&session.background()),
        "case_export": case_export(session),
        "suggest_all": suggest_all(&session.background(), crate::app::document::now_ms()),
    })
}

/// The case glTF being written (`writing`: structures done of all, bytes so far) or written
/// and current (`written`: its bytes and triangles), and why the last one failed; null before
/// any.
fn case_export(session: &Session) -> Value {
    let writing = session.case_export().progress().map(|p| {
        json!({"done": p.structures_done, "total": p.structures, "bytes": p.bytes, "triangles": p.triangles})
    });
    let written = (session.case_export().written())
        .map(|w| json!({"bytes": w.bytes.len(), "triangles": w.triangles}));
    let error = session.case_export().error();
    if writing.is_none() && written.is_none() && error.is_none() {
        return Value::Null;
    }
    json!({"writing": writing, "written": written, "error": error})
}

/// The current quality graphs as `sweep --json` prints them, once they are current.
pub(crate) fn graphs(background: &Background) -> Option<Value> {
    if !background.graphs_current() {
        return None;
    }
    let graphs = background.graphs()?;
    Some(graphs.to_json(background.graphs_seconds()))
}

/// `state().guidance`: the background work under way, whether the graphs are current, the
/// suggestion and the gallery.
pub(crate) fn guidance(background: &Background) -> Value {
    let activities: Vec<Value> = (background.activities().iter())
        .map(|a| json!({"what": a.describe(), "fraction": a.fraction()}))
        .collect();
    json!({
        "activities": activities,
        "graphs_current": background.graphs_current(),
        "suggestion": background.suggestion().map(|s| s.suggestion.to_json(s.elapsed_ms / 1000.0)),
        "gallery": background.gallery().iter().map(|p| json!({
            "tau": p.tau,
            "params": p.params.to_json(),
            "terms": p.terms,
            "volume_change": p.volume_change,
        })).collect::<Vec<_>>(),
        "problem": background.guidance_problem(),
    })
}

/// The last "Suggest all": `{tau, search, structures, done, total, work_done, seconds_left,
/// cancelled}`, each structure `{name, params, evaluations, metrics}`, `{name, error}` or null
/// until it answers; `work_done`, while it runs, the fraction of the expected work done, and
/// `seconds_left` the time that work takes at the pace so far (both null after).
pub(crate) fn suggest_all(background: &Background, now_ms: f64) -> Option<Value> {
    let report = background.suggest_all()?;
    let outcome = |o: &Option<StructureOutcome>| match o {
        Some(StructureOutcome::Suggested {
            name,
            params,
            evaluations,
            metrics,
        }) => json!({"name": name, "params": params.to_json(), "evaluations": evaluations,
            "metrics": metrics}),
        Some(StructureOutcome::Failed { name, why }) => json!({"name": name, "error": why}),
        None => Value::Null,
    };
    Some(json!({
        "tau": report.options.tau,
        "search": report.options.search,
        "structures": report.structures.iter().map(outcome).collect::<Vec<_>>(),
        "done": report.done,
        "total": report.total,
        "work_done": background.suggest_all_work_done(),
        "seconds_left": background.suggest_all_seconds_left(now_ms),
        "cancelled": report.cancelled,
    }))
}

/// The last checks' report as `case check --json` prints it, with whether the structures are
/// still as checked (`current`); null before any checks.
pub(crate) fn checks(background: &Background) -> Value {
    let Some(report) = background.checks_report() else {
        return Value::Null;
    };
    let mut report = report.clone();
    report["current"] = background.checks_current().into();
    report
}

/// What `state()` says of the CPU engine: its workers, whether they are threads, and how many
/// openings were asked of them.
pub fn cpu_engine(pool: &crate::worker::Pool) -> Value {
    json!({
        "workers": pool.workers(),
        "view_worker": pool.has_view_worker(),
        "threaded": pool.threaded(),
        "openings": pool.openings(),
        "restarts": pool.restarts(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_browser);

    #[wasm_bindgen_test]
    fn set_structure_takes_each_key_and_refuses_the_wrong_kind_by_name() {
        let (index, change) = structure_change(&json!({
            "index": 2, "name": " tumour ", "color": [0.0, 1.0, 0.0], "opacity": 0.4,
            "visible": false, "group": null, "description": "it grows",
            "names": {"DE": "Tumor"},
        }))
        .unwrap();
        assert_eq!(index, Some(2));
        let expected = StructureChange {
            name: Some(" tumour ".into()),
            color: Some([0.0, 1.0, 0.0]),
            opacity: Some(0.4),
            visible: Some(false),
            group: Some(None),
            description: Some("it grows".into()),
            names: Some([("de".to_string(), "Tumor".to_string())].into()),
        };
        assert_eq!(change, expected);
        assert_eq!(
            structure_change(&json!({})).unwrap(),
            (None, StructureChange::default())
        );
        for (bad, named) in [
            (json!({"group": 3}), "group"),
            (json!({"visible": "yes"}), "visible"),
            (json!({"color": [0, 1]}), "color"),
            (json!({"index": -1}), "index"),
            (json!({"colour": [0, 1, 0]}), "colour"),
            (json!([1]), "an object"),
            (json!({"names": "Tumor"}), "names must be an object"),
            (json!({"names": {"de": 1}}), "the name in 'de' is not text"),
        ] {
            let e = structure_change(&bad).unwrap_err();
            assert!(e.contains(named), "{bad}: {e}");
        }
    }

    #[wasm_bindgen_test]
    fn the_structures_list_names_each_with_its_look_and_measures() {
        let mut session = Session::default();
        assert_eq!(structures(session.case()), None, "nothing open");
        session
            .open(crate::app::SAMPLE_NAME, crate::app::SAMPLE_BYTES)
            .unwrap();
        let (_, group) = structure_change(&json!({"group": " Vessels "})).unwrap();
        session.case_mut().set_structure(0, group).unwrap();
        let list = structures(session.case()).unwrap();
        assert_eq!(list["current"], 0);
        assert_eq!(list["file"], crate::app::SAMPLE_NAME);
        assert_eq!(list["structures"][0]["group"], "Vessels");
        assert_eq!(list["structures"][0]["names"]["de"], "Leber");
        assert!(
            list["structures"][0]["metrics"].is_null(),
            "not smoothed yet"
        );
        crate::session::testing::smooth_cpu(&mut session);
        let list = structures(session.case()).unwrap();
        assert_eq!(
            list["structures"][0]["metrics"],
            metrics(session.case()).unwrap()
        );
        let state = session_state(&session, false);
        assert_eq!(state["structures"], list);
        assert_eq!(state["checks"], Value::Null);
    }
}
