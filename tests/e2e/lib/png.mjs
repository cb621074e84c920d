// Reads the PNG screenshots Chromium writes (8-bit greyscale, RGB or RGBA, not interlaced), so
// the tests can look at pixels without an image package.
import { inflateSync } from "node:zlib";

const SIGNATURE = Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
const CHANNELS = { 0: 1, 2: 3, 4: 2, 6: 4 };

/** Decodes a PNG into `{width, height, rgba}` (4 bytes per pixel, row by row). */
export function decodePng(bytes) {
    if (!bytes.subarray(0, 8).equals(SIGNATURE)) {
        throw new Error("not a PNG file");
    }
    let width = 0;
    let height = 0;
    let channels = 0;
    const idat = [];
    for (let at = 8; at < bytes.length; ) {
        const length = bytes.readUInt32BE(at);
        const type = bytes.toString("latin1", at + 4, at + 8);
        const data = bytes.subarray(at + 8, at + 8 + length);
        if (type === "IHDR") {
            width = data.readUInt32BE(0);
            height = data.readUInt32BE(4);
            const [depth, colourType, , , interlace] = data.subarray(8, 13);
            channels = CHANNELS[colourType];
            if (depth !== 8 || !channels || interlace !== 0) {
                throw new Error(`unsupported PNG: bit depth ${depth}, colour type ${colourType}, interlace ${interlace}`);
            }
        } else if (type === "IDAT") {
            idat.push(data);
        } else if (type === "IEND") {
            break;
        }
        at += 12 + length;
    }
    const raw = inflateSync(Buffer.concat(idat));
    const stride = width * channels;
    const pixels = Buffer.alloc(stride * height);
    for (let y = 0; y < height; y++) {
        const filter = raw[y * (stride + 1)];
        const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
        const out = pixels.subarray(y * stride, (y + 1) * stride);
        const above = y > 0 ? pixels.subarray((y - 1) * stride, y * stride) : Buffer.alloc(stride);
        for (let i = 0; i < stride; i++) {
            const a = i >= channels ? out[i - channels] : 0;
            const b = above[i];
            const c = i >= channels ? above[i - channels] : 0;
            let predictor = 0;
            if (filter === 1) predictor = a;
            else if (filter === 2) predictor = b;
            else if (filter === 3) predictor = (a + b) >> 1;
            else if (filter === 4) predictor = paeth(a, b, c);
            else if (filter !== 0) throw new Error(`bad PNG filter ${filter} on row ${y}`);
            out[i] = (line[i] + predictor) & 0xff;
        }
    }
    const rgba = Buffer.alloc(width * height * 4);
    for (let p = 0; p < width * height; p++) {
        const s = p * channels;
        const grey = channels <= 2;
        rgba[p * 4] = pixels[s];
        rgba[p * 4 + 1] = grey ? pixels[s] : pixels[s + 1];
        rgba[p * 4 + 2] = grey ? pixels[s] : pixels[s + 2];
        rgba[p * 4 + 3] = channels === 4 ? pixels[s + 3] : channels === 2 ? pixels[s + 1] : 255;
    }
    return { width, height, rgba };
}

function paeth(a, b, c) {
    const p = a + b - c;
    const pa = Math.abs(p - a);
    const pb = Math.abs(p - b);
    const pc = Math.abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/** The colour at (x, y) as a number 0xRRGGBB. */
export function colourAt(image, x, y) {
    const i = (y * image.width + x) * 4;
    return (image.rgba[i] << 16) | (image.rgba[i + 1] << 8) | image.rgba[i + 2];
}

/** How many pixels of each colour (0xRRGGBB) the rectangle holds, most frequent first. */
export function colourHistogram(image, { x0 = 0, y0 = 0, x1 = image.width, y1 = image.height } = {}) {
    const counts = new Map();
    for (let y = y0; y < y1; y++) {
        for (let x = x0; x < x1; x++) {
            const c = colourAt(image, x, y);
            counts.set(c, (counts.get(c) ?? 0) + 1);
        }
    }
    return [...counts.entries()].sort((p, q) => q[1] - p[1]);
}

/**
 * Filled rectangles of one flat colour in a band of the image (the look of an egui button: a
 * flat fill with its label inside), left to right. The band's most common colour is the
 * background and is skipped; so are thin lines (separators) and small blobs (glyphs).
 */
export function flatBoxes(image, { y0 = 0, y1 = image.height, minWidth = 24, minHeight = 12, minFill = 0.5 } = {}) {
    const histogram = colourHistogram(image, { y0, y1 });
    const background = histogram[0][0];
    const seen = new Uint8Array(image.width * (y1 - y0));
    const boxes = [];
    for (const [colour, count] of histogram) {
        if (colour === background || count < minWidth * minHeight * minFill) {
            continue;
        }
        for (let y = y0; y < y1; y++) {
            for (let x = 0; x < image.width; x++) {
                const k = (y - y0) * image.width + x;
                if (seen[k] || colourAt(image, x, y) !== colour) continue;
                // Flood fill (4-connected) this colour's component.
                let [minX, maxX, minY, maxY, pixels] = [x, x, y, y, 0];
                const stack = [[x, y]];
                seen[k] = 1;
                while (stack.length) {
                    const [px, py] = stack.pop();
                    pixels++;
                    minX = Math.min(minX, px);
                    maxX = Math.max(maxX, px);
                    minY = Math.min(minY, py);
                    maxY = Math.max(maxY, py);
                    for (const [nx, ny] of [[px + 1, py], [px - 1, py], [px, py + 1], [px, py - 1]]) {
                        if (nx < 0 || nx >= image.width || ny < y0 || ny >= y1) continue;
                        const nk = (ny - y0) * image.width + nx;
                        if (!seen[nk] && colourAt(image, nx, ny) === colour) {
                            seen[nk] = 1;
                            stack.push([nx, ny]);
                        }
                    }
                }
                const width = maxX - minX + 1;
                const height = maxY - minY + 1;
                if (width >= minWidth && height >= minHeight && pixels >= minFill * width * height) {
                    boxes.push({ x: minX, y: minY, width, height, colour, pixels });
                }
            }
        }
    }
    return boxes.sort((a, b) => a.x - b.x);
}

/**
 * Throws unless the screenshot shows something: a blank or single-colour canvas (a failed
 * WebGPU/WebGL capture) has very few colours.
 */
export function assertNotBlank(image, what) {
    const histogram = colourHistogram(image);
    const total = image.width * image.height;
    const background = histogram[0][1] / total;
    if (histogram.length < 16 || background > 0.995) {
        throw new Error(
            `${what}: the screenshot looks blank (${histogram.length} colours, ` +
                `${(background * 100).toFixed(1)} % one colour #${histogram[0][0].toString(16).padStart(6, "0")})`,
        );
    }
}
