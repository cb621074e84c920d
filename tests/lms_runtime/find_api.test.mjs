// Finding the LMS's API (web/lms/find_api.js) in windows made of plain objects: up the parents,
// past windows of other origins, then through the opener.
import { describe, it } from "node:test";
import assert from "node:assert/strict";

import { findApi } from "../../web/lms/find_api.js";

/** A window inside `parent` (a top window when there is none), with `props` on it. */
function frame(parent = null, props = {}) {
    const win = { ...props };
    win.parent = parent ?? win;
    win.top = parent ? parent.top : win;
    win.opener = null;
    return win;
}

/** A window of another origin: reading anything but `parent`, `top` and `opener` throws. */
function foreign(parent = null) {
    const win = frame(parent);
    for (const name of ["API", "API_1484_11"]) {
        Object.defineProperty(win, name, {
            get() {
                throw new Error("SecurityError: Blocked a frame with origin from accessing a cross-origin frame");
            },
        });
    }
    return win;
}

/** `depth` frames nested in `top`, the innermost returned. */
function nested(top, depth) {
    let win = top;
    for (let i = 0; i < depth; i++) win = frame(win);
    return win;
}

describe("finding the SCORM API", () => {
    it("finds each version's own API up the parents, the nearest first", () => {
        const api12 = { LMSInitialize() {} };
        const api2004 = { Initialize() {} };
        const near2004 = { Initialize() {} };
        const top = frame(null, { API: api12, API_1484_11: api2004 });
        const player = frame(top, { API_1484_11: near2004 });
        const launchPage = nested(player, 3);
        assert.equal(findApi(launchPage, "1.2"), api12);
        assert.equal(findApi(launchPage, "2004"), near2004);
        assert.equal(findApi(launchPage, "2005"), null);
    });

    it("looks in this window too, and climbs deeper than ADL's SCORM 1.2 wrapper did", () => {
        const api = {};
        assert.equal(findApi(frame(null, { API: api }), "1.2"), api);
        const deep = nested(frame(null, { API: api }), 12);
        assert.equal(findApi(deep, "1.2"), api);
    });

    it("climbs past windows of other origins", () => {
        const api = {};
        const top = frame(null, { API_1484_11: api });
        const cdn = foreign(top);
        const launchPage = frame(cdn);
        assert.equal(findApi(launchPage, "2004"), api);
    });

    it("then looks in the opener and its parents, and in the opener of the top window", () => {
        const api = {};
        const lmsTop = frame(null, { API: api });
        const lmsFrame = frame(lmsTop);
        const popup = frame();
        popup.opener = lmsFrame;
        assert.equal(findApi(popup, "1.2"), api, "a popup the LMS opened");

        const popupTop = frame();
        popupTop.opener = lmsFrame;
        const inPopup = nested(popupTop, 2);
        assert.equal(findApi(inPopup, "1.2"), api, "a frame in that popup");
    });

    it("gives up without an API, and on a chain of windows without a top", () => {
        assert.equal(findApi(nested(frame(), 4), "1.2"), null);
        const a = { opener: null };
        const b = { parent: a, opener: null };
        a.parent = b;
        assert.equal(findApi(a, "2004"), null);
        const closed = frame();
        Object.defineProperty(closed, "opener", { get() { throw new Error("SecurityError"); } });
        assert.equal(findApi(closed, "1.2"), null);
    });
});
