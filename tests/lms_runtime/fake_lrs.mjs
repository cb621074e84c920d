// A cmi5 LMS as the runtime sees it through `fetch`: the one-time token URL, the record store's
// statements, state documents and agent profiles, with an outage the test can switch on.

export const ENDPOINT = "https://lrs.example/xapi/";
export const FETCH_URL = "https://lms.example/cmi5/token?k=2390289x0";
export const ACTOR = { objectType: "Agent", account: { homePage: "https://lms.example", name: "1625378" } };
export const REGISTRATION = "760e3480-ba55-4991-94b0-01820dbd23a2";
export const ACTIVITY_ID = "https://lms.example/course/7/au/case-lesson";
export const SESSION_ID = "0b5e9c4b-5f5e-4a39-8d6e-7d8a6b3c8a11";
export const PUBLISHER_ID = "urn:meshsmooth:package:abdominal-phantom";
export const TOKEN = "QWxhZGRpbjpvcGVuIHNlc2FtZQ==";

/** The page's query string as the LMS launches it. */
export function launchQuery() {
    const query = new URLSearchParams({ endpoint: ENDPOINT, fetch: FETCH_URL, actor: JSON.stringify(ACTOR), registration: REGISTRATION, activityId: ACTIVITY_ID });
    return `?${query}`;
}

/** The LMS.LaunchData document, with `overrides`. */
export function launchData(overrides = {}) {
    return {
        contextTemplate: {
            contextActivities: { grouping: [{ objectType: "Activity", id: PUBLISHER_ID }] },
            extensions: { "https://w3id.org/xapi/cmi5/context/extensions/sessionid": SESSION_ID },
        },
        launchMode: "Normal",
        moveOn: "CompletedAndPassed",
        returnURL: "https://lms.example/course/7",
        ...overrides,
    };
}

const json = (status, body) => new Response(body === undefined ? null : JSON.stringify(body), { status, headers: { "Content-Type": "application/json" } });

/**
 * The LMS. `documents`: the state documents by stateId; `profile`: the learner preferences.
 * `lms.outage = (request) => null | "network" | status` fails the requests it picks.
 */
export function fakeLms({ documents = {}, profile = null } = {}) {
    const lms = {
        statements: [],
        requests: [],
        tokenCalls: 0,
        documents: new Map(Object.entries({ "LMS.LaunchData": launchData(), ...documents })),
        outage: () => null,
        async fetch(url, init = {}) {
            const method = init.method ?? "GET";
            const headers = init.headers ?? {};
            const request = { url, method, headers, keepalive: init.keepalive === true, body: init.body };
            lms.requests.push(request);
            if (url === FETCH_URL) {
                lms.tokenCalls++;
                if (method !== "POST") return json(405, {});
                return json(200, lms.tokenCalls === 1 ? { "auth-token": TOKEN } : { "error-code": "1", "error-text": "The authorization token has already been returned." });
            }
            const failure = lms.outage(request);
            if (failure === "network") throw new TypeError("Failed to fetch");
            if (failure) return json(failure, { error: "unavailable" });
            if (headers.Authorization !== `Basic ${TOKEN}` || headers["X-Experience-API-Version"] !== "1.0.3") return json(401, {});
            const parsed = new URL(url);
            const params = parsed.searchParams;
            if (parsed.pathname === "/xapi/statements" && method === "POST") {
                if (headers["Content-Type"] !== "application/json") return json(400, {});
                const statement = JSON.parse(init.body);
                if (lms.statements.some((s) => s.id === statement.id)) return json(409, {});
                lms.statements.push(statement);
                return json(200, [statement.id]);
            }
            const agentMatches = params.get("agent") === JSON.stringify(ACTOR);
            if (parsed.pathname === "/xapi/activities/state") {
                const scoped = agentMatches && params.get("activityId") === ACTIVITY_ID && params.get("registration") === REGISTRATION;
                if (!scoped) return json(404);
                const id = params.get("stateId");
                if (method === "PUT") {
                    if (id === "LMS.LaunchData") return json(403, {});
                    lms.documents.set(id, JSON.parse(init.body));
                    return json(204);
                }
                return lms.documents.has(id) ? json(200, lms.documents.get(id)) : json(404);
            }
            if (parsed.pathname === "/xapi/agents/profile" && params.get("profileId") === "cmi5LearnerPreferences") {
                return agentMatches && profile ? json(200, profile) : json(404);
            }
            return json(400, {});
        },
    };
    return lms;
}

/** The page's sessionStorage. */
export function memoryStorage() {
    const items = new Map();
    return {
        items,
        getItem: (k) => (items.has(k) ? items.get(k) : null),
        setItem: (k, v) => items.set(k, String(v)),
        removeItem: (k) => items.delete(k),
    };
}
