//! The case's quiz as the page plays it: started, answered and moved on by the student's
//! clicks or the platform's calls, what `state()` reports of it, and the events (with their
//! xAPI statements) the platform hears.

use serde_json::{json, Value};

use super::document::{now_ms, Document};
use crate::case::{xapi, QuizMode};
use crate::session::StructureChange;
use crate::view::QuizRun;

/// The quiz in words ([`Document::quiz_words`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QuizWords {
    pub heading: String,
    pub question: String,
    /// Right (or passed), and the sentence that says so.
    pub outcome: Option<(bool, String)>,
}

impl Document {
    /// Starts the case's quiz (again), leaving the tour; the structures it asks are shown.
    pub fn start_quiz(&mut self) -> Result<(), String> {
        let quiz = (self.session().case().lesson().quiz.clone()).ok_or("the case has no quiz")?;
        let structures = self.session().case().as_case().structures.as_slice();
        let shown: Vec<bool> = structures.iter().map(|s| s.visible).collect();
        let names = self.session().case().as_case().names();
        // The clock seeds the order, so that a second try asks in another.
        let now = now_ms();
        let run = QuizRun::new(&quiz, &names, &shown, now.to_bits(), now)?;
        let mut asked: Vec<usize> = run.questions().iter().map(|q| q.structure).collect();
        asked.sort_unstable();
        asked.dedup();
        for i in asked.into_iter().filter(|&i| !shown[i]) {
            let visible = StructureChange {
                visible: Some(true),
                ..Default::default()
            };
            self.session_mut().case_mut().set_structure(i, visible)?;
        }
        self.leave_tour();
        self.quiz = Some(run);
        Ok(())
    }

    /// Answers the question asked with structure `given` (clicked or named); the platform
    /// hears it.
    pub fn answer_quiz(&mut self, given: usize) -> Result<(), String> {
        let running = self.quiz.as_mut().ok_or("no quiz is running")?;
        let answer = running.answer(given, now_ms())?;
        let run = self.quiz.as_ref().ok_or("no quiz is running")?;
        let (_, question) = run.current().ok_or("the quiz is over")?;
        let names = self.session().case().as_case().names();
        let name = |i: usize| names.get(i).copied().unwrap_or_default();
        let choices: Vec<&str> = question.choices.iter().map(|&i| name(i)).collect();
        let asked = (name(question.structure), question.mode);
        let statement = xapi::quiz_answered(
            self.session().case().as_case(),
            asked,
            &choices,
            name(given),
            answer.ms,
        );
        let event = json!({
            "structure": asked.0,
            "mode": question.mode,
            "given": name(given),
            "right": answer.right,
            "ms": answer.ms,
            "statement": statement,
        });
        self.lesson_events.push(("quizAnswered", event));
        Ok(())
    }

    /// Asks the next question, the one asked being answered; after the last, the platform
    /// hears the score.
    pub fn next_question(&mut self) -> Result<(), String> {
        let running = self.quiz.as_mut().ok_or("no quiz is running")?;
        if !running.next(now_ms())? {
            return Ok(());
        }
        let run = self.quiz.as_ref().ok_or("no quiz is running")?;
        let (right, questions) = (run.score().0, run.questions().len());
        let statement = xapi::quiz_finished(
            self.session().case().as_case(),
            run.quiz(),
            right,
            questions,
        );
        let event = json!({
            "right": right,
            "questions": questions,
            "score": run.scaled(),
            "passed": run.passed(),
            "statement": statement,
        });
        self.lesson_events.push(("quizFinished", event));
        Ok(())
    }

    /// Ends the quiz, finished or not.
    pub fn end_quiz(&mut self) {
        self.quiz = None;
    }

    /// The structure the view singles out: the one asked in "Name it", and the right one
    /// once a question is answered.
    pub fn quiz_highlight(&self) -> Option<usize> {
        let run = self.quiz.as_ref()?;
        let (_, q) = run.current()?;
        (q.mode == QuizMode::NameIt || run.answered().is_some()).then_some(q.structure)
    }

    /// Whether a click in the view answers the question asked ("Find it", not yet answered).
    pub fn quiz_wants_click(&self) -> bool {
        let Some(run) = &self.quiz else {
            return false;
        };
        let asking = run
            .current()
            .is_some_and(|(_, q)| q.mode == QuizMode::FindIt);
        asking && run.answered().is_none()
    }

    /// The quiz in words, as the panel shows it and a screen reader reads it: the heading
    /// ("Quiz: question 3 of 8"), the question, and once answered whether it was right and
    /// what; once finished, the score and whether it passes. Empty when no quiz runs.
    pub fn quiz_words(&self) -> QuizWords {
        let Some(run) = &self.quiz else {
            return QuizWords::default();
        };
        let words = self.words();
        let name = |i: usize| words.name(i);
        let total = run.questions().len();
        let Some((i, question)) = run.current() else {
            let percent = (100.0 * run.scaled()).round();
            let mark = (100.0 * run.quiz().pass_mark).round();
            let verdict = match run.passed() {
                true => format!("Passed (the pass mark is {mark}%)."),
                false => format!("Not passed yet (the pass mark is {mark}%)."),
            };
            return QuizWords {
                heading: "Quiz finished".into(),
                question: format!("{} of {total} right ({percent}%).", run.score().0),
                outcome: Some((run.passed(), verdict)),
            };
        };
        let asked = name(question.structure);
        let question_text = match question.mode {
            QuizMode::FindIt => format!("Find it: click the {asked} in the view."),
            QuizMode::NameIt => "Name it: which structure is highlighted?".to_string(),
        };
        let outcome = run.answered().map(|a| match a.right {
            true => (true, format!("Right: the {asked}.")),
            false => (
                false,
                format!(
                    "No, that is the {}. The {asked} is highlighted.",
                    name(a.given)
                ),
            ),
        });
        QuizWords {
            heading: format!("Quiz: question {} of {total}", i + 1),
            question: question_text,
            outcome,
        }
    }

    /// The quiz for `state()`: null without one in the case; `running` false until started.
    pub fn quiz_json(&self) -> Value {
        let Some(quiz) = &self.session().case().lesson().quiz else {
            return Value::Null;
        };
        let Some(run) = &self.quiz else {
            return json!({ "running": false, "modes": quiz.modes, "pass_mark": quiz.pass_mark });
        };
        let names = self.session().case().as_case().names();
        let name = |i: usize| names.get(i).copied().unwrap_or_default();
        let current = run.current();
        let (right, answered) = run.score();
        json!({
            "running": true,
            "modes": quiz.modes,
            "pass_mark": quiz.pass_mark,
            "question": current.map(|(i, _)| i),
            "questions": run.questions().len(),
            "mode": current.map(|(_, q)| q.mode),
            "asked": current.map(|(_, q)| name(q.structure)),
            "choices": current.map_or(Vec::new(), |(_, q)| q.choices.iter().map(|&i| name(i)).collect()),
            "answer": run.answered().map(|a| json!({"given": name(a.given), "right": a.right})),
            "right": right,
            "answered": answered,
            "finished": run.finished(),
            "score": run.scaled(),
            "passed": run.finished().then(|| run.passed()),
        })
    }
}
