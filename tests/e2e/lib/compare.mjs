// Comparing what the web app reports with what the CLI reports, with float tolerances.

/** Relative difference of two numbers, measured against `max(|expected|, scale)`. */
export function relativeDifference(actual, expected, scale = 0) {
    const denominator = Math.max(Math.abs(expected), scale);
    return denominator === 0 ? Math.abs(actual - expected) : Math.abs(actual - expected) / denominator;
}

/**
 * Compares two JSON values: the same keys, booleans, strings and nulls; numbers within `rtol`
 * relative (for counts below 1e9 and rtol <= 1e-9 that is equality); numbers under a key of
 * `f32Keys` equal once rounded to f32. Returns the differences as readable lines (none: equal).
 */
export function jsonDifferences(actual, expected, rtol, { f32Keys = [] } = {}, path = "", asF32 = false) {
    const where = path || "(top)";
    if (expected === null || typeof expected !== "object") {
        if (typeof expected === "number" && typeof actual === "number") {
            if (asF32) {
                return Math.fround(actual) === Math.fround(expected) ? [] : [`${where}: ${actual}, expected ${expected} (different as f32)`];
            }
            const d = relativeDifference(actual, expected);
            return d <= rtol ? [] : [`${where}: ${actual}, expected ${expected} (relative difference ${d.toExponential(2)} > ${rtol})`];
        }
        return actual === expected ? [] : [`${where}: ${JSON.stringify(actual)}, expected ${JSON.stringify(expected)}`];
    }
    if (Array.isArray(expected)) {
        if (!Array.isArray(actual) || actual.length !== expected.length) {
            return [`${where}: ${JSON.stringify(actual)}, expected ${JSON.stringify(expected)}`];
        }
        return expected.flatMap((e, i) => jsonDifferences(actual[i], e, rtol, { f32Keys }, `${path}[${i}]`, asF32));
    }
    if (actual === null || typeof actual !== "object") {
        return [`${where}: ${JSON.stringify(actual)}, expected an object`];
    }
    const missing = Object.keys(expected).filter((k) => !(k in actual));
    const extra = Object.keys(actual).filter((k) => !(k in expected));
    const lines = [];
    if (missing.length) lines.push(`${where}: missing keys ${missing.join(", ")}`);
    if (extra.length) lines.push(`${where}: unexpected keys ${extra.join(", ")}`);
    for (const key of Object.keys(expected)) {
        if (key in actual) {
            const keyPath = path ? `${path}.${key}` : key;
            lines.push(...jsonDifferences(actual[key], expected[key], rtol, { f32Keys }, keyPath, asF32 || f32Keys.includes(key)));
        }
    }
    return lines;
}

/**
 * The measures that are ratios near zero (volume_change) or scores of order one are compared
 * against a scale of 1 rather than their own size: a 1e-7 relative change of the volume moves
 * volume_change by about 1e-7 whatever its value, so "relative to itself" would demand more
 * precision from it than from the volume it comes from.
 */
const METRIC_SCALES = { volume_change: 1, score: 1 };

/**
 * Compares the app's metrics with the CLI's. Every key of the CLI's object must be there; the
 * result lists the differences above `rtol` and, for the report, each key's relative difference.
 */
export function metricDifferences(actual, expected, rtol) {
    const problems = [];
    const differences = {};
    for (const [key, e] of Object.entries(expected)) {
        if (!(key in actual)) {
            problems.push(`${key}: missing`);
            continue;
        }
        const a = actual[key];
        if (e === null || a === null) {
            if (a !== e) problems.push(`${key}: ${a}, expected ${e}`);
            continue;
        }
        if (typeof a !== "number" || !Number.isFinite(a)) {
            problems.push(`${key}: ${JSON.stringify(a)}, expected the number ${e}`);
            continue;
        }
        const d = relativeDifference(a, e, METRIC_SCALES[key] ?? 0);
        differences[key] = d;
        if (d > rtol) {
            problems.push(`${key}: ${a}, expected ${e} (relative difference ${d.toExponential(2)} > ${rtol})`);
        }
    }
    return { problems, differences };
}
