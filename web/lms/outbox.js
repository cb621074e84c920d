// Requests for the learning record store, sent one at a time in the order they were made. One
// the store does not take now (no network, or a server error) is tried again after a growing
// pause, never dropped, and the requests after it wait, so the order holds. The list is kept in
// the page's storage, so a reload sends what was left.

export class Outbox {
    /**
     * `send(item, {keepalive})` resolves "done" (taken, or refused for good) or "retry".
     * `store`: `{load(), save(items)}` or null; `retry`: the first and the longest pause (ms).
     */
    constructor({ send, store = null, retry = { first: 1000, max: 60000 }, timers = globalThis }) {
        this.send = send;
        this.store = store;
        this.retry = retry;
        this.timers = timers;
        this.items = store?.load() ?? [];
        this.started = false;
        this.busy = false;
        this.timer = null;
        this.pause = retry.first;
        this.waiting = [];
    }

    get size() {
        return this.items.length;
    }

    /**
     * Adds `item` at the end. An item with a `key` replaces the unsent ones with the same key
     * (a document written again: only the last version matters).
     */
    push(item) {
        if (item.key) {
            const inFlight = this.busy ? this.items[0] : null;
            this.items = this.items.filter((i) => i === inFlight || i.key !== item.key);
        }
        this.items.push(item);
        this.#save();
        this.#pump();
    }

    /** Starts sending (once the store can be reached: the token is known). */
    start() {
        this.started = true;
        this.#pump();
    }

    /** Tries again now, as when the browser says it is back online. */
    kick() {
        if (this.timer === null) return;
        this.timers.clearTimeout(this.timer);
        this.timer = null;
        this.#pump();
    }

    /**
     * The page is going away: everything left goes out at once with `keepalive`, which lets a
     * request outlive the page. They stay listed, so a reload sends them again (the store
     * knows a statement it has by its id).
     */
    flush() {
        if (!this.started) return;
        for (const item of this.items) this.send(item, { keepalive: true }).catch(() => {});
    }

    /** Resolves once nothing is left to send. */
    idle() {
        if (this.items.length === 0) return Promise.resolve();
        return new Promise((resolve) => this.waiting.push(resolve));
    }

    async #pump() {
        if (!this.started || this.busy || this.timer !== null) return;
        this.busy = true;
        while (this.items.length) {
            const item = this.items[0];
            let outcome;
            try {
                outcome = await this.send(item, { keepalive: false });
            } catch {
                outcome = "retry";
            }
            if (outcome === "retry") {
                this.busy = false;
                this.timer = this.timers.setTimeout(() => {
                    this.timer = null;
                    this.#pump();
                }, this.pause);
                this.pause = Math.min(this.pause * 2, this.retry.max);
                return;
            }
            this.pause = this.retry.first;
            this.items.shift();
            this.#save();
        }
        this.busy = false;
        for (const resolve of this.waiting.splice(0)) resolve();
    }

    #save() {
        this.store?.save(this.items);
    }
}
