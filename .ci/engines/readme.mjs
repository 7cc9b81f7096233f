// docs/engines.md's "Use a lobe in three.js" and "Use a lobe in Babylon.js" (the README's tour
// points there), run as printed: each
// section's shell command writes the module (with the binary checked), its JavaScript runs as
// a page's module beside it (an import map gives it the packages, a canvas is on the page), and
// the page must log no error, draw a lit object, and change its image as the snippet sweeps n
// through the uniform. The page makes its WebGL canvas keep its frames (preserveDrawingBuffer)
// so that they can be read; the snippet's text is not touched.
// Usage: node .ci/engines/readme.mjs SPECULA_BIN
import { readFile } from "node:fs/promises";
import * as lib from "./lib.mjs";

const BIN = process.argv[2];
if (!BIN) { console.error("usage: node .ci/engines/readme.mjs SPECULA_BIN"); process.exit(2); }
const readme = await readFile(new URL("../../docs/engines.md", import.meta.url), "utf8");

// The first ```sh and ```js blocks after `heading`.
function section(heading) {
  const rest = readme.split(`\n${heading}\n`)[1];
  if (!rest) throw new Error(`docs/engines.md has no section "${heading}"`);
  const block = (language) => rest.split("\n```" + language + "\n")[1]?.split("\n```")[0];
  return { sh: block("sh"), js: block("js") };
}

const IMPORTS = JSON.stringify({ imports: {
  three: "/node_modules/three/build/three.module.js",
  "three/webgpu": "/node_modules/three/build/three.webgpu.js",
  "three/tsl": "/node_modules/three/build/three.tsl.js",
  "@babylonjs/core/": "/node_modules/@babylonjs/core/",
} });
const KEEP_FRAMES = `const getContext = HTMLCanvasElement.prototype.getContext;
HTMLCanvasElement.prototype.getContext = function (kind, options = {}) {
  return getContext.call(this, kind, kind.startsWith("webgl") ? { ...options, preserveDrawingBuffer: true } : options);
};`;

const work = await lib.workDir();
const failures = [];
const browser = await lib.launchChromium("README engines check");
const { server, url } = await lib.startServer(work);
try {
  for (const [name, heading] of [["three", "## Use a lobe in three.js"], ["babylon", "## Use a lobe in Babylon.js"]]) {
    const { sh, js } = section(heading);
    if (!sh || !js) { failures.push(`${heading}: no sh or js block`); continue; }
    for (const line of sh.split("\n").filter((l) => l.trim() && !l.startsWith("#"))) {
      const [command, ...args] = line.trim().split(/\s+/);
      if (command !== "specula") { failures.push(`${heading}: not a specula command: ${line}`); continue; }
      await lib.run(BIN, args, { cwd: work });
    }
    await lib.writeFile(lib.join(work, `${name}.mjs`), js);
    await lib.writeFile(lib.join(work, `${name}.html`), `<!doctype html><html><head><meta charset="utf-8"></head><body>
<canvas width="256" height="256"></canvas>
<script>${KEEP_FRAMES}</script>
<script type="importmap">${IMPORTS}</script>
<script type="module" src="/work/${name}.mjs"></script>
</body></html>`);
    const page = await browser.newPage();
    const errors = [];
    page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
    page.on("pageerror", (e) => errors.push(e.message));
    await page.goto(`${url}/work/${name}.html`);
    // Two frames some time apart: n has moved between them.
    const frame = () => page.evaluate(() => {
      const canvas = document.querySelector("canvas");
      const copy = Object.assign(document.createElement("canvas"), { width: canvas.width, height: canvas.height });
      const g = copy.getContext("2d");
      g.drawImage(canvas, 0, 0);
      return Array.from(g.getImageData(0, 0, copy.width, copy.height).data);
    });
    await page.waitForTimeout(3000);
    const first = await frame();
    await page.waitForTimeout(700);
    const second = await frame();
    await page.close();
    // The object: pixels unlike the corner's (the clear colour).
    const lit = first.filter((v, k) => k % 4 !== 3 && Math.abs(v - first[k % 4]) > 8).length / (first.length * 0.75);
    const changed = first.filter((v, k) => Math.abs(v - second[k]) > 2).length;
    console.log(`${heading}: ran as printed; ${(100 * lit).toFixed(1)} % of the channels unlike the background, ${changed} changed as n moved; ${errors.length} errors`);
    if (errors.length) failures.push(`${heading}: the page logged ${errors[0]}`);
    if (lit < 0.02) failures.push(`${heading}: the canvas shows nothing but its background`);
    if (changed === 0) failures.push(`${heading}: the image did not change as n moved`);
  }
} catch (error) {
  failures.push(error.message.split("\n")[0]);
} finally {
  await browser.close();
  server.close();
}
for (const f of failures) console.error(`FAIL ${f}`);
process.exit(failures.length ? 1 : 0);
