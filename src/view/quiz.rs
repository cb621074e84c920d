//! Playing a case's quiz: its questions drawn from the case's structures (one per structure
//! and mode, each mode's in a shuffled order), the student's answers with the time each took,
//! and the score against the author's pass mark.

use crate::case::{Quiz, QuizMode};

/// How many names "Name it" offers (fewer when the case has fewer structures).
pub const CHOICES: usize = 4;

/// One question: the structure asked and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Question {
    /// The structure asked (its place in the case).
    pub structure: usize,
    pub mode: QuizMode,
    /// "Name it": the structures whose names are offered, the asked one among them; empty
    /// for "Find it".
    pub choices: Vec<usize>,
}

/// The student's answer to a question.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// The structure clicked ("Find it") or named ("Name it").
    pub given: usize,
    pub right: bool,
    /// From the question being asked to its answer.
    pub ms: f64,
}

/// A quiz as the student takes it.
#[derive(Clone, Debug)]
pub struct QuizRun {
    questions: Vec<Question>,
    /// One per question asked so far; the current one's once answered.
    answers: Vec<Answer>,
    /// The question being asked (`questions.len()` once finished).
    at: usize,
    asked_ms: f64,
    quiz: Quiz,
}

impl QuizRun {
    /// The questions of `quiz` on a case whose structures are named `names` (in the case's
    /// order), asking those the quiz names or, when it names none, those `shown`; the order
    /// is drawn from `seed`. Errors when it would ask nothing.
    pub fn new(
        quiz: &Quiz,
        names: &[&str],
        shown: &[bool],
        seed: u64,
        now_ms: f64,
    ) -> Result<Self, String> {
        let asked: Vec<usize> = if quiz.structures.is_empty() {
            (0..names.len())
                .filter(|&i| shown.get(i).copied().unwrap_or(false))
                .collect()
        } else {
            (quiz.structures.iter())
                .filter_map(|n| names.iter().position(|m| m == n))
                .collect()
        };
        if quiz.modes.is_empty() {
            return Err("the quiz has no mode to ask in".to_string());
        }
        if asked.is_empty() {
            return Err("the quiz has nothing to ask: none of its structures is shown".to_string());
        }
        let mut random = SplitMix(seed);
        let mut questions = Vec::with_capacity(asked.len() * quiz.modes.len());
        for &mode in &quiz.modes {
            let mut order = asked.clone();
            random.shuffle(&mut order);
            for structure in order {
                let choices = match mode {
                    QuizMode::FindIt => Vec::new(),
                    QuizMode::NameIt => choices(structure, names, &mut random),
                };
                questions.push(Question {
                    structure,
                    mode,
                    choices,
                });
            }
        }
        Ok(Self {
            questions,
            answers: Vec::new(),
            at: 0,
            asked_ms: now_ms,
            quiz: quiz.clone(),
        })
    }

    pub fn questions(&self) -> &[Question] {
        &self.questions
    }

    pub fn answers(&self) -> &[Answer] {
        &self.answers
    }

    /// The question being asked, with its place in the quiz; `None` once finished.
    pub fn current(&self) -> Option<(usize, &Question)> {
        self.questions.get(self.at).map(|q| (self.at, q))
    }

    /// The answer to the question being asked, once given.
    pub fn answered(&self) -> Option<&Answer> {
        self.answers.get(self.at)
    }

    /// Takes `given` (a structure) as the answer to the question being asked. Errors when it
    /// was answered already or the quiz is over.
    pub fn answer(&mut self, given: usize, now_ms: f64) -> Result<Answer, String> {
        let (_, question) = self.current().ok_or("the quiz is over")?;
        if self.answered().is_some() {
            return Err("this question was answered already".to_string());
        }
        let answer = Answer {
            given,
            right: given == question.structure,
            ms: (now_ms - self.asked_ms).max(0.0),
        };
        self.answers.push(answer);
        Ok(answer)
    }

    /// Asks the next question (the current one answered); whether the quiz is now over.
    pub fn next(&mut self, now_ms: f64) -> Result<bool, String> {
        if self.answered().is_none() {
            return Err("the question is not answered yet".to_string());
        }
        self.at += 1;
        self.asked_ms = now_ms;
        Ok(self.finished())
    }

    /// Every question answered and the last one left.
    pub fn finished(&self) -> bool {
        self.at >= self.questions.len()
    }

    /// Right answers, and questions answered.
    pub fn score(&self) -> (usize, usize) {
        let right = self.answers.iter().filter(|a| a.right).count();
        (right, self.answers.len())
    }

    /// The share of the quiz's questions answered right, in [0, 1].
    pub fn scaled(&self) -> f32 {
        self.score().0 as f32 / self.questions.len().max(1) as f32
    }

    pub fn passed(&self) -> bool {
        self.quiz.passes(self.score().0, self.questions.len())
    }

    /// The quiz asked.
    pub fn quiz(&self) -> &Quiz {
        &self.quiz
    }
}

/// `structure` and up to three others of different names, in a shuffled order.
fn choices(structure: usize, names: &[&str], random: &mut SplitMix) -> Vec<usize> {
    let mut others: Vec<usize> = (0..names.len())
        .filter(|&i| names[i] != names[structure])
        .collect();
    random.shuffle(&mut others);
    let mut out: Vec<usize> = Vec::with_capacity(CHOICES);
    out.push(structure);
    for i in others {
        if out.len() == CHOICES {
            break;
        }
        if !out.iter().any(|&o| names[o] == names[i]) {
            out.push(i);
        }
    }
    random.shuffle(&mut out);
    out
}

/// SplitMix64 (Steele, Lea and Flood): a quiz's order needs variety, not cryptographic
/// strength, and this is six lines where a crate would be a dependency for one shuffle.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Fisher-Yates.
    fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = (self.next() % (i as u64 + 1)) as usize;
            items.swap(i, j);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: [&str; 6] = ["liver", "spleen", "tumor", "right_kidney", "aorta", "liver"];

    fn quiz(structures: &[&str], modes: &[QuizMode]) -> Quiz {
        Quiz {
            structures: structures.iter().map(|s| s.to_string()).collect(),
            modes: modes.to_vec(),
            pass_mark: 0.5,
        }
    }

    #[test]
    fn it_asks_each_structure_once_per_mode_the_modes_in_the_authors_order() {
        let q = quiz(&[], &[QuizMode::NameIt, QuizMode::FindIt]);
        let shown = [true, false, true, true, true, false];
        let run = QuizRun::new(&q, &NAMES, &shown, 7, 0.0).unwrap();
        let asked = |mode| -> Vec<usize> {
            let mut v: Vec<usize> = (run.questions().iter())
                .filter(|q| q.mode == mode)
                .map(|q| q.structure)
                .collect();
            v.sort();
            v
        };
        assert_eq!(asked(QuizMode::NameIt), [0, 2, 3, 4], "the shown ones");
        assert_eq!(asked(QuizMode::FindIt), [0, 2, 3, 4]);
        assert!(run.questions()[..4]
            .iter()
            .all(|q| q.mode == QuizMode::NameIt));
        let named = QuizRun::new(
            &quiz(&["tumor", "aorta"], &[QuizMode::FindIt]),
            &NAMES,
            &shown,
            1,
            0.0,
        );
        let mut s: Vec<usize> = named
            .unwrap()
            .questions()
            .iter()
            .map(|q| q.structure)
            .collect();
        s.sort();
        assert_eq!(s, [2, 4], "the quiz's own structures, shown or not");
        // Different seeds give different orders somewhere among a few tries.
        let order = |seed| -> Vec<usize> {
            let r = QuizRun::new(&q, &NAMES, &shown, seed, 0.0).unwrap();
            r.questions().iter().map(|q| q.structure).collect()
        };
        assert!((1..10).any(|seed| order(seed) != order(0)));
    }

    #[test]
    fn name_it_offers_four_different_names_the_right_one_among_them() {
        let q = quiz(&[], &[QuizMode::NameIt]);
        for seed in 0..50 {
            let run = QuizRun::new(&q, &NAMES, &[true; 6], seed, 0.0).unwrap();
            for question in run.questions() {
                let c = &question.choices;
                assert_eq!(c.len(), CHOICES);
                assert!(c.contains(&question.structure));
                let mut names: Vec<&str> = c.iter().map(|&i| NAMES[i]).collect();
                names.sort();
                names.dedup();
                assert_eq!(names.len(), CHOICES, "no name twice: {names:?}");
            }
        }
        let two = QuizRun::new(&q, &NAMES[..2], &[true; 2], 3, 0.0).unwrap();
        assert!(two.questions().iter().all(|q| q.choices.len() == 2));
    }

    #[test]
    fn answers_are_timed_and_scored_against_the_pass_mark() {
        let q = quiz(&["liver", "tumor", "aorta"], &[QuizMode::FindIt]);
        let mut run = QuizRun::new(&q, &NAMES, &[true; 6], 5, 1000.0).unwrap();
        assert!(run.next(1100.0).is_err(), "not answered yet");
        let (i, asked) = run.current().map(|(i, q)| (i, q.structure)).unwrap();
        assert_eq!(i, 0);
        let a = run.answer(asked, 3500.0).unwrap();
        assert!(a.right);
        assert_eq!(a.ms, 2500.0);
        assert!(run.answer(asked, 3600.0).is_err(), "one answer a question");
        assert_eq!(run.next(4000.0), Ok(false));
        let asked = run.current().unwrap().1.structure;
        let wrong = (0..6).find(|&s| s != asked).unwrap();
        let a = run.answer(wrong, 4500.0).unwrap();
        assert!(!a.right && a.ms == 500.0);
        assert_eq!(run.score(), (1, 2));
        assert!(!run.passed(), "1 of 3 is below one half");
        run.next(5000.0).unwrap();
        let asked = run.current().unwrap().1.structure;
        run.answer(asked, 6000.0).unwrap();
        assert_eq!(run.next(6100.0), Ok(true));
        assert!(run.finished() && run.current().is_none());
        assert_eq!(run.score(), (2, 3));
        assert!(run.passed(), "2 of 3 passes one half");
        assert!(run.answer(0, 7000.0).is_err());
    }

    #[test]
    fn a_quiz_with_nothing_to_ask_is_refused() {
        let q = quiz(&[], &[QuizMode::FindIt]);
        assert!(QuizRun::new(&q, &NAMES, &[false; 6], 0, 0.0).is_err());
        assert!(QuizRun::new(&quiz(&["liver"], &[]), &NAMES, &[true; 6], 0, 0.0).is_err());
    }
}
