// Drives `specula serve` in Debian's Chromium: loads the explorer, moves the n slider, changes
// the lobes (the environment view follows the lobe chosen last) and the volume view's lobe and
// volume, and requires that the plots and the renders change and that the console stays
// silent. Saves a screenshot.
// Usage: node check.mjs SPECULA_BINARY SCREENSHOT.png
import { chromium } from "playwright-core";
import { startServer } from "./serve.mjs";

const [binary, screenshot] = process.argv.slice(2);
const { server, url } = await startServer(binary);

// Without WebGL2: the page as a browser without it shows it, the server's sphere (live.mjs
// checks the live views).
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu", "--disable-webgl2"] });
const failures = [];
try {
  const page = await browser.newPage({ viewport: { width: 1500, height: 1200 } });
  const messages = [];
  page.on("console", (message) => messages.push(`${message.type()}: ${message.text()}`));
  page.on("pageerror", (error) => messages.push(`pageerror: ${error.message}`));
  // Each user action may start an update before the next action lands (the page debounces by
  // 60 ms, a loaded machine acts slower), so a change has settled only once the page has
  // drawn the address it holds and that address has `key` at `value` (list values in any
  // order).
  const drawn = (key, value) => page.waitForFunction(([k, v]) => {
    const shown = document.body.dataset.drawn ?? "";
    const got = (new URLSearchParams(shown).get(k) ?? "").split(",").sort().join(",");
    return shown === location.search && got === v;
  }, [key, value.split(",").sort().join(",")], { timeout: 60000 });
  const snapshot = () => page.evaluate(() => {
    // An image's pixels, not its address: a re-rendered image must look different.
    const pixels = (img) => {
      const canvas = document.createElement("canvas");
      [canvas.width, canvas.height] = [img.naturalWidth, img.naturalHeight];
      canvas.getContext("2d").drawImage(img, 0, 0);
      return canvas.toDataURL();
    };
    return {
      plots: ["cartesian", "error", "polar", "albedo", "slice"].map((id) => document.getElementById(id).toDataURL()),
      sphere: document.getElementById("sphere").dataset.source,
      teapot: document.getElementById("teapot").dataset.source,
      environment: pixels(document.getElementById("environment-image")),
      environmentPow: pixels(document.getElementById("environment-pow")),
      environmentPsnr: document.getElementById("environment-psnr").textContent,
      volume: pixels(document.getElementById("volume-image")),
      volumePow: pixels(document.getElementById("volume-pow")),
      address: location.search,
    };
  });
  const changed = (a, b, what) => {
    a.plots.forEach((plot, k) => { if (plot === b.plots[k]) failures.push(`${what}: plot ${k} did not change`); });
    if (a.sphere === b.sphere) failures.push(`${what}: the sphere was not re-rendered`);
  };

  await page.goto(url + "?lobes=schlick,cosquad&n=16");
  await drawn("lobes", "schlick,cosquad");
  const first = await snapshot();
  if (!first.address.includes("lobes=schlick%2Ccosquad")) failures.push(`the address does not hold the state: ${first.address}`);

  await page.locator("#n").evaluate((slider) => { slider.value = "250"; slider.dispatchEvent(new Event("input", { bubbles: true })); });
  await drawn("n", "316");
  const moved = await snapshot();
  changed(first, moved, "moving n");
  if (moved.volume === first.volume || moved.volumePow === first.volumePow) failures.push("moving n: the volume was not re-rendered");
  if (moved.environment === first.environment || moved.environmentPow === first.environmentPow) failures.push("moving n: the environment view was not re-rendered");

  await page.locator('#lobes input[value="schlick"]').uncheck();
  await page.locator('#lobes input[value="logexp"]').check();
  await drawn("lobes", "logexp,cosquad");
  const relobed = await snapshot();
  changed(moved, relobed, "changing the lobes");
  // The environment view follows the lobe chosen last (logexp) and keeps pow's image.
  if (relobed.environment === moved.environment) failures.push("changing the lobes: the environment view did not re-render the chosen lobe");
  if (relobed.environmentPow !== moved.environmentPow) failures.push("changing the lobes changed the environment's pow image");
  if (!/^PSNR [0-9.]+ dB against pow/.test(relobed.environmentPsnr)) failures.push(`logexp under the sky has no PSNR against pow: '${relobed.environmentPsnr}'`);

  // The machine-code view follows the chosen lobe (logexp) and the GPU: the compiler's code
  // beside pow's, the special-function instructions marked (SASS's MUFU, AMD's v_exp/v_log).
  const code = () => page.evaluate(() => ({
    lobe: document.getElementById("isa-lobe").textContent,
    lines: document.querySelectorAll("#isa-code .isa-line").length,
    marked: [...document.querySelectorAll("#isa-code .isa-transcendental")].map((line) => line.textContent.trim()),
    error: document.getElementById("isa-error").textContent,
  }));
  const sass = await code();
  if (sass.lobe !== "logexp" || sass.error || !sass.marked.length || !sass.marked.every((line) => line.includes("MUFU."))) failures.push(`the machine code on sm_89: ${JSON.stringify(sass)}`);
  await page.locator("#gpu").selectOption("gfx1100");
  await drawn("gpu", "gfx1100");
  const rdna = await code();
  if (rdna.error || !rdna.marked.length || !rdna.marked.every((line) => /v_(exp|log|rcp|sqrt|rsq)_f32/.test(line))) failures.push(`the machine code on gfx1100: ${JSON.stringify(rdna)}`);

  // The volume follows the chosen lobe as every panel does: logexp's image, pow's unchanged;
  // pow chosen, the two agree; the volume selector changes both.
  if (relobed.volume === moved.volume) failures.push("changing the lobes: the volume did not re-render the chosen lobe");
  if (relobed.volumePow !== moved.volumePow) failures.push("changing the lobes changed the volume's pow image");
  const volumeName = () => page.evaluate(() => document.getElementById("volume-lobe-name").textContent);
  if ((await volumeName()) !== "logexp") failures.push(`the volume shows '${await volumeName()}', not the chosen logexp`);
  const psnr = await page.evaluate(() => document.getElementById("volume-psnr").textContent);
  if (!/^PSNR [0-9.]+ dB against pow/.test(psnr)) failures.push(`logexp's volume has no PSNR against pow: '${psnr}'`);
  await page.locator('#lobes input[value="pow"]').check();
  await drawn("render", "pow");
  const same = await page.evaluate(() => document.getElementById("volume-psnr").textContent);
  if (same !== "identical to pow") failures.push(`pow against itself: '${same}'`);
  await page.locator('#lobes input[value="pow"]').uncheck();
  await drawn("lobes", "logexp,cosquad");
  const volumeLobe = await snapshot();
  await page.locator("#volume").selectOption("marschner-lobb");
  await drawn("volume", "marschner-lobb");
  const otherVolume = await snapshot();
  if (otherVolume.volume === volumeLobe.volume || otherVolume.volumePow === volumeLobe.volumePow) failures.push("choosing another volume did not change the images");

  // The shared address restores the view.
  const shared = page.url();
  const other = await browser.newPage();
  await other.goto(shared);
  await other.waitForFunction(() => Number(document.body.dataset.updates) > 0, null, { timeout: 30000 });
  const restored = await other.evaluate(() => [...document.querySelectorAll("#lobes input:checked")].map((c) => c.value).sort().join(",") + " " + document.getElementById("volume-lobe-name").textContent + " " + document.getElementById("volume").value);
  if (restored !== "cosquad,logexp cosquad marschner-lobb") failures.push(`the shared address restored ${restored}`);

  // The controls stay in view when the page scrolls, and the plots fill their sections.
  await page.evaluate(() => window.scrollTo(0, document.body.scrollHeight));
  const controlsTop = await page.evaluate(() => document.getElementById("controls").getBoundingClientRect().top);
  if (Math.abs(controlsTop) > 1) failures.push(`scrolled down, the controls moved to ${controlsTop} px`);
  const fill = await page.evaluate(() => {
    const canvas = document.getElementById("cartesian");
    const section = canvas.parentElement;
    const style = getComputedStyle(section);
    return canvas.getBoundingClientRect().width / (section.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight));
  });
  if (!(fill > 0.95 && fill <= 1.01)) failures.push(`the lobe plot fills ${(100 * fill).toFixed(0)} % of its section`);

  // Energy creation is said, and a bad address is reported rather than silently fixed.
  const warned = await browser.newPage();
  await warned.goto(url + "?lobes=pow&geometry=blinn&normalisation=lobe&n=64");
  await warned.waitForFunction(() => Number(document.body.dataset.updates) > 0, null, { timeout: 30000 });
  const warning = await warned.evaluate(() => document.getElementById("warning").textContent);
  if (!/Albedo reaches [0-9.]+ \(pow/.test(warning)) failures.push(`no albedo warning for Blinn with the lobe normalisation: '${warning}'`);
  const defaulted = await page.evaluate(() => document.getElementById("warning").textContent);
  if (defaulted) failures.push(`the default view warns: ${defaulted}`);
  const corrected = await browser.newPage();
  await corrected.goto(url + "?lobes=nope,pow&n=5000");
  await corrected.waitForFunction(() => Number(document.body.dataset.updates) > 0, null, { timeout: 30000 });
  const notes = await corrected.evaluate(() => document.getElementById("notes").textContent);
  if (!notes.includes("unknown lobe 'nope'") || !notes.includes("outside [1, 1000]")) failures.push(`the corrected address is not reported: '${notes}'`);

  // cosquad's v has a control, it changes the plots, and the address keeps it.
  const beforeV = await snapshot();
  await page.locator("#param-cosquad-v").fill("2");
  await drawn("lobes", "logexp,cosquad:v=2");
  const afterV = await snapshot();
  if (afterV.plots[0] === beforeV.plots[0]) failures.push("changing cosquad's v did not change the lobe plot");
  if (!afterV.address.includes("cosquad%3Av%3D2")) failures.push(`v is not in the address: ${afterV.address}`);

  // The formula box: a formula typed there is drawn beside the lobes and becomes the renders'
  // and the volume's lobe; a refused one gets its one-line error beside the box, is drawn
  // nowhere, and the rest of the page is drawn all the same.
  const K4 = "let a = (n + 1) / 17; max(0, a * (t - 1) + 1) ^ 16";
  const beforeFormula = await snapshot();
  await page.locator("#formula").fill(K4);
  await drawn("formula", K4);
  const typed = await snapshot();
  // Every plot but the slice (the first lobe's) draws the formula's curve too.
  typed.plots.slice(0, 4).forEach((plot, k) => { if (plot === beforeFormula.plots[k]) failures.push(`typing a formula: plot ${k} did not change`); });
  if (typed.sphere === beforeFormula.sphere) failures.push("typing a formula: the sphere was not re-rendered");
  if (typed.volume === beforeFormula.volume) failures.push("typing a formula did not re-render the volume with it");
  const labels = () => page.evaluate(() => ({
    error: document.getElementById("formula-error").textContent,
    legend: document.getElementById("legend-cartesian").textContent,
    render: document.getElementById("render-lobe").textContent,
    volume: document.getElementById("volume-lobe-name").textContent,
    status: document.getElementById("status").textContent,
  }));
  const good = await labels();
  if (good.error || good.status || !good.legend.includes("formula") || good.render !== "formula" || good.volume !== "formula") failures.push(`a good formula: ${JSON.stringify(good)}`);
  // A refusal's console line ("Failed to load resource: ... 400") is the browser's, expected here.
  const quiet = messages.length;
  for (const [text, expected] of [["max(0, tt)", "column 8: unknown name 'tt'; did you mean 't'?"], ["2 * t", "(above 1)"]]) {
    await page.locator("#formula").fill(text);
    await drawn("formula", text);
    const bad = await labels();
    if (!bad.error.includes(expected) || bad.error.includes("\n")) failures.push(`the formula '${text}' shows '${bad.error}', not '${expected}'`);
    if (bad.legend.includes("formula") || bad.render === "formula" || bad.volume === "formula" || bad.status) failures.push(`a refused formula is drawn: ${JSON.stringify(bad)}`);
  }
  messages.push(...messages.splice(quiet).filter((m) => !/status of 400/.test(m)));
  await page.locator("#formula").fill("");
  await drawn("formula", "");
  const cleared = await labels();
  if (cleared.error || cleared.legend.includes("formula")) failures.push(`clearing the formula: ${JSON.stringify(cleared)}`);

  // The design panel: specula design's verdict under its button, and the designed lobe put in
  // the formula box, where it is drawn like a typed one.
  await page.locator("#design-panel summary").click();
  await page.locator("#design-error").fill("0.1");
  const beforeDesign = await snapshot();
  await page.locator("#design-run").click();
  await page.waitForFunction(() => document.getElementById("formula").value.includes("exp2"), null, { timeout: 120000 });
  const designedFormula = await page.evaluate(() => document.getElementById("formula").value);
  await drawn("formula", designedFormula);
  const designedView = await snapshot();
  const verdict = await page.evaluate(() => document.getElementById("design-result").textContent);
  if (!/the cheapest designed lobe within 0\.1 %/.test(verdict)) failures.push(`the design's verdict: '${verdict}'`);
  if (designedView.plots[0] === beforeDesign.plots[0]) failures.push("the designed lobe was not drawn");
  const afterDesign = await labels();
  if (afterDesign.error || !afterDesign.legend.includes("formula")) failures.push(`the designed formula: ${JSON.stringify(afterDesign)}`);

  // Axis ticks are round numbers, counted by hand: 1, 2 or 5 times a power of ten.
  const ticks = await page.evaluate(() => [[0, 21.4], [-0.129, 0.129], [0, 1.05], [0, 90]].map(([lo, hi]) => niceTicks(lo, hi).map(([, label]) => label).join(" ")));
  const expected = ["0 5 10 15 20", "-0.10 -0.05 0.00 0.05 0.10", "0.0 0.2 0.4 0.6 0.8 1.0", "0 20 40 60 80"];
  ticks.forEach((got, k) => { if (got !== expected[k]) failures.push(`ticks: '${got}', expected '${expected[k]}'`); });

  // From the top: the controls are sticky, so a full-page capture draws them where the view is.
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.screenshot({ path: screenshot, fullPage: true });
  if (messages.length) failures.push(...messages.map((m) => `console: ${m}`));
} finally {
  await browser.close();
  server.kill("SIGINT");
}
if (failures.length) {
  console.error("explorer check failed:\n  " + failures.join("\n  "));
  process.exit(1);
}
console.log(`explorer check: loaded, moved n, changed lobes (and the environment view), the machine code followed the lobe and the GPU, the volume followed the chosen lobe, changed the volume, the controls stayed in view, the plots filled their sections, restored from the address, warned about albedo above 1, reported a corrected address, changed cosquad's v, typed a formula (drawn and rendered) and two refused ones (their errors beside the box), ran a design (its lobe drawn from the box), round ticks; no console message; screenshot ${screenshot}`);
