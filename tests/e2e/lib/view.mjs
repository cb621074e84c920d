// Reading the 3D view in a screenshot: which pixels show a surface, and which changed.

/** Whether (x, y) lies on the orientation marker, in the view's top-right corner. */
export const onMarker = (x, y, view) => x > view.x + view.width - 100 && y < view.y + 100;

/**
 * The pixels of the 3D view that show a surface: unlike the background (read at the view's
 * top-right corner), away from the messages at its top, the orientation marker and its tools
 * at its bottom. Returns their count and mean x (CSS pixels).
 */
export function drawn(image, view) {
    const at = (x, y) => {
        const i = (Math.round(y) * image.width + Math.round(x)) * 4;
        return [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
    };
    const background = at(view.x + view.width - 4, view.y + 4);
    let count = 0;
    let sumX = 0;
    for (let y = Math.round(view.y + 60); y < Math.round(view.y + view.height - 40); y++) {
        for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) {
            const c = at(x, y);
            if (onMarker(x, y, view)) continue;
            if (c.some((v, k) => Math.abs(v - background[k]) > 24)) {
                count++;
                sumX += x;
            }
        }
    }
    return { count, meanX: count ? sumX / count : NaN };
}

/** Pixels of the view (away from its messages, marker and tools) that differ between two images. */
export function changedPixels(a, b, view) {
    let count = 0;
    for (let y = Math.round(view.y + 60); y < Math.round(view.y + view.height - 40); y++) {
        for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) {
            const i = (y * a.width + x) * 4;
            if (onMarker(x, y, view)) continue;
            if ([0, 1, 2].some((k) => Math.abs(a.rgba[i + k] - b.rgba[i + k]) > 16)) count++;
        }
    }
    return count;
}

/**
 * Across the rows within `rows` pixels of the view's centre: the mean colour step between
 * neighbouring surface pixels (sum over red, green and blue; a flat face has almost none,
 * relief and rings have more), and the background pixels lying between a row's first and last
 * surface pixel (holes in what is drawn).
 */
export function roughnessAcross(image, view, rows = 20) {
    const at = (x, y) => {
        const i = (y * image.width + x) * 4;
        return [image.rgba[i], image.rgba[i + 1], image.rgba[i + 2]];
    };
    const background = at(Math.round(view.x + view.width - 4), Math.round(view.y + 4));
    const surface = (c) => c.some((v, k) => Math.abs(v - background[k]) > 24);
    const centre = Math.round(view.y + view.height / 2);
    let steps = 0;
    let pairs = 0;
    let holes = 0;
    for (let y = centre - rows; y <= centre + rows; y++) {
        const row = [];
        for (let x = Math.round(view.x); x < Math.round(view.x + view.width); x++) row.push(at(x, y));
        const first = row.findIndex(surface);
        const last = row.findLastIndex(surface);
        for (let x = first; first >= 0 && x < last; x++) {
            const [a, b] = [row[x], row[x + 1]];
            if (!surface(a)) holes++;
            if (surface(a) && surface(b)) {
                steps += a.reduce((sum, v, k) => sum + Math.abs(v - b[k]), 0);
                pairs++;
            }
        }
    }
    return { step: pairs ? steps / pairs : NaN, pairs, holes };
}
