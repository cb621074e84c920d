// The native CLI as the reference: the web app must report what `meshsmooth ... --json` reports.
import { execFile } from "node:child_process";
import { existsSync } from "node:fs";
import { promisify } from "node:util";
import { cliPath } from "./paths.mjs";

const run = promisify(execFile);

/** The embedding API's parameter names and the CLI's flags for them. */
const PARAM_FLAGS = {
    lambda: "--lambda",
    mu: "--mu",
    alpha: "--alpha",
    beta: "--beta",
    passband: "--passband",
    iterations: "--iterations",
    max_displacement: "--max-displacement",
};

export function requireCli() {
    const cli = cliPath();
    if (!existsSync(cli)) {
        throw new Error(`the CLI is missing at ${cli}: run \`cargo build --release\` (tests/e2e/run.sh does)`);
    }
    return cli;
}

/** Runs the CLI; resolves with stdout, rejects with an Error carrying its stderr. */
export function cli(...args) {
    return cliWithEnv({}, ...args);
}

/** `cli` with environment variables added (e.g. `RAYON_NUM_THREADS`). */
export async function cliWithEnv(env, ...args) {
    try {
        const options = { maxBuffer: 64 << 20, env: { ...process.env, ...env } };
        const { stdout } = await run(requireCli(), args, options);
        return stdout;
    } catch (e) {
        const error = new Error(`meshsmooth ${args.join(" ")} failed (exit ${e.code}): ${String(e.stderr).trim()}`);
        error.stderr = String(e.stderr ?? "");
        error.exitCode = e.code;
        throw error;
    }
}

export async function cliJson(...args) {
    return JSON.parse(await cli(...args));
}

/** `meshsmooth info FILE --json`. */
export function info(file) {
    return cliJson("info", file, "--json");
}

/** The CLI arguments for the API's parameter object. */
export function paramArgs(params) {
    return Object.entries(params).flatMap(([key, value]) => {
        const flag = PARAM_FLAGS[key];
        if (!flag) {
            throw new Error(`no CLI flag for the parameter '${key}'`);
        }
        return [flag, String(value)];
    });
}

/** `meshsmooth smooth FILE -o OUT --filter F ... --json`: `{filter, params, seconds, metrics}`. */
export function smooth(file, output, filter, params) {
    return cliJson("smooth", file, "-o", output, "--filter", filter, ...paramArgs(params), "--json");
}

/** The CLI's message for a refused command, without its `meshsmooth: error: ` prefix. */
export async function refusal(...args) {
    try {
        await cli(...args);
    } catch (e) {
        return e.stderr.trim().replace(/^meshsmooth: error: /, "");
    }
    throw new Error(`meshsmooth ${args.join(" ")} succeeded; expected a refusal`);
}
