// Mouse and keyboard over the app's 3D view, as a hand gives them: a frame apart.
import assert from "node:assert/strict";

/** Waits for the next two frames the page paints (input is handled once per frame). */
export const frames = (app) =>
    app.page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

/** The 3D view's rectangle and its centre (CSS pixels), from `state().view`. */
export async function viewCentre(app) {
    const { view } = await app.state();
    assert.ok(view && view.width > 200 && view.height > 200, `state().view: ${JSON.stringify(view)}`);
    return { x: view.x + view.width / 2, y: view.y + view.height / 2, view };
}

/**
 * Drags with `button` from `from` by `by` in `steps` moves, a frame apart (as a hand does);
 * `during(app)` runs before the button is released.
 */
export async function drag(app, button, from, by, { steps = 12, during } = {}) {
    const mouse = app.page.mouse;
    await mouse.move(from.x, from.y);
    await frames(app);
    await mouse.down({ button });
    await frames(app);
    for (let k = 1; k <= steps; k++) {
        await mouse.move(from.x + (by.x * k) / steps, from.y + (by.y * k) / steps);
        await frames(app);
    }
    await during?.(app);
    await mouse.up({ button });
    await frames(app);
}

/** Clicks the view (so the canvas has the keyboard) and presses P, the brush's key. */
export async function brushOn(app, centre) {
    await app.page.mouse.click(centre.x, centre.y);
    await frames(app);
    await app.page.keyboard.press("p");
    await frames(app);
}

/** The current parameters once the page has taken every event (its measures computed). */
export async function settled(app) {
    const metrics = await app.metrics();
    const state = await app.state();
    return { metrics, state };
}


/**
 * Clicks the control `key` of the page's lessons (`state().layout.lesson`): the Lesson panel's,
 * the tour's, the quiz's. One out of the panel's sight is scrolled into it first, as the author
 * would.
 */
export async function pressLessonControl(app, key) {
    const centreOf = (r) => [r.x + r.width / 2, r.y + r.height / 2];
    let state = await app.stateWhen((s) => s.layout.lesson?.[key], `the lesson's ${key}`);
    for (let tries = 0; tries < 20 && state.layout.lesson["in-sight"]; tries++) {
        const [r, v] = [state.layout.lesson[key], state.layout.lesson["in-sight"]];
        const below = r.y + r.height > v.y + v.height;
        if (!below && r.y >= v.y) break;
        await app.page.mouse.move(...centreOf(v));
        await app.page.mouse.wheel(0, below ? 100 : -100);
        await frames(app);
        state = await app.state();
    }
    await app.page.mouse.click(...centreOf(state.layout.lesson[key]));
    await frames(app);
}
