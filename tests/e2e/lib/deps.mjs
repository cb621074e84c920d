// The npm packages of the tests live in web/node_modules (web/package.json, installed by
// `npm ci` in .ci/install.sh), not beside these files: resolve them from there.
import { createRequire } from "node:module";

const require = createRequire(new URL("../../../web/package.json", import.meta.url));

/** playwright-core: drives Debian's chromium; it never downloads a browser. */
export const { chromium } = require("playwright-core");

/** The Khronos glTF-Validator, compiled to JavaScript. */
export const gltfValidator = require("gltf-validator");
