// The cmi5 LMS's record store as xAPI reaches it: the one-time token, state documents, agent
// profiles and statements, each request with the token and the xAPI version it speaks.

const XAPI_VERSION = "1.0.3";

/** A failed request: its HTTP status (0 without an answer), and whether trying again may help. */
export class RequestError extends Error {
    constructor(what, status) {
        super(`${what}: ${status ? `HTTP ${status}` : "no answer"}`);
        this.status = status;
        this.transient = status === 0 || status >= 500 || status === 408 || status === 429;
    }
}

export class RecordStore {
    /** `launch`: from `cmi5Launch`; `retry`: the first and the longest pause between tries. */
    constructor(launch, { fetch, timers = globalThis, retry = { first: 1000, max: 60000 }, log = console }) {
        Object.assign(this, { launch, fetch, timers, retry, log });
    }

    /** Posts to the token URL, which answers once per launch: the caller keeps the token. */
    async fetchToken() {
        let response;
        try {
            response = await this.fetch(this.launch.fetchUrl, { method: "POST" });
        } catch {
            throw new RequestError("the token URL", 0);
        }
        const body = await response.json().catch(() => ({}));
        if (!response.ok || typeof body["auth-token"] !== "string") {
            throw new Error(`the token URL gave no token: ${body["error-text"] ?? `HTTP ${response.status}`}`);
        }
        return body["auth-token"];
    }

    /** State document `stateId` of this unit, student and registration (undefined if none). */
    state(stateId, token, options) {
        return this.#getJson(`the ${stateId} document`, this.stateUrl(stateId), token, options);
    }

    /** Agent profile `profileId` of the student (undefined if none). */
    profile(profileId, token, options) {
        const url = `${this.launch.endpoint}agents/profile?${this.#query({ profileId })}`;
        return this.#getJson(`the ${profileId} profile`, url, token, options);
    }

    /**
     * Sends an outbox item (a statement to post, or a state document to put): "done" when the
     * store took it, or refused it for good (logged); "retry" when it could not answer.
     */
    async send(item, { keepalive }, token) {
        const headers = this.#headers(token, { "Content-Type": "application/json" });
        const [url, init] =
            item.kind === "state"
                ? [this.stateUrl(item.stateId), { method: "PUT", headers, body: JSON.stringify(item.document), keepalive }]
                : [`${this.launch.endpoint}statements`, { method: "POST", headers, body: JSON.stringify(item.statement), keepalive }];
        let response;
        try {
            response = await this.fetch(url, init);
        } catch {
            return "retry";
        }
        // 409: the store has this statement already (sent before a reload).
        if (response.ok || (item.kind === "statement" && response.status === 409)) return "done";
        const what = item.kind === "state" ? `the ${item.stateId} document` : `the ${item.statement.verb?.display?.["en-US"] ?? ""} statement`;
        const error = new RequestError(what, response.status);
        if (error.transient) return "retry";
        this.log.warn(`cmi5: the record store refused ${error.message}`);
        return "done";
    }

    stateUrl(stateId) {
        const { activityId, registration } = this.launch;
        return `${this.launch.endpoint}activities/state?${this.#query({ stateId, activityId, registration })}`;
    }

    #query(params) {
        return new URLSearchParams({ ...params, agent: JSON.stringify(this.launch.actor) }).toString();
    }

    #headers(token, extra = {}) {
        return { Authorization: `Basic ${token}`, "X-Experience-API-Version": XAPI_VERSION, ...extra };
    }

    /** A JSON document, undefined where there is none (404); up to `tries` tries through outages. */
    async #getJson(what, url, token, { tries = 1 } = {}) {
        let pause = this.retry.first;
        for (let tried = 1; ; tried++) {
            try {
                let response;
                try {
                    response = await this.fetch(url, { headers: this.#headers(token) });
                } catch {
                    throw new RequestError(what, 0);
                }
                if (response.status === 404) return undefined;
                if (!response.ok) throw new RequestError(what, response.status);
                return await response.json();
            } catch (error) {
                if (tried >= tries || !error.transient) throw error;
                await new Promise((resolve) => this.timers.setTimeout(resolve, pause));
                pause = Math.min(pause * 2, this.retry.max);
            }
        }
    }
}
