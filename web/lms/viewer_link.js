// Talks to the viewer in the launch page's iframe by its postMessage protocol: `call(name,
// ...args)` runs one of its calls and resolves with the value; `on(event, listener)` hears its
// events (ready, loaded, failed, step, quizAnswered, quizFinished). Only messages from that
// iframe's window and the viewer's origin count.

export function connectViewer(iframe, origin, win = window) {
    let lastId = 0;
    const pending = new Map();
    const listeners = new Map();
    let markReady;
    const ready = new Promise((resolve) => (markReady = resolve));

    win.addEventListener("message", (event) => {
        const message = event.data;
        if (event.origin !== origin || event.source !== iframe.contentWindow || !message || typeof message !== "object") return;
        if (message.meshsmooth === "reply" && pending.has(message.id)) {
            const { resolve, reject } = pending.get(message.id);
            pending.delete(message.id);
            if (message.ok) resolve(message.value);
            else reject(new Error(message.error));
        } else if (message.meshsmooth === "event") {
            if (message.event === "ready") markReady(message.detail);
            for (const listener of listeners.get(message.event) ?? []) {
                try {
                    listener(message.detail);
                } catch (error) {
                    // One listener's fault must not stop the lesson or the others.
                    console.warn(`launch page: handling the viewer's ${message.event} event failed:`, error);
                }
            }
        }
    });

    return {
        ready,
        async call(name, ...args) {
            await ready;
            return new Promise((resolve, reject) => {
                const id = ++lastId;
                pending.set(id, { resolve, reject });
                iframe.contentWindow.postMessage({ meshsmooth: "call", id, call: name, args }, origin);
            });
        },
        on(event, listener) {
            if (!listeners.has(event)) listeners.set(event, []);
            listeners.get(event).push(listener);
        },
    };
}

/** The path from the page at URL `from` to the file at URL `to`, both in one folder tree. */
export function relativePath(from, to) {
    const source = new URL(from).pathname.split("/").slice(0, -1);
    const target = new URL(to).pathname.split("/");
    let common = 0;
    while (common < source.length && common < target.length - 1 && source[common] === target[common]) common++;
    return "../".repeat(source.length - common) + target.slice(common).join("/");
}

/**
 * The viewer's address: `viewer` (launch.json's, relative to `page`) in viewer mode with the
 * case, this page's origin as its parent (only a web origin can be one) and the languages.
 */
export function viewerUrl(page, { viewer = "viewer/index.html", caseFile = "case.glb", language = null } = {}) {
    const url = new URL(viewer, page);
    url.search = "";
    url.searchParams.set("mode", "viewer");
    url.searchParams.set("case", relativePath(url.href, new URL(caseFile, page).href));
    const origin = new URL(page).origin;
    if (/^https?:/.test(origin)) url.searchParams.set("parent", origin);
    if (language) url.searchParams.set("lang", language);
    return url.href;
}
