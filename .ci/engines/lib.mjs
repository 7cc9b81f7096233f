// Shared by check.mjs and bench.mjs: the scene (one mesh file for every renderer), the local
// static server, Chromium, `specula` runs, and a reader for the EXR files `specula render`
// writes (RLE-coded f32 RGB in 64 x 64 tiles, or scanlines).
import { execFile } from "node:child_process";
import { existsSync } from "node:fs";
import { mkdtemp, readFile, writeFile } from "node:fs/promises";
import http from "node:http";
import { tmpdir } from "node:os";
import { extname, join, normalize } from "node:path";
import { fileURLToPath } from "node:url";
import { inflateSync } from "node:zlib";

export const HERE = fileURLToPath(new URL(".", import.meta.url));
export const CI = process.env.CI === "true";

// ---- the scene: world z up, lengths in world units, linear RGB ----
export const CAMERA = { eye: [0, -4.4, 1.3], target: [0.02, 0, 0], up: [0, 0, 1], fov: 46, near: 0.1,
  far: 100 };
// towards: from the surface to the light
export const LIGHTS = [
  { towards: [0.8, -1.0, 1.2], intensity: [1.0, 0.95, 0.9] },
  { towards: [-1.2, -0.6, 0.5], intensity: [0.45, 0.5, 0.6] },
];
export const COLOUR = [0.5, 0.32, 0.2];

const norm3 = (v) => { const l = Math.hypot(...v); return v.map((x) => x / l); };
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

// A UV sphere (segments x rings) and a torus (segments x sides), positions and unit normals in
// world space, counter-clockwise seen from outside, no degenerate triangles (the poles are fans).
// Every number is an f32 so that the OBJ text and the engines' Float32Arrays are the same values.
export function buildMesh({ segments = 128, rings = 64 } = {}) {
  const P = [], N = [], I = [];
  const vertex = (p, n) => { P.push(...p.map(Math.fround)); N.push(...norm3(n).map(Math.fround));
    return P.length / 3 - 1; };
  // sphere: centre c, radius r
  const c = [-1.0, 0, 0], r = 0.8;
  const at = (i, j) => {
    const th = (Math.PI * j) / rings, ph = (2 * Math.PI * i) / segments;
    const n = [Math.sin(th) * Math.cos(ph), Math.sin(th) * Math.sin(ph), Math.cos(th)];
    return [c.map((x, k) => x + r * n[k]), n];
  };
  const top = vertex([c[0], c[1], c[2] + r], [0, 0, 1]);
  const row = [];
  for (let j = 1; j < rings; j++) {
    row.push([]);
    for (let i = 0; i < segments; i++) row[j - 1].push(vertex(...at(i, j)));
  }
  const bottom = vertex([c[0], c[1], c[2] - r], [0, 0, -1]);
  for (let i = 0; i < segments; i++) {
    const i2 = (i + 1) % segments;
    I.push(top, row[0][i], row[0][i2]);
    for (let j = 0; j < rings - 2; j++) {
      const a = row[j][i], b = row[j][i2], d = row[j + 1][i], e = row[j + 1][i2];
      I.push(a, d, e, a, e, b);
    }
    I.push(bottom, row[rings - 2][i2], row[rings - 2][i]);
  }
  const sphereTriangles = I.length / 3;
  // torus: centre t, major R, minor q, its axis towards the camera: seen face on, it hides no part
  // of itself (an edge where it would is covered on both sides, and the rasterizers' choices of
  // side there differ by whole surfaces)
  const t = [1.05, 0, 0.05], R = 0.6, q = 0.24;
  const az = norm3(CAMERA.eye.map((x, k) => x - t[k])), ax = norm3(cross([0, 0, 1], az)), ay = cross(az, ax);
  const world = (v) => [0, 1, 2].map((k) => ax[k] * v[0] + ay[k] * v[1] + az[k] * v[2]);
  const sides = rings, base = P.length / 3;
  for (let i = 0; i < segments; i++) for (let j = 0; j < sides; j++) {
    const u = (2 * Math.PI * i) / segments, v = (2 * Math.PI * j) / sides;
    const n = world([Math.cos(v) * Math.cos(u), Math.cos(v) * Math.sin(u), Math.sin(v)]);
    const s = world([(R + q * Math.cos(v)) * Math.cos(u), (R + q * Math.cos(v)) * Math.sin(u),
      q * Math.sin(v)]);
    vertex(s.map((x, k) => x + t[k]), n);
  }
  const id = (i, j) => base + (i % segments) * sides + (j % sides);
  for (let i = 0; i < segments; i++) for (let j = 0; j < sides; j++) {
    const a = id(i, j), b = id(i + 1, j), d = id(i, j + 1), e = id(i + 1, j + 1);
    I.push(a, b, e, a, e, d);
  }
  return { positions: P, normals: N, indices: I, sphereTriangles };
}

export function objText(mesh) {
  const lines = ["# specula .ci/engines: a UV sphere and a torus, vertex normals"];
  const { positions: P, normals: N, indices: I } = mesh;
  for (let i = 0; i < P.length; i += 3) lines.push(`v ${P[i]} ${P[i + 1]} ${P[i + 2]}`);
  for (let i = 0; i < N.length; i += 3) lines.push(`vn ${N[i]} ${N[i + 1]} ${N[i + 2]}`);
  for (let i = 0; i < I.length; i += 3) {
    const [a, b, c] = [I[i] + 1, I[i + 1] + 1, I[i + 2] + 1];
    lines.push(`f ${a}//${a} ${b}//${b} ${c}//${c}`);
  }
  return lines.join("\n") + "\n";
}

const toml = (v) => (Array.isArray(v) ? `[${v.map((x) => toml(x)).join(", ")}]`
  : typeof v === "string" ? JSON.stringify(v) : String(v));

// A specula scene: the mesh, the camera and lights above, one material.
export function sceneToml({ W, H, model, mesh = "mesh.obj", material, ambient = [0, 0, 0] }) {
  const m = { ka: 0, kd: 1, ks: 1, colour: COLOUR, specular_colour: [1, 1, 1], lobe: "pow", n: 64,
    geometry: "phong", normalisation: "none", ...material };
  const out = [`ambient = ${toml(ambient)}`, "", "[camera]"];
  for (const [k, v] of Object.entries(CAMERA)) out.push(`${k} = ${toml(v)}`);
  out.push("", "[render]", `width = ${W}`, `height = ${H}`, "samples = 1", 'shading = "phong"',
    `model = "${model}"`, "cull_back_faces = true", "background = [0.0, 0.0, 0.0]",
    "exposure = 1.0", 'tonemap = "clamp"');
  for (const l of LIGHTS) {
    out.push("", "[[lights]]", 'kind = "directional"', `towards = ${toml(l.towards)}`,
      `intensity = ${toml(l.intensity)}`);
  }
  out.push("", "[[objects]]", 'shape = "mesh"', `path = ${toml(mesh)}`, "[objects.material]");
  for (const [k, v] of Object.entries(m)) out.push(`${k} = ${toml(v)}`);
  return out.join("\n") + "\n";
}

// ---- running specula ----
export function run(bin, args, { cwd } = {}) {
  return new Promise((ok, fail) => {
    execFile(bin, args, { cwd, maxBuffer: 64 << 20 }, (error, stdout, stderr) => {
      if (error) fail(new Error(`${bin} ${args.join(" ")}: ${(stderr || error.message).trim()}`));
      else ok(stdout);
    });
  });
}

// Runs the thunks `jobs` at most `width` at a time, in order of their results.
export async function pool(jobs, width = 2) {
  const results = new Array(jobs.length);
  let next = 0;
  const worker = async () => { while (next < jobs.length) { const i = next++; results[i] = await jobs[i](); } };
  await Promise.all(Array.from({ length: Math.min(width, jobs.length) }, worker));
  return results;
}

// The built-in lobes: the first column of `specula models`.
export async function builtInLobes(bin) {
  const text = await run(bin, ["models"]);
  const lines = text.split("\n");
  const rule = lines.findIndex((l) => /^-{3,}/.test(l));
  const ids = lines.slice(rule + 1).map((l) => l.split(/\s+/)[0]).filter((s) => /^[a-z0-9-]+$/.test(s));
  if (ids.length < 5 || !ids.includes("pow")) throw new Error(`specula models: no lobe table in:\n${text}`);
  return ids;
}

export const workDir = () => mkdtemp(join(tmpdir(), "specula-engines-"));

// ---- EXR (the subset the `exr` crate writes for specula: one part, FLOAT or HALF channels,
// NO, RLE or ZIP(S) compression, scanlines or one-level tiles) ----
function halfToFloat(h) {
  const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 0x1f, f = h & 0x3ff;
  if (e === 0) return s * f * 2 ** -24;
  if (e === 31) return f ? NaN : s * Infinity;
  return s * (1 + f / 1024) * 2 ** (e - 15);
}
function unRle(src, size) {
  const out = new Uint8Array(size);
  let i = 0, o = 0;
  while (i < src.length) {
    const count = (src[i] << 24) >> 24; // signed byte
    i++;
    if (count < 0) { out.set(src.subarray(i, i - count), o); o -= count; i -= count; }
    else { out.fill(src[i], o, o + count + 1); o += count + 1; i++; }
  }
  if (o !== size) throw new Error(`EXR: RLE block gives ${o} bytes, expected ${size}`);
  return out;
}
function unPredict(t) { // delta predictor, then the two halves interleaved
  for (let i = 1; i < t.length; i++) t[i] = (t[i - 1] + t[i] - 128) & 0xff;
  const out = new Uint8Array(t.length), half = (t.length + 1) >> 1;
  for (let i = 0, a = 0, b = half; i < t.length; i++) out[i] = i & 1 ? t[b++] : t[a++];
  return out;
}

export async function readExr(path) {
  const buf = await readFile(path);
  const dv = new DataView(buf.buffer, buf.byteOffset, buf.byteLength);
  if (dv.getUint32(0, true) !== 20000630) throw new Error(`${path}: not an OpenEXR file`);
  const flags = dv.getUint32(4, true);
  if (flags & 0x1000) throw new Error(`${path}: multi-part EXR not supported`);
  let p = 8;
  const cstr = () => { const e = buf.indexOf(0, p); const s = buf.toString("latin1", p, e); p = e + 1; return s; };
  const header = {};
  for (;;) {
    const name = cstr();
    if (!name) break;
    const type = cstr(), size = dv.getUint32(p, true);
    p += 4;
    const start = p;
    if (type === "chlist") {
      const ch = [];
      while (buf[p]) { const n = cstr(); ch.push({ name: n, type: dv.getInt32(p, true) }); p += 16; }
      header[name] = ch;
    } else if (type === "box2i") {
      header[name] = [0, 4, 8, 12].map((k) => dv.getInt32(start + k, true));
    } else if (type === "compression") header[name] = buf[start];
    else if (type === "tiledesc") {
      header[name] = { x: dv.getUint32(start, true), y: dv.getUint32(start + 4, true), mode: buf[start + 8] };
    }
    p = start + size;
  }
  const [x0, y0, x1, y1] = header.dataWindow;
  const W = x1 - x0 + 1, H = y1 - y0 + 1;
  const channels = header.channels; // stored sorted by name
  const bytes = channels.map((c) => (c.type === 1 ? 2 : 4));
  const comp = header.compression;
  if (![0, 1, 2, 3].includes(comp)) throw new Error(`${path}: EXR compression ${comp} not supported`);
  const tiled = !!(flags & 0x200);
  const tw = tiled ? header.tiles.x : W;
  const th = tiled ? header.tiles.y : comp === 3 ? 16 : 1;
  if (tiled && (header.tiles.mode & 0xf) !== 0) throw new Error(`${path}: mip-mapped EXR not supported`);
  const chunks = Math.ceil(W / tw) * Math.ceil(H / th);
  const rgb = new Float32Array(W * H * 3);
  const index = Object.fromEntries(channels.map((c, k) => [c.name.split(".").pop(), k]));
  for (const want of ["R", "G", "B"]) if (!(want in index)) throw new Error(`${path}: no ${want} channel`);
  for (let k = 0; k < chunks; k++) {
    let q = Number(dv.getBigUint64(p + 8 * k, true));
    let cx = 0, cy;
    if (tiled) { cx = dv.getInt32(q, true) * tw; cy = dv.getInt32(q + 4, true) * th; q += 16; }
    else { cy = dv.getInt32(q, true) - y0; q += 4; }
    const size = dv.getInt32(q, true);
    q += 4;
    const w = Math.min(tw, W - cx), h = Math.min(th, H - cy);
    const raw = w * h * bytes.reduce((a, b) => a + b, 0);
    let data = buf.subarray(q, q + size);
    if (size < raw) data = comp === 1 ? unPredict(unRle(data, raw)) : unPredict(new Uint8Array(inflateSync(data)));
    const d = new DataView(data.buffer, data.byteOffset, data.byteLength);
    let o = 0;
    for (let y = 0; y < h; y++) for (const [c, ch] of channels.entries()) {
      const slot = { R: 0, G: 1, B: 2 }[ch.name.split(".").pop()];
      for (let x = 0; x < w; x++) {
        const v = bytes[c] === 2 ? halfToFloat(d.getUint16(o, true)) : ch.type === 2 ? d.getFloat32(o, true) : d.getUint32(o, true);
        o += bytes[c];
        if (slot !== undefined) rgb[((cy + y) * W + cx + x) * 3 + slot] = v;
      }
    }
  }
  return { width: W, height: H, rgb };
}

// ---- the browser side ----
const TYPES = { ".html": "text/html", ".js": "text/javascript", ".mjs": "text/javascript",
  ".json": "application/json", ".obj": "text/plain" };

// Serves this folder (the pages, node_modules) at / and `work` at /work/. 127.0.0.1 is a secure
// context, which WebGPU needs.
export function startServer(work) {
  const server = http.createServer(async (req, res) => {
    const path = normalize(decodeURIComponent(new URL(req.url, "http://x").pathname));
    if (path.includes("..")) { res.writeHead(403).end(); return; }
    if (path === "/favicon.ico") { res.writeHead(204).end(); return; }
    const file = path.startsWith("/work/") ? join(work, path.slice(6)) : join(HERE, path);
    try {
      const body = await readFile(file);
      res.writeHead(200, { "content-type": TYPES[extname(file)] ?? "application/octet-stream",
        "cache-control": "no-store" });
      res.end(body);
    } catch { res.writeHead(404).end("not found"); }
  });
  return new Promise((ok) => server.listen(0, "127.0.0.1",
    () => ok({ server, url: `http://127.0.0.1:${server.address().port}` })));
}

export const CHROMIUM_ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--ignore-gpu-blocklist", "--enable-unsafe-webgpu"];

// Chromium through playwright-core; without it (or without the engines' packages) the check is
// skipped, except under CI=true, where that is a failure.
export async function launchChromium(what) {
  const executablePath = process.env.CHROMIUM ?? "/usr/bin/chromium";
  const missing = !existsSync(executablePath) ? `no Chromium at ${executablePath} (set CHROMIUM)`
    : ["three", "@babylonjs/core"].find((p) => !existsSync(join(HERE, "node_modules", p)))
      ? "the engines are not installed (npm ci --prefix .ci/engines)" : null;
  if (missing) {
    if (CI) { console.error(`${what}: FAIL: ${missing}`); process.exit(1); }
    console.log(`${what}: skipped: ${missing}`);
    process.exit(0);
  }
  const { chromium } = await import("playwright-core");
  return chromium.launch({ executablePath, args: CHROMIUM_ARGS });
}

// Opens the page of `engine` ("three", "tsl", "babylon"); console errors are collected in `log`.
export async function openPage(browser, url, engine, log) {
  const page = await browser.newPage();
  page.on("console", (m) => {
    if (m.type() === "error" || m.type() === "warning") log.push(`${engine} ${m.type()}: ${m.text().slice(0, 300)}`);
  });
  page.on("pageerror", (e) => log.push(`${engine} pageerror: ${e.message}`));
  await page.goto(`${url}/page.html?engine=${engine}`);
  await page.waitForFunction(() => window.speculaReady === true || window.speculaError, null,
    { timeout: 120000 });
  const error = await page.evaluate(() => window.speculaError ?? null);
  if (error) throw new Error(`${engine} page: ${error}`);
  return page;
}

export function f32FromBase64(s) {
  const b = Buffer.from(s, "base64");
  return new Float32Array(b.buffer, b.byteOffset, b.byteLength / 4);
}

export { writeFile, join };
