// Opens a written report in Debian's Chromium and measures it as a reader meets it:
// - the first screen (1400 x 900) holds the answer box, above any table;
// - every image loads, and every image of a comparison's tiles is a link to its own file;
// - no two labels overlap: the tiles' captions and the table of contents on the page, and the
//   text of every SVG chart, each opened on its own and its <text> boxes measured;
// - every lobe's swatch colour lies at least 20 from every other's in CIELAB;
// and saves the first screen and the render comparison as screenshots.
// Usage: node report.mjs REPORT_DIRECTORY SCREENSHOT_DIRECTORY
import { readdirSync } from "node:fs";
import { join, resolve } from "node:path";
import { chromium } from "playwright-core";

const [directory, shots] = process.argv.slice(2).map((p) => resolve(p));
const page_url = "file://" + join(directory, "index.html");
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu"] });
const failures = [];

// Two boxes overlap when they share more than a pixel each way (antialiased edges touch).
const overlapping = (a, b) => Math.min(a.right, b.right) - Math.max(a.left, b.left) > 1 && Math.min(a.bottom, b.bottom) - Math.max(a.top, b.top) > 1;
const pairs = (boxes) => boxes.flatMap((a, i) => boxes.slice(i + 1).filter((b) => overlapping(a, b)).map((b) => `'${a.text}' and '${b.text}'`));

try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const messages = [];
  page.on("console", (message) => messages.push(`${message.type()}: ${message.text()}`));
  await page.goto(page_url, { waitUntil: "load" });
  // Lazy images load as they come into view: scroll through the page, then back.
  await page.evaluate(async () => {
    for (let y = 0; y < document.body.scrollHeight; y += 800) {
      window.scrollTo(0, y);
      await new Promise((r) => setTimeout(r, 20));
    }
    window.scrollTo(0, 0);
  });
  await page.waitForFunction(() => [...document.images].every((img) => img.complete), null, { timeout: 30000 });

  const first = await page.evaluate(() => {
    const answer = document.querySelector(".answer")?.getBoundingClientRect();
    const table = document.querySelector("table")?.getBoundingClientRect();
    return { answer: answer && { top: answer.top, bottom: answer.bottom }, table: table && table.top };
  });
  if (!first.answer || first.answer.bottom > 900) failures.push(`the answer box is not on the first screen: ${JSON.stringify(first)}`);
  else if (first.table !== undefined && first.table < first.answer.top) failures.push("a table comes before the answer box");
  await page.screenshot({ path: join(shots, "report-top.png") });

  const images = await page.evaluate(() => [...document.images].map((img) => ({
    src: img.getAttribute("src"), loaded: img.naturalWidth > 0,
    tiled: img.closest(".tile") !== null, link: img.closest("a")?.getAttribute("href") ?? null,
  })));
  for (const image of images) {
    if (!image.loaded) failures.push(`${image.src} did not load`);
    if (image.tiled && image.link !== image.src) failures.push(`${image.src} in a tile links to ${image.link}`);
  }
  const tiled = images.filter((image) => image.tiled).length;
  if (tiled < 20) failures.push(`only ${tiled} images in tiles`);

  // Labels on the page: the tiles' captions and figures, the table of contents.
  const labels = await page.evaluate(() => [...document.querySelectorAll(".tile figcaption, .tile p, nav.toc li")].map((el) => {
    const r = el.getBoundingClientRect();
    return { text: el.textContent.trim().slice(0, 40), left: r.left, right: r.right, top: r.top, bottom: r.bottom };
  }));
  for (const pair of pairs(labels)) failures.push(`on the page, ${pair} overlap`);

  // Every lobe's colour, as the page draws its swatch, distinct from every other's.
  const swatches = await page.evaluate(() => {
    const seen = new Map();
    for (const tile of document.querySelectorAll(".tile")) {
      const name = tile.querySelector("figcaption").textContent.trim();
      seen.set(name, getComputedStyle(tile.querySelector(".swatch")).backgroundColor);
    }
    return [...seen];
  });
  const lab = (css) => {
    const [r, g, b] = css.match(/\d+/g).slice(0, 3).map((c) => {
      const v = Number(c) / 255;
      return v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4;
    });
    const f = (t) => (t > 216 / 24389 ? Math.cbrt(t) : (24389 / 27 * t + 16) / 116);
    const [x, y, z] = [(0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047, 0.2126 * r + 0.7152 * g + 0.0722 * b, (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883];
    return [116 * f(y) - 16, 500 * (f(x) - f(y)), 200 * (f(y) - f(z))];
  };
  if (swatches.length < 13) failures.push(`only ${swatches.length} lobes have swatches`);
  swatches.forEach(([a, ca], i) => swatches.slice(i + 1).forEach(([b, cb]) => {
    const d = Math.hypot(...lab(ca).map((v, k) => v - lab(cb)[k]));
    if (d < 20) failures.push(`${a} (${ca}) and ${b} (${cb}) are ${d.toFixed(1)} apart in CIELAB`);
  }));

  const renders = page.locator("#s9 .tiles").first();
  await renders.scrollIntoViewIfNeeded();
  await renders.screenshot({ path: join(shots, "report-renders.png") });

  // Each chart on its own: its text boxes.
  const charts = readdirSync(directory).filter((name) => name.endsWith(".svg"));
  const chart = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  for (const name of charts) {
    await chart.goto("file://" + join(directory, name));
    const boxes = await chart.evaluate(() => [...document.querySelectorAll("text")].filter((t) => t.textContent.trim()).map((t) => {
      const r = t.getBoundingClientRect();
      return { text: t.textContent.trim(), left: r.left, right: r.right, top: r.top, bottom: r.bottom };
    }));
    for (const pair of pairs(boxes)) failures.push(`${name}: ${pair} overlap`);
  }
  if (charts.length < 20) failures.push(`only ${charts.length} charts`);
  if (messages.length) failures.push(...messages);
  console.log(`report check: ${images.length} images loaded (${tiled} in tiles, each a link to itself), ${labels.length} page labels and ${charts.length} charts' text without overlap, ${swatches.length} lobe colours distinct; screenshots in ${shots}`);
} finally {
  await browser.close();
}
if (failures.length) {
  console.error(failures.join("\n"));
  process.exit(1);
}
