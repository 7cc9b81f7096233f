// specula's lobes dropped into three.js (WebGLRenderer on WebGL2, WebGPURenderer with TSL) and
// Babylon.js (StandardMaterial + MaterialPluginBase), rendered by the engines themselves in
// headless Chromium (SwiftShader) and compared pixel by pixel with `specula render` of the same
// scene: one mesh file (a UV sphere and a torus with vertex normals) for every renderer, the
// same camera, lights and material, per-pixel Phong shading, one sample per pixel.
//   three.js  = specula's physical model: (kd C / pi + ks N(n) lobe(t)) (N.L) E
//   Babylon   = specula's classic model:  kd C (N.L) I + ks N(n) lobe(t) I
// Every built-in lobe (`specula models`, n = 64, both geometries, four normalisations across
// them), a formula lobe, and n changed at run time through the module's uniform (64 -> 100, no
// new program) are asserted; the engines' own pow materials and three's Fresnel with a
// coloured specular are printed beside them, not asserted.
// Usage: node .ci/engines/check.mjs SPECULA_BIN   (exit 1 with one line per failure)
import { cpus } from "node:os";
import * as lib from "./lib.mjs";

const BIN = process.argv[2];
if (!BIN) { console.error("usage: node .ci/engines/check.mjs SPECULA_BIN"); process.exit(2); }
const W = 256, H = 256, N = 64;

// Tolerances, per channel, relative to the peak of specula's image over the inner pixels (a
// pixel and its 8 neighbours covered in both images). The rasterizers snap vertices to their own
// sub-pixel grids (specula's 1/256 pixel, SwiftShader's its own), so interpolated normals differ
// by a little, which a highlight at n = 64 turns into more on its steep flanks (the differences
// alternate in sign around the highlights; there is no shift of the image): measured
// (Chromium 156, SwiftShader, 256 x 256, this scene), the largest difference of any lobe on any
// engine was 0.048 of the peak (fasterpow, whose bit tricks have kinks; the smooth lobes 0.025),
// at most 2.1 % of the inner channels differed by more than 0.2 % of the peak and 0.32 %
// by more than 1 %, and the image's total (the energy) by at most 0.08 %. The bounds leave
// about twice that; a wrong lobe, normalisation, geometry, Fresnel or light moves a highlight
// by tens of per cent of the peak, and the energy by per cents.
const MAX_DIFF = 0.1; // any single channel
const SHARE_AT = 1e-2; // a channel "differs" beyond this ...
const MAX_SHARE = 1e-2; // ... and at most this share of the inner channels may
const MAX_ENERGY = 2e-3; // |sum of the engine's inner channels / specula's - 1|

const failures = [];
const fail = (line) => { failures.push(line); };
const fmt = (x) => (x === 0 ? "0" : Math.abs(x) >= 0.01 && Math.abs(x) < 1000 ? x.toFixed(4) : x.toExponential(2));

const work = await lib.workDir();
const mesh = lib.buildMesh();
await lib.writeFile(lib.join(work, "mesh.obj"), lib.objText(mesh));
await lib.writeFile(lib.join(work, "mesh.json"), JSON.stringify(mesh));

// ---- the cases ----
const NORMS = ["none", "lobe", "lafortune", "blinn"];
const lobes = await lib.builtInLobes(BIN);
const cases = lobes.map((lobe, i) => ({ name: lobe, lobe, n: N, geometry: i % 2 ? "blinn" : "phong",
  normalisation: NORMS[Math.floor(i / 2) % NORMS.length] }));
cases.push({ name: "formula", lobe: "=exp2(n * (t - 1) * 1.4427)", n: N, geometry: "phong",
  normalisation: "lobe" });
// n at run time: exported at 64, drawn, set to 100 through the uniform, drawn again (N(n) must
// follow n too: "lobe" normalisation)
cases.push({ name: "pow n=64->100", lobe: "pow", n: N, thenN: 100, geometry: "blinn", normalisation: "lobe" });
// the plain (N.H)^n, beside the engines' own materials and with three's Fresnel
const plain = { name: "pow blinn none", lobe: "pow", n: N, geometry: "blinn", normalisation: "none" };
cases.push(plain);
for (const [i, c] of cases.entries()) c.file = `case${i}`;

const material = (c, n = c.n) => ({ lobe: c.lobe, n, geometry: c.geometry, normalisation: c.normalisation });
const shader = (c, lang) => lib.run(BIN, ["shader", "--lang", lang, `--lobe=${c.lobe}`, "--n", String(c.n),
  "--geometry", c.geometry, "--normalisation", c.normalisation, "-o", lib.join(work, `${c.file}-${lang}.js`)]);
const render = async (name, scene) => {
  await lib.writeFile(lib.join(work, `${name}.toml`), lib.sceneToml({ W, H, ...scene }));
  await lib.run(BIN, ["render", lib.join(work, `${name}.toml`), "-o", lib.join(work, `${name}.exr`)]);
  return lib.readExr(lib.join(work, `${name}.exr`));
};

const t0 = Date.now();
const jobs = [];
const refs = {}; // name -> image
const job = (name, scene) => jobs.push(async () => { refs[name] = await render(name, scene); });
// coverage: ambient 1, ka 1, nothing else
job("mask", { model: "classic", ambient: [1, 1, 1], material: { ka: 1, kd: 0, ks: 0, colour: [1, 1, 1] } });
for (const c of cases) {
  jobs.push(() => shader(c, "threejs"), () => shader(c, "babylon"));
  for (const model of ["physical", "classic"]) {
    job(`${c.file}-${model}`, { model, material: material(c) });
    if (c.thenN) job(`${c.file}-${model}-then`, { model, material: material(c, c.thenN) });
  }
}
job("coloured-physical", { model: "physical", material: { ...material(plain), specular_colour: [0.04, 0.04, 0.04] } });
try {
  await lib.pool(jobs, Math.max(2, Math.min(4, cpus().length)));
} catch (e) {
  console.error(`engines check: FAIL: ${e.message.split("\n")[0]}`);
  process.exit(1);
}
console.log(`specula: ${cases.length} cases, ${Object.keys(refs).length} renders and ` +
  `${2 * cases.length} modules at ${W}x${H} in ${((Date.now() - t0) / 1000).toFixed(1)} s`);

// ---- comparison ----
const covered = refs.mask.rgb.map((x) => x > 0.5);
const maskAt = (i) => covered[i * 3];
// got: RGBA top first (engine); want: RGB top first (specula)
function compare(got, want) {
  const ok = new Uint8Array(W * H);
  for (let i = 0; i < W * H; i++) ok[i] = got[i * 4 + 3] > 0.5 && maskAt(i) ? 1 : 0;
  let inner = 0, peak = 0, max = 0, at = null, beyond = 0, engineOnly = 0, speculaOnly = 0;
  for (let i = 0; i < W * H; i++) {
    const e = got[i * 4 + 3] > 0.5, s = maskAt(i);
    if (e && !s) engineOnly++;
    if (s && !e) speculaOnly++;
  }
  const innerPixels = [];
  for (let y = 1; y < H - 1; y++) for (let x = 1; x < W - 1; x++) {
    let all = true;
    for (let dy = -1; dy <= 1 && all; dy++) for (let dx = -1; dx <= 1; dx++) if (!ok[(y + dy) * W + x + dx]) { all = false; break; }
    if (all) innerPixels.push(y * W + x);
  }
  inner = innerPixels.length;
  for (const i of innerPixels) for (let k = 0; k < 3; k++) peak = Math.max(peak, want.rgb[i * 3 + k]);
  let energyGot = 0, energyWant = 0, fine = 0;
  for (const i of innerPixels) for (let k = 0; k < 3; k++) {
    const d = Math.abs(got[i * 4 + k] - want.rgb[i * 3 + k]) / peak;
    energyGot += got[i * 4 + k]; energyWant += want.rgb[i * 3 + k];
    if (d > max) { max = d; at = [i % W, Math.floor(i / W), "RGB"[k], got[i * 4 + k], want.rgb[i * 3 + k]]; }
    if (d > SHARE_AT) beyond++;
    if (d > 2e-3) fine++;
  }
  return { inner, peak, max, at, share: beyond / (3 * inner), fine: fine / (3 * inner), engineOnly, speculaOnly,
    energy: energyGot / energyWant };
}
// two engine images (a over b): the largest difference relative to b's peak, and a's energy over b's
function contrast(a, b) {
  let peak = 0, max = 0, ea = 0, eb = 0;
  for (let i = 0; i < W * H; i++) for (let k = 0; k < 3; k++) peak = Math.max(peak, b[i * 4 + k]);
  for (let i = 0; i < W * H; i++) for (let k = 0; k < 3; k++) {
    max = Math.max(max, Math.abs(a[i * 4 + k] - b[i * 4 + k]));
    ea += a[i * 4 + k]; eb += b[i * 4 + k];
  }
  return { max: max / peak, energy: ea / eb };
}

const coveredCount = covered.filter((x, i) => i % 3 === 0 && x).length;
const browser = await lib.launchChromium("engines check");
const { server, url } = await lib.startServer(work);
const log = [];
const measured = { max: 0, share: 0 };
const scene = { W, H, camera: lib.CAMERA, lights: lib.LIGHTS };
const WHITE = [1, 1, 1];
try {
  for (const engine of ["three", "tsl", "babylon"]) {
    const t1 = Date.now();
    const lang = engine === "babylon" ? "babylon" : "threejs";
    const model = engine === "babylon" ? "classic" : "physical";
    let page;
    let info;
    try {
      page = await lib.openPage(browser, url, engine, log);
      info = await page.evaluate((cfg) => window.specula.init(cfg), scene);
    } catch (e) { fail(`${engine}: ${e.message.split("\n")[0]}`); continue; }
    const label = { three: "three.js WebGLRenderer", tsl: "three.js WebGPURenderer+TSL", babylon: "Babylon.js" }[engine];
    console.log(`\n${label}: ${info.backend}${engine === "tsl" ? `; WebGPU adapter: ${info.adapter ?? "none"}` : ""}`);
    if (engine === "tsl" && !info.adapter) console.log("  (no WebGPU adapter in this Chromium: TSL checked on forceWebGL)");
    const draw = async (v) => {
      const r = await page.evaluate((x) => window.specula.render(x), v);
      return { image: lib.f32FromBase64(r.image), then: r.imageThen && lib.f32FromBase64(r.imageThen), newPrograms: r.newPrograms };
    };
    const row = (name, r) => {
      const pc = (x) => `${(100 * x).toFixed(3).padStart(6)} %`;
      console.log(`  ${name.padEnd(30)} ${fmt(r.max).padStart(8)} ${pc(r.fine)} ${pc(r.share)}  ${r.energy.toFixed(5)}`);
      measured.max = Math.max(measured.max, r.max); measured.share = Math.max(measured.share, r.share);
      measured.fine = Math.max(measured.fine ?? 0, r.fine);
      measured.energy = Math.max(measured.energy ?? 0, Math.abs(r.energy - 1));
      const where = r.at ? ` at (${r.at[0]}, ${r.at[1]}) ${r.at[2]}: ${fmt(r.at[3])} against specula's ${fmt(r.at[4])}` : "";
      if (r.inner < 0.8 * coveredCount) fail(`${engine} ${name}: only ${r.inner} inner pixels of ${coveredCount} covered by specula (camera or mesh differ)`);
      if (r.max > MAX_DIFF) fail(`${engine} ${name}: largest difference ${fmt(r.max)} of the peak > ${MAX_DIFF}${where}`);
      if (Math.abs(r.energy - 1) > MAX_ENERGY) fail(`${engine} ${name}: energy ratio ${r.energy.toFixed(5)} (at most ${MAX_ENERGY} from 1)`);
      if (r.share > MAX_SHARE) fail(`${engine} ${name}: ${(100 * r.share).toFixed(3)} % of channels differ by > ${SHARE_AT} of the peak (at most ${100 * MAX_SHARE} %)${where}`);
    };
    console.log(`  against specula render --model ${model} (${coveredCount} pixels covered; of them inner ` +
      "pixels: a pixel and its 8 neighbours covered in both images)");
    console.log(`  ${"lobe (geometry, normalisation)".padEnd(30)} ${"max diff".padStart(8)} ${"> 0.2 %".padStart(8)} ` +
      `${"> 1 %".padStart(8)}  energy   (differences relative to specula's peak)`);
    for (const c of cases) {
      const module = `/work/${c.file}-${lang}.js`;
      const name = `${c.name} (${c.geometry}, ${c.normalisation})`;
      let r;
      try { r = await draw({ module, n: c.n, thenN: c.thenN, color: lib.COLOUR, specular: WHITE }); }
      catch (e) { fail(`${engine} ${name}: ${e.message.split("\n")[0]}`); continue; }
      row(name, compare(r.image, refs[`${c.file}-${model}`]));
      if (c.thenN) {
        row(`  then n=${c.thenN} (uniform)`, compare(r.then, refs[`${c.file}-${model}-then`]));
        if (r.newPrograms) fail(`${engine} ${c.name}: changing n compiled ${r.newPrograms} new program(s)`);
        console.log(`    new programs after changing n: ${r.newPrograms ?? "(not counted on this renderer)"}`);
      }
    }
    // the modules refuse an n they do not serve
    for (const c of [cases.find((x) => x.lobe === "minimax2"), cases.find((x) => x.lobe === "pow")].filter(Boolean)) {
      const bad = c.lobe === "pow" ? 5000 : c.n + 1;
      const message = await page.evaluate(([m, n]) => window.specula.refuses(m, n), [`/work/${c.file}-${lang}.js`, bad]);
      if (!message?.startsWith("RangeError")) fail(`${engine} ${c.name}: n = ${bad} was not refused with a RangeError (${message})`);
      else if (message.includes("\n")) fail(`${engine} ${c.name}: the RangeError's message is not one line`);
      else if (!message.includes(`n = ${bad} `)) fail(`${engine} ${c.name}: the RangeError does not name n = ${bad}: ${message}`);
      else console.log(`  n = ${bad} refused: ${message}`);
    }
    // printed only: what the drop-in changes against the engine's own pow material
    const black = [0, 0, 0];
    const stock = await draw({ module: null, n: N, color: black, specular: WHITE });
    const dropin = await draw({ module: `/work/${plain.file}-${lang}.js`, n: N, color: black, specular: WHITE });
    const s = contrast(stock.image, dropin.image);
    const what = engine === "babylon" ? "Babylon's pow(N.H, n), no N.L, lit past the horizon"
      : "three's G D = (n + 2) / (8 pi) (N.H)^n";
    console.log(`  stock material at shininess ${N} against the drop-in (N.H)^${N} (specular only; ${what}):` +
      ` energy ratio ${s.energy.toFixed(4)}, largest difference ${fmt(s.max)} of the drop-in's peak`);
    if (engine !== "babylon") {
      const col = await draw({ module: `/work/${plain.file}-${lang}.js`, n: N, color: lib.COLOUR, specular: [0.04, 0.04, 0.04] });
      const f = compare(col.image, refs["coloured-physical"]);
      console.log(`  specular 0.04 (three's Schlick Fresnel) against specula's specular_colour 0.04 (no Fresnel):` +
        ` largest difference ${fmt(f.max)} of the peak, energy ratio ${f.energy.toFixed(4)}`);
    }
    console.log(`  (${((Date.now() - t1) / 1000).toFixed(1)} s)`);
    await page.close();
  }
} finally {
  await browser.close();
  server.close();
}
for (const line of log) console.log(`console: ${line}`);
console.log(`\nworst over every engine and lobe: largest difference ${fmt(measured.max)} of the peak (bound ${MAX_DIFF});` +
  ` channels beyond 0.2 % of it ${(100 * measured.fine).toFixed(3)} %, beyond ${100 * SHARE_AT} % ` +
  `${(100 * measured.share).toFixed(3)} % (bound ${100 * MAX_SHARE} %); energy off by ${measured.energy.toExponential(2)} ` +
  `(bound ${MAX_ENERGY})`);
if (log.some((l) => /error/i.test(l))) fail("the pages logged errors (above)");
if (failures.length) {
  for (const f of failures) console.error(`FAIL ${f}`);
  process.exit(1);
}
console.log("engines check: ok");
