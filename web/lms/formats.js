// The value formats the SCORM data models and xAPI ask for: time spans, timestamps and
// identifiers. Pure functions, so Node tests them as the browser runs them.

const pad = (n, width = 2) => String(n).padStart(width, "0");

/** Whole hundredths of a second in `ms` (never negative), so the parts below add up exactly. */
function hundredths(ms) {
    return Math.max(0, Math.round((Number(ms) || 0) / 10));
}

/** SCORM 1.2's CMITimespan, `HHHH:MM:SS.SS`; the hours stop at four digits as the format does. */
export function cmiTimespan(ms) {
    const cs = Math.min(hundredths(ms), (10000 * 3600 - 1) * 100 + 99);
    const hours = Math.floor(cs / 360000);
    const minutes = Math.floor(cs / 6000) % 60;
    const seconds = Math.floor(cs / 100) % 60;
    return `${pad(hours, 4)}:${pad(minutes)}:${pad(seconds)}.${pad(cs % 100)}`;
}

/**
 * An ISO 8601 duration as SCORM 2004's timeinterval (second, 10, 2) and xAPI read it:
 * `PT1H2M3.45S`, hundredths at most, `PT0S` for nothing.
 */
export function isoDuration(ms) {
    const cs = hundredths(ms);
    const hours = Math.floor(cs / 360000);
    const minutes = Math.floor(cs / 6000) % 60;
    const seconds = (cs % 6000) / 100;
    let text = "PT";
    if (hours) text += `${hours}H`;
    if (minutes) text += `${minutes}M`;
    if (seconds || text === "PT") text += `${Number(seconds.toFixed(2))}S`;
    return text;
}

/** SCORM 1.2's CMITime: the local time of day, `HH:MM:SS`. */
export function cmiTimeOfDay(date) {
    return `${pad(date.getHours())}:${pad(date.getMinutes())}:${pad(date.getSeconds())}`;
}

/**
 * SCORM 2004's time (second, 10, 0): `YYYY-MM-DDThh:mm:ss.ssZ` in UTC. The zone may only follow
 * a fraction of a second in its format, so the hundredths are always written.
 */
export function scormTimestamp(date) {
    const iso = date.toISOString(); // YYYY-MM-DDThh:mm:ss.sssZ
    return `${iso.slice(0, 22)}Z`;
}

/**
 * A name as an identifier without spaces that both SCORM versions and URIs accept: ASCII
 * letters and digits kept (lowercased), runs of anything else as `-`, and letters outside ASCII
 * percent-encoded so that names in any script stay distinct. At most `max` characters.
 */
export function identifier(name, max = 250) {
    let text = "";
    for (const ch of String(name ?? "").toLowerCase()) {
        if (/[a-z0-9]/.test(ch)) text += ch;
        else if (/[\p{L}\p{N}]/u.test(ch)) text += encodeURIComponent(ch);
        else if (!text.endsWith("-")) text += "-";
    }
    text = text.replace(/^-+|-+$/g, "");
    if (text.length > max) {
        // Never cut inside a %XX escape.
        text = text.slice(0, max).replace(/%[0-9A-F]?$/, "").replace(/-+$/, "");
    }
    return text || "structure";
}

/** `text` cut to `max` characters (code points, so no character is split). */
export function clip(text, max) {
    const chars = Array.from(String(text ?? ""));
    return chars.length > max ? chars.slice(0, max).join("") : chars.join("");
}

/**
 * Language tags as the viewer's `?lang=` takes them (`de` or `de-CH,fr`): only well-formed
 * BCP 47 tags from a comma-separated list, or null when none is.
 */
export function languageList(text) {
    const tags = String(text ?? "")
        .split(",")
        .map((t) => t.trim())
        .filter((t) => /^[A-Za-z]{2,3}(-[A-Za-z0-9]{1,8})*$/.test(t));
    return tags.length ? tags.join(",") : null;
}
