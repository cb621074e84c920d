// Headless Chromium (Debian's, driven by playwright-core) in the two modes the app must work in.
import { existsSync } from "node:fs";
import { chromium } from "./deps.mjs";

/** Flags shared by both modes: no network chatter of the browser's own, no first-run UI. */
const COMMON_FLAGS = [
    "--no-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
];

/**
 * `webgpu`: WebGPU on SwiftShader, with a canvas that screenshots capture (docs/TOOLCHAIN.md:
 * other flag sets compute but capture a blank canvas). `cpu`: no WebGPU, so eframe renders with
 * WebGL2 and the app smooths with its CPU engine.
 */
export const MODES = {
    webgpu: {
        flags: [
            "--enable-unsafe-webgpu",
            "--enable-features=Vulkan",
            "--use-vulkan=swiftshader",
            "--use-angle=vulkan",
            ...COMMON_FLAGS,
        ],
        backend: "webgpu",
    },
    cpu: { flags: COMMON_FLAGS, backend: "cpu" },
};

export function modeFromEnv() {
    const mode = process.env.E2E_MODE ?? "webgpu";
    if (!MODES[mode]) {
        throw new Error(`E2E_MODE=${mode}: expected one of ${Object.keys(MODES).join(", ")}`);
    }
    return mode;
}

const CHROMIUM_CANDIDATES = ["/usr/bin/chromium", "/usr/lib/chromium/chromium"];

/**
 * Starts headless Chromium for `mode`. Playwright gives every launch a fresh temporary
 * --user-data-dir, so no profile state (caches, storage, GPU shader cache) carries over.
 */
export async function launchBrowser(mode) {
    const executablePath = process.env.CHROMIUM ?? CHROMIUM_CANDIDATES.find((p) => existsSync(p));
    if (!executablePath) {
        throw new Error(`no Chromium at ${CHROMIUM_CANDIDATES.join(" or ")} (apt-get install chromium), or set CHROMIUM`);
    }
    return chromium.launch({
        executablePath,
        headless: true,
        args: MODES[mode].flags,
        timeout: 60_000,
    });
}
