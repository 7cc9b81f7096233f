// Drives the explorer's measured-materials view in Debian's Chromium: a server without a
// folder offers the five bundled materials, `--data DIR` adds DIR's files to them; choosing a
// material fills the fits table, the three polar plots and the render; checking a fit redraws
// them and the address; the address restores the view; an unknown material in the address is
// said. The console must stay silent. Saves a screenshot.
// Usage: node measured.mjs SPECULA_BINARY DATA_DIR SCREENSHOT.png (DATA_DIR: one .bsdf file,
// named like no bundled material)
import { spawn } from "node:child_process";
import { chromium } from "playwright-core";
import { counts } from "./serve.mjs";

const [binary, data, screenshot] = process.argv.slice(2);
const start = (args) => new Promise((resolve, reject) => {
  const server = spawn(binary, ["serve", "--port", "0", ...args], { stdio: ["ignore", "pipe", "inherit"] });
  server.stdout.on("data", (chunk) => { const m = /on (http:\/\/\S+)/.exec(String(chunk)); if (m) resolve([server, m[1]]); });
  setTimeout(() => reject(new Error("no address")), 20000);
});
const [server, url] = await start(["--data", data]);
const [bare, bareUrl] = await start([]);
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu"] });
const failures = [];
const messages = [];
const watch = (page) => { page.on("console", (m) => messages.push(`${m.type()}: ${m.text()}`)); page.on("pageerror", (e) => messages.push(`pageerror: ${e.message}`)); };
try {
  const page = await browser.newPage({ viewport: { width: 1500, height: 1400 } });
  watch(page);
  await page.goto(url);
  // The five bundled materials, the folder's one and the prompt.
  await page.waitForFunction(() => document.querySelectorAll("#material option").length === 7, null, { timeout: 30000 });
  const settled = () => page.waitForFunction(() => document.body.dataset.drawn === location.search, null, { timeout: 60000 });
  const t0 = Date.now();
  await page.locator("#material").selectOption(process.env.MATERIAL ?? "paper_white_rgb");
  await page.waitForFunction(() => document.querySelectorAll("#measured-fits tbody tr").length === 27 && !document.getElementById("measured-renders").hidden && /against the measurement|identical/.test(document.getElementById("measured-psnr").textContent), null, { timeout: 90000 });
  console.log(`chose paper_white_rgb: table, polars and renders in ${Date.now() - t0} ms`);
  await settled();
  const snap = () => page.evaluate(() => ({
    polars: [...document.querySelectorAll("#measured-polars canvas")].map((c) => c.toDataURL()),
    checked: [...document.querySelectorAll("#measured-fits input:checked")].map((b) => b.value),
    fitName: document.getElementById("measured-fit-name").textContent,
    psnr: document.getElementById("measured-psnr").textContent,
    status: document.getElementById("measured-status").textContent,
    legend: document.getElementById("legend-measured").textContent,
    address: location.search,
  }));
  const first = await snap();
  console.log(JSON.stringify({ ...first, polars: first.polars.length }));
  if (first.polars.length !== 3) failures.push(`polars: ${first.polars.length}`);
  if (first.checked.length !== 3) failures.push(`default fits: ${first.checked}`);
  if (!first.address.includes("material=" + (process.env.MATERIAL ?? "paper_white_rgb")) || !first.address.includes("material_fits=")) failures.push(`address: ${first.address}`);
  if (!first.legend.startsWith("measured")) failures.push(`legend: ${first.legend}`);
  await page.locator('#measured-fits input[value="schlick/phong"]').check();
  await page.waitForFunction(() => document.getElementById("measured-fit-name").textContent === "schlick/phong" && /against the measurement|identical/.test(document.getElementById("measured-psnr").textContent), null, { timeout: 60000 });
  await settled();
  const second = await snap();
  second.polars.forEach((p, k) => { if (p === first.polars[k]) failures.push(`checking schlick/phong did not change polar ${k}`); });
  if (!second.address.includes("schlick%2Fphong")) failures.push(`address after checking: ${second.address}`);
  if (second.psnr === first.psnr) failures.push(`the render did not follow: ${second.psnr}`);
  await page.locator("#measured-scale").uncheck();
  const linear = await snap();
  if (linear.polars[0] === second.polars[0]) failures.push("the linear scale did not redraw");
  // The shared address restores material and fits.
  const other = await browser.newPage({ viewport: { width: 1500, height: 1400 } });
  watch(other);
  const t1 = Date.now();
  await other.goto(url + second.address);
  await other.waitForFunction(() => document.querySelectorAll("#measured-fits tbody tr").length === 27, null, { timeout: 30000 });
  console.log(`restored from the address (cached fits) in ${Date.now() - t1} ms`);
  const restored = await other.evaluate(() => [document.getElementById("material").value, [...document.querySelectorAll("#measured-fits input:checked")].map((b) => b.value).sort().join(",")]);
  if (restored[0] !== (process.env.MATERIAL ?? "paper_white_rgb") || restored[1] !== [...second.checked].sort().join(",")) failures.push(`restored ${restored}`);
  // An unknown material in the address is said.
  const wrong = await browser.newPage();
  watch(wrong);
  await wrong.goto(url + "?material=../x");
  await wrong.waitForFunction(() => document.getElementById("measured-status").textContent.includes("not offered"), null, { timeout: 30000 });
  await wrong.waitForFunction(() => document.body.dataset.drawn === location.search && !location.search.includes("material="), null, { timeout: 60000 });
  // Without --data the view offers the bundled materials.
  const bundled = await browser.newPage();
  watch(bundled);
  await bundled.goto(bareUrl);
  await bundled.waitForFunction(() => document.querySelectorAll("#material option").length === 6, null, { timeout: 30000 });
  const offered = await bundled.evaluate(() => [...document.querySelectorAll("#material option")].map((o) => o.value).filter((v) => v));
  if (offered.join(",") !== "cc_ibiza_sunset_rgb,cc_iris_purple_gem_rgb,colodur_napoli_4f_rgb,paper_white_rgb,vch_golden_yellow_rgb") failures.push(`bundled materials offered: ${offered}`);
  if (await bundled.evaluate(() => document.getElementById("measured-controls").hidden)) failures.push("controls hidden without --data");
  await page.locator("#measured-scale").check();
  await page.locator("#measured-view").screenshot({ path: screenshot });
  failures.push(...messages.filter(counts).map((m) => `console: ${m}`));
} finally {
  await browser.close();
  server.kill("SIGINT");
  bare.kill("SIGINT");
}
if (failures.length) { console.error("measured view check failed:\n  " + failures.join("\n  ")); process.exit(1); }
console.log("measured view check: ok");
