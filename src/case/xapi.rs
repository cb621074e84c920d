//! What a student did with a case's lesson, as xAPI statements (the Experience API that
//! learning record stores keep): the verb, the object and the result, with the actor left to
//! the platform, which knows who the student is.

use serde_json::{json, Value};

use super::{Case, Step};

/// ADL's verb for having seen a piece of content.
const EXPERIENCED: &str = "http://adlnet.gov/expapi/verbs/experienced";

/// The activity id of part `fragment` of the case: an IRI under the case's title, since a
/// case carries no address of its own (the platform may replace it with its own).
fn activity_id(case: &Case, fragment: &str) -> String {
    let title = if case.title.is_empty() {
        "case"
    } else {
        &case.title
    };
    let title: String = (title.chars())
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    format!("urn:meshsmooth:case:{title}#{fragment}")
}

/// "Experienced step `index` of the tour".
pub fn step_shown(case: &Case, index: usize, step: &Step) -> Value {
    json!({
        "verb": { "id": EXPERIENCED, "display": { "en-US": "experienced" } },
        "object": {
            "objectType": "Activity",
            "id": activity_id(case, &format!("step-{}", index + 1)),
            "definition": {
                "type": "http://adlnet.gov/expapi/activities/interaction",
                "name": { "en-US": step.title },
                "description": { "en-US": step.caption },
            },
        },
        "context": { "extensions": {
            "urn:meshsmooth:step": index + 1,
            "urn:meshsmooth:steps": case.lesson.steps.len(),
        } },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::Camera;

    #[test]
    fn a_step_shown_is_an_experienced_statement_about_that_step() {
        let step = Step {
            title: "The liver".into(),
            caption: "Seen from the front.".into(),
            camera: Camera {
                target: [0.0; 3],
                yaw: 0.0,
                pitch: 0.0,
                distance: 1.0,
            },
            hidden: Vec::new(),
            opacity: Default::default(),
            selected: None,
            clip: None,
            toward_segmentation: 0.0,
        };
        let mut case = Case {
            title: "Abdominal phantom".into(),
            ..Case::default()
        };
        case.lesson.steps = vec![step.clone(), step.clone()];
        let s = step_shown(&case, 1, &step);
        assert_eq!(s["verb"]["id"], EXPERIENCED);
        assert_eq!(
            s["object"]["id"],
            "urn:meshsmooth:case:Abdominal-phantom#step-2"
        );
        assert_eq!(s["object"]["definition"]["name"]["en-US"], "The liver");
        assert_eq!(s["context"]["extensions"]["urn:meshsmooth:steps"], 2);
        assert!(s.get("actor").is_none(), "the platform knows the student");
    }
}
