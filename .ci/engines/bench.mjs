// Frame times of specula's lobes in three.js (WebGL2, WebGPU) and Babylon.js against each
// engine's own pow material in the same page: 512 x 512, the sphere and the torus of check.mjs,
// two directional lights. Every variant is compiled and warmed up, then ROUNDS rounds run over
// all variants in turn (drift spreads evenly), each FRAMES frames closed by a 1-pixel read that
// waits for the GPU. Printed per lobe: the median ms/frame, its spread (min-max over the rounds)
// and the ratio of medians to the engine's pow; spreads that overlap are printed "tie". Under
// SwiftShader these are CPU timings of the rasterizer and the shader together; never asserted.
// Beside each: the lobe's throughput over pow's in specula's GPU cost model (the shader's
// instructions, `specula recommend --target gpu-nvidia|gpu-amd`), the cost where it is paid on
// a real GPU, which the frame times on a CPU rasterizer cannot show.
// Usage: node .ci/engines/bench.mjs SPECULA_BIN
import * as lib from "./lib.mjs";

const BIN = process.argv[2];
if (!BIN) { console.error("usage: node .ci/engines/bench.mjs SPECULA_BIN"); process.exit(2); }
const W = 512, H = 512, N = 64;
const ROUNDS = Number(process.env.BENCH_ROUNDS ?? 5), FRAMES = Number(process.env.BENCH_FRAMES ?? 4);
const WARMUP = 2;

const work = await lib.workDir();
await lib.writeFile(lib.join(work, "mesh.json"), JSON.stringify(lib.buildMesh()));
const lobes = await lib.builtInLobes(BIN);
const cases = lobes.map((lobe) => ({ name: lobe, lobe }));
cases.push({ name: "formula", lobe: "=exp2(n * (t - 1) * 1.4427)" });
for (const [i, c] of cases.entries()) c.file = `lobe${i}`;
const jobs = [];
for (const c of cases) for (const lang of ["threejs", "babylon"]) {
  jobs.push(() => lib.run(BIN, ["shader", "--lang", lang, `--lobe=${c.lobe}`, "--n", String(N), "--geometry", "blinn",
    "--normalisation", "none", "-o", lib.join(work, `${c.file}-${lang}.js`)]));
}
try { await lib.pool(jobs, 4); } catch (e) { console.error(`engines bench: FAIL: ${e.message.split("\n")[0]}`); process.exit(1); }

// The cost model's rates at n, per lobe ("formula" is not in recommend's list).
const modelled = {};
for (const target of ["gpu-nvidia", "gpu-amd"]) {
  const out = await lib.run(BIN, ["recommend", "--target", target, "--n", String(N), "--max-error", "100%", "--format", "json"]);
  const rows = JSON.parse(out);
  const pow = rows.find((r) => r.lobe === "pow")?.rate;
  for (const r of rows) (modelled[r.lobe] ??= {})[target] = pow ? r.rate / pow : null;
}
const model = (lobe) => {
  const m = modelled[lobe];
  return m ? `model ${["gpu-nvidia", "gpu-amd"].map((t) => (m[t] === null ? "-" : `${m[t].toFixed(2)}x`)).join(" / ")}` : "";
};

const median = (a) => { const s = [...a].sort((x, y) => x - y); return s.length % 2 ? s[s.length >> 1] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2; };
const browser = await lib.launchChromium("engines bench");
const { server, url } = await lib.startServer(work);
const log = [];
let failed = false;
console.log(`frame times at ${W}x${H}, n = ${N} (blinn, no normalisation), ${ROUNDS} rounds of ${FRAMES} frames; ` +
  "ratio = median / the engine's pow material's median; model = the lobe's throughput over pow's in " +
  "specula's GPU cost model (NVIDIA / AMD)");
try {
  for (const engine of ["three", "tsl", "babylon"]) {
    const lang = engine === "babylon" ? "babylon" : "threejs";
    let page, info, ms;
    const variants = [{ module: null, n: N, color: lib.COLOUR, specular: [1, 1, 1] },
      ...cases.map((c) => ({ module: `/work/${c.file}-${lang}.js`, n: N, color: lib.COLOUR, specular: [1, 1, 1] }))];
    const t0 = Date.now();
    try {
      page = await lib.openPage(browser, url, engine, log);
      info = await page.evaluate((cfg) => window.specula.init(cfg), { W, H, camera: lib.CAMERA, lights: lib.LIGHTS });
      ms = await page.evaluate(([v, o]) => window.specula.bench(v, o), [variants, { rounds: ROUNDS, frames: FRAMES, warmup: WARMUP }]);
    } catch (e) { console.error(`engines bench: ${engine}: ${e.message.split("\n")[0]}`); failed = true; continue; }
    const label = { three: "three.js WebGLRenderer", tsl: "three.js WebGPURenderer+TSL", babylon: "Babylon.js" }[engine];
    console.log(`\n${label} (${info.backend}${engine === "tsl" ? `; adapter ${info.adapter ?? "none"}` : ""}), ` +
      `${((Date.now() - t0) / 1000).toFixed(1)} s`);
    const stock = { med: median(ms[0]), min: Math.min(...ms[0]), max: Math.max(...ms[0]) };
    const line = (name, t) => {
      const med = median(t), lo = Math.min(...t), hi = Math.max(...t);
      const tie = t !== ms[0] && lo <= stock.max && hi >= stock.min;
      const ratio = t === ms[0] ? "1 (reference)" : `${(med / stock.med).toFixed(2)}${tie ? " tie" : ""}`;
      console.log(`  ${name.padEnd(22)} ${med.toFixed(2).padStart(7)} ms  (${lo.toFixed(2)}-${hi.toFixed(2)})  ${ratio.padEnd(9)}  ${model(name)}`);
    };
    line(`${engine === "babylon" ? "StandardMaterial" : "MeshPhong"} pow`, ms[0]);
    for (const [i, c] of cases.entries()) line(c.name, ms[i + 1]);
    await page.close();
  }
} finally {
  await browser.close();
  server.close();
}
for (const l of log) console.log(`console: ${l}`);
if (failed) process.exit(1);
