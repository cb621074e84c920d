// Where things are: the checkout, the shared test meshes beside it, the built page, the CLI and
// the output folder of this run.
import { mkdirSync } from "node:fs";
import { isAbsolute, join, resolve } from "node:path";

export const ROOT = resolve(import.meta.dirname, "../../..");
export const DATA = resolve(process.env.E2E_DATA ?? join(ROOT, "../shared/data"));
export const DIST = resolve(process.env.E2E_DIST ?? join(ROOT, "dist"));
/** The student's viewer, built beside the app (web/build_viewer.sh): what a package carries. */
export const VIEWER_DIST = join(DIST, "viewer");

/** The native CLI that `cargo build --release` made (honours CARGO_TARGET_DIR). */
export function cliPath() {
    if (process.env.MESHSMOOTH_CLI) {
        return resolve(process.env.MESHSMOOTH_CLI);
    }
    const target = process.env.CARGO_TARGET_DIR ?? "target";
    return join(isAbsolute(target) ? target : join(ROOT, target), "release", "meshsmooth");
}

/** target/e2e/<mode>/, created on first use: screenshots and exported files of the run. */
export function outputDir(mode) {
    const dir = join(ROOT, "target", "e2e", mode);
    mkdirSync(dir, { recursive: true });
    return dir;
}

export const E2E_OUT = join(ROOT, "target", "e2e");

export function meshPath(relative) {
    return join(DATA, relative);
}
