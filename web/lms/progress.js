// Where the student is in the lesson and what they have done: the tour step shown, the steps
// seen, whether the tour or the quiz is done. Both runtimes keep it; its compact text form is
// SCORM's suspend_data, which SCORM 1.2 keeps short.

export class Progress {
    /** `lesson`: launch.json's `{steps, quiz}`. */
    constructor(lesson) {
        this.steps = Math.max(0, Number(lesson?.steps) || 0);
        this.hasQuiz = Boolean(lesson?.quiz);
        this.step = null;
        this.seen = new Set();
        this.tourDone = false;
        this.quizDone = false;
        this.opened = false;
    }

    /** The case is open in the viewer; true when that completes the lesson (no tour, no quiz). */
    open() {
        this.opened = true;
        return this.steps === 0 && !this.hasQuiz;
    }

    /** Step `step` (from 0) of `steps` shown; true when it is the tour's last. */
    show(step, steps) {
        if (Number.isInteger(steps) && steps > 0) this.steps = steps;
        if (!Number.isInteger(step) || step < 0) return false;
        this.step = step;
        this.seen.add(step);
        const last = this.steps > 0 && step === this.steps - 1;
        if (last) this.tourDone = true;
        return last;
    }

    /** Nothing left to do: the tour's last step seen or the quiz finished. */
    get complete() {
        return this.tourDone || this.quizDone || (this.steps === 0 && !this.hasQuiz && this.opened);
    }

    /** The lesson has nothing further to report: the quiz finished, or without one the tour. */
    get finished() {
        return this.hasQuiz ? this.quizDone : this.complete;
    }

    /** The share of the lesson done, 0 to 1: steps seen and the quiz, 1 once complete. */
    get measure() {
        if (this.complete) return 1;
        const parts = this.steps + (this.hasQuiz ? 1 : 0);
        return parts ? Math.min(1, this.seen.size / parts) : 0;
    }

    /** The steps seen as hexadecimal digits, four steps a digit, the first step lowest. */
    seenText() {
        const digits = [];
        for (let i = 0; i < this.steps; i += 4) {
            let d = 0;
            for (let b = 0; b < 4; b++) if (this.seen.has(i + b)) d |= 1 << b;
            digits.push(d.toString(16));
        }
        return digits.join("").replace(/0+$/, "");
    }

    readSeen(text) {
        for (const [k, ch] of Array.from(String(text ?? "")).entries()) {
            const d = parseInt(ch, 16);
            if (Number.isNaN(d)) return;
            for (let b = 0; b < 4; b++) if (d & (1 << b)) this.seen.add(k * 4 + b);
        }
    }

    /** The suspend_data string: `1:<step or ->:<steps seen>`, the 1 its format's version. */
    toText() {
        return `1:${this.step ?? "-"}:${this.seenText()}`;
    }

    /** Takes back what `toText` wrote; anything else (another format, or none) is left alone. */
    readText(text) {
        const match = /^1:(\d+|-):([0-9a-f]*)$/.exec(String(text ?? ""));
        if (!match) return false;
        if (match[1] !== "-") this.step = Number(match[1]);
        this.readSeen(match[2]);
        return true;
    }
}
