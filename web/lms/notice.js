// The launch page's one line above the viewer: what the student should know about recording,
// in their words, with a short form for narrow screens and a button to dismiss it.

export const NOTICES = {
    outside: {
        long: "Opened outside a learning platform: your progress and answers are not recorded.",
        short: "Outside a learning platform: not recorded.",
    },
    unreachable: {
        long: "The learning platform did not answer: your progress and answers are not recorded.",
        short: "Platform not answering: not recorded.",
    },
    ended: {
        long: "This session has ended: open the lesson again from your course to record more.",
        short: "Session ended: reopen it from your course.",
    },
    done: {
        long: "Your progress is recorded. ",
        short: "",
        link: "Return to your course when you are done",
    },
    saving: {
        long: "Saving your results before you return to your course…",
        short: "Saving your results…",
    },
};

/** Shows `notice` (one of NOTICES), replacing the one shown; `onLink` answers its link. */
export function showNotice(doc, notice, onLink = null) {
    const bar = doc.getElementById("notice");
    const text = doc.getElementById("notice-text");
    const part = (words, kind) => {
        const span = doc.createElement("span");
        span.className = kind;
        span.textContent = words;
        return span;
    };
    text.replaceChildren(part(notice.long, "long"), part(notice.short, "short"));
    if (notice.link && onLink) {
        const link = doc.createElement("a");
        link.href = "#";
        link.textContent = notice.link;
        link.addEventListener("click", (event) => {
            event.preventDefault();
            onLink();
        });
        text.append(link, ".");
    }
    text.title = notice.long + (notice.link ?? "");
    bar.hidden = false;
    doc.getElementById("notice-close").onclick = () => (bar.hidden = true);
}
