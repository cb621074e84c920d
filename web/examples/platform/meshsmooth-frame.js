// Talks to a meshsmooth page (the authoring page or the viewer) in an iframe, by its
// postMessage protocol: `call(name, ...args)` runs `window.meshsmooth[name]` there and resolves
// with its value; `on(event, listener)` hears `ready`, `loaded`, `failed`, `changed`, `step`,
// `quizAnswered` and `quizFinished`.
// Messages from anywhere but that iframe's window at `origin` are ignored.
//
// The page must be opened with `?parent=<this page's origin>`; `open(path)` does that.
export function connect(iframe, origin) {
    let lastId = 0;
    const pending = new Map();
    const listeners = new Map();
    let markReady;
    const ready = new Promise((resolve) => (markReady = resolve));

    window.addEventListener("message", (event) => {
        const message = event.data;
        if (event.origin !== origin || event.source !== iframe.contentWindow || message === null || typeof message !== "object") {
            return;
        }
        if (message.meshsmooth === "reply" && pending.has(message.id)) {
            const { resolve, reject } = pending.get(message.id);
            pending.delete(message.id);
            if (message.ok) resolve(message.value);
            else reject(new Error(message.error));
        } else if (message.meshsmooth === "event") {
            if (message.event === "ready") markReady(message.detail);
            for (const listener of listeners.get(message.event) ?? []) listener(message.detail);
        }
    });

    return {
        ready,
        /** Opens the page at `path` (under `origin`, with `query`) in the iframe. */
        open(path = "/", query = {}) {
            const url = new URL(path, origin);
            for (const [key, value] of Object.entries(query)) url.searchParams.set(key, value);
            url.searchParams.set("parent", window.location.origin);
            iframe.src = url.href;
        },
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
