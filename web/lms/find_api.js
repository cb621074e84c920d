// Finds the LMS's SCORM API object as ADL's discovery algorithm does: this window and its
// parents up to the top, then the window that opened this one (and the one that opened the top
// window) with their parents. SCORM 1.2 names the object `API`, SCORM 2004 `API_1484_11`.

/** ADL's bound on the climb, against a chain of windows that never reaches its top. */
const MAX_TRIES = 500;

export const API_NAMES = { "1.2": "API", 2004: "API_1484_11" };

/** `read()`, or null where it throws: another origin's window refuses property reads. */
function safely(read) {
    try {
        return read() ?? null;
    } catch {
        return null;
    }
}

/** The API named `name` on `win` or one of its parents, or null. */
function scan(win, name) {
    for (let tries = 0; win && tries <= MAX_TRIES; tries++) {
        const api = safely(() => win[name]);
        if (api && (typeof api === "object" || typeof api === "function")) return api;
        const parent = safely(() => win.parent);
        if (!parent || parent === win) return null;
        win = parent;
    }
    return null;
}

/** The API of SCORM `version` ("1.2" or "2004") reachable from `win`, or null. */
export function findApi(win, version) {
    const name = API_NAMES[version];
    if (!name) return null;
    const found = scan(win, name);
    if (found) return found;
    const openers = [safely(() => win.opener), safely(() => win.top?.opener)];
    for (const opener of new Set(openers.filter(Boolean))) {
        const api = scan(opener, name);
        if (api) return api;
    }
    return null;
}
