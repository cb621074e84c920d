//! What a student did with a case's lesson, as xAPI statements (the Experience API that
//! learning record stores keep): the verb, the object and the result, with the actor left to
//! the platform, which knows who the student is.

use serde_json::{json, Value};

use super::{Case, Quiz, QuizMode, Step};

/// ADL's verbs: having seen a piece of content, answered a question, passed or failed a test.
const EXPERIENCED: &str = "http://adlnet.gov/expapi/verbs/experienced";
const ANSWERED: &str = "http://adlnet.gov/expapi/verbs/answered";
const PASSED: &str = "http://adlnet.gov/expapi/verbs/passed";
const FAILED: &str = "http://adlnet.gov/expapi/verbs/failed";
/// The activity type of a question (SCORM's interaction, as xAPI adopted it).
const INTERACTION: &str = "http://adlnet.gov/expapi/activities/cmi.interaction";

/// The case's activity id: an IRI made from its title, since a case carries no address of its
/// own (the platform may replace it with its own). A package's cmi5 AU has this id.
pub fn case_activity(case: &Case) -> String {
    let title = if case.title.is_empty() {
        "case"
    } else {
        &case.title
    };
    format!("urn:meshsmooth:case:{}", slug(title))
}

/// The activity id of part `fragment` of the case, under [`case_activity`].
fn activity_id(case: &Case, fragment: &str) -> String {
    format!("{}#{fragment}", case_activity(case))
}

/// `text` with every character but ASCII letters and digits as `-`, for an IRI.
fn slug(text: &str) -> String {
    (text.chars())
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
}

/// "Answered" the quiz's question on `structure` in `mode` with `given` (the structure
/// clicked or named), right or not, after `ms`; `choices` are the names offered ("Name it").
pub fn quiz_answered(
    case: &Case,
    (structure, mode): (&str, QuizMode),
    choices: &[&str],
    given: &str,
    ms: f64,
) -> Value {
    let (mode_id, asked, interaction) = match mode {
        QuizMode::FindIt => ("find-it", format!("Find the {structure}"), "other"),
        QuizMode::NameIt => ("name-it", "Name the structure shown".to_string(), "choice"),
    };
    let mut definition = json!({
        "type": INTERACTION,
        "name": { "en-US": asked },
        "interactionType": interaction,
        "correctResponsesPattern": [structure],
    });
    if !choices.is_empty() {
        definition["choices"] = (choices.iter())
            .map(|c| json!({ "id": c, "description": { "en-US": c } }))
            .collect();
    }
    json!({
        "verb": { "id": ANSWERED, "display": { "en-US": "answered" } },
        "object": {
            "objectType": "Activity",
            "id": activity_id(case, &format!("quiz-{mode_id}-{}", slug(structure))),
            "definition": definition,
        },
        "result": {
            "success": given == structure,
            "response": given,
            "duration": duration(ms),
        },
        "context": { "extensions": { "urn:meshsmooth:quiz-mode": mode_id } },
    })
}

/// "Passed" or "failed" `quiz`, `right` of `questions` answered right.
pub fn quiz_finished(case: &Case, quiz: &Quiz, right: usize, questions: usize) -> Value {
    let scaled = right as f64 / questions.max(1) as f64;
    let passed = quiz.passes(right, questions);
    let (verb, word) = if passed {
        (PASSED, "passed")
    } else {
        (FAILED, "failed")
    };
    json!({
        "verb": { "id": verb, "display": { "en-US": word } },
        "object": {
            "objectType": "Activity",
            "id": activity_id(case, "quiz"),
            "definition": {
                "type": "http://adlnet.gov/expapi/activities/assessment",
                "name": { "en-US": "Quiz" },
            },
        },
        "result": {
            "score": { "scaled": scaled, "raw": right, "min": 0, "max": questions },
            "success": passed,
            "completion": true,
        },
        "context": { "extensions": { "urn:meshsmooth:pass-mark": quiz.pass_mark } },
    })
}

/// An xAPI language map: the own text as English (en-US), then the text in each other
/// language the author gave.
fn language_map(own: &str, others: &super::names::Names) -> Value {
    let mut map = serde_json::Map::new();
    map.insert("en-US".into(), json!(own));
    for (tag, text) in others
        .iter()
        .filter(|(t, _)| !t.eq_ignore_ascii_case("en-US"))
    {
        map.insert(tag.clone(), json!(text));
    }
    Value::Object(map)
}

/// An ISO 8601 duration, as xAPI's results carry it.
fn duration(ms: f64) -> String {
    format!("PT{:.2}S", ms.max(0.0) / 1000.0)
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
                "name": language_map(&step.title, &step.titles),
                "description": language_map(&step.caption, &step.captions),
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
            titles: [("de".to_string(), "Die Leber".to_string())].into(),
            captions: Default::default(),
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
            planes: None,
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
        let definition = &s["object"]["definition"];
        assert_eq!(
            definition["name"],
            json!({"en-US": "The liver", "de": "Die Leber"})
        );
        assert_eq!(
            definition["description"],
            json!({"en-US": "Seen from the front."})
        );
        assert_eq!(s["context"]["extensions"]["urn:meshsmooth:steps"], 2);
        assert!(s.get("actor").is_none(), "the platform knows the student");
    }

    #[test]
    fn an_answer_states_the_question_the_response_and_its_success() {
        let case = Case {
            title: "Abdominal phantom".into(),
            ..Case::default()
        };
        let found = quiz_answered(
            &case,
            ("right kidney", QuizMode::FindIt),
            &[],
            "liver",
            2345.0,
        );
        assert_eq!(found["verb"]["id"], ANSWERED);
        assert_eq!(
            found["object"]["id"],
            "urn:meshsmooth:case:Abdominal-phantom#quiz-find-it-right-kidney"
        );
        let definition = &found["object"]["definition"];
        assert_eq!(definition["type"], INTERACTION);
        assert_eq!(definition["interactionType"], "other");
        assert_eq!(definition["correctResponsesPattern"][0], "right kidney");
        assert_eq!(found["result"]["success"], false);
        assert_eq!(found["result"]["response"], "liver");
        assert_eq!(found["result"]["duration"], "PT2.35S");

        let choices = ["tumor", "liver", "aorta", "spleen"];
        let named = quiz_answered(&case, ("liver", QuizMode::NameIt), &choices, "liver", 900.0);
        assert_eq!(named["object"]["definition"]["interactionType"], "choice");
        assert_eq!(named["object"]["definition"]["choices"][3]["id"], "spleen");
        assert_eq!(named["result"]["success"], true);
    }

    #[test]
    fn a_finished_quiz_passed_or_failed_with_its_scaled_score() {
        let case = Case::default();
        let quiz = Quiz {
            structures: Vec::new(),
            modes: vec![QuizMode::FindIt],
            pass_mark: 0.75,
        };
        let passed = quiz_finished(&case, &quiz, 3, 4);
        assert_eq!(passed["verb"]["id"], PASSED);
        assert_eq!(passed["result"]["score"]["scaled"], 0.75);
        assert_eq!(passed["result"]["score"]["raw"], 3);
        assert_eq!(passed["result"]["score"]["max"], 4);
        assert_eq!(passed["result"]["success"], true);
        assert_eq!(passed["object"]["id"], "urn:meshsmooth:case:case#quiz");
        let failed = quiz_finished(&case, &quiz, 2, 4);
        assert_eq!(failed["verb"]["id"], FAILED);
        assert_eq!(failed["result"]["success"], false);
        let fifths = Quiz {
            pass_mark: 0.6,
            ..quiz
        };
        let three_of_five = quiz_finished(&case, &fifths, 3, 5);
        assert_eq!(
            three_of_five["verb"]["id"], PASSED,
            "the mark itself passes"
        );
    }
}
