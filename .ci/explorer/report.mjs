// Opens a written report in Debian's Chromium and measures it as a reader meets it:
// - the first screen (1400 x 900) holds the answer box, above any table;
// - every image loads and is a link to its own file (a plot or render opens alone at full size
//   in one click);
// - no two labels overlap: the tiles' captions and the table of contents on the page, and the
//   text of every SVG chart, each opened on its own and its <text> boxes measured;
// - no text of an SVG, on the page or in a chart as the page shows it (its displayed width over
//   its own), renders under 10 px at the page's width;
// - in every scatter chart, each dot's name stands nearer its own dot than any other: the
//   distance from each dot's centre (a circle of the chart's "dots" group, titled with its
//   name) to each name's box (a text of its "dot-labels" group) measured in the browser, and
//   every dot named;
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
    scale: img.getBoundingClientRect().width / img.naturalWidth,
  })));
  for (const image of images) {
    if (!image.loaded) failures.push(`${image.src} did not load`);
    if (image.link !== image.src) failures.push(`${image.src} links to ${image.link}, not to itself`);
  }
  // The smallest scale each SVG is shown at on the page.
  const shownAt = new Map();
  for (const image of images.filter((i) => i.src.endsWith(".svg"))) shownAt.set(image.src, Math.min(shownAt.get(image.src) ?? Infinity, image.scale));
  // A text's rendered size: its font size through every transform above it (the viewBox's).
  const textSizes = () => [...document.querySelectorAll("text")].filter((t) => t.textContent.trim()).map((t) => {
    const m = t.getScreenCTM();
    return { text: t.textContent.trim().slice(0, 40), px: parseFloat(getComputedStyle(t).fontSize) * Math.hypot(m.a, m.b) };
  });
  const SMALLEST = 10;
  for (const t of await page.evaluate(textSizes)) {
    if (t.px < SMALLEST - 1e-6) failures.push(`on the page, '${t.text}' renders at ${t.px.toFixed(1)} px`);
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
  let scatters = 0, named = 0, smallest = Infinity;
  for (const name of charts) {
    await chart.goto("file://" + join(directory, name));
    const boxes = await chart.evaluate(() => [...document.querySelectorAll("text")].filter((t) => t.textContent.trim()).map((t) => {
      const r = t.getBoundingClientRect();
      return { text: t.textContent.trim(), left: r.left, right: r.right, top: r.top, bottom: r.bottom };
    }));
    for (const pair of pairs(boxes)) failures.push(`${name}: ${pair} overlap`);
    // Its text as the page shows it; a chart the page does not show, at its own size.
    const scale = shownAt.get(name) ?? 1;
    for (const t of await chart.evaluate(textSizes)) {
      smallest = Math.min(smallest, t.px * scale);
      if (t.px * scale < SMALLEST - 1e-6) failures.push(`${name}: '${t.text}' renders at ${(t.px * scale).toFixed(1)} px on the page`);
    }
    const scatter = await chart.evaluate(() => {
      const dots = [...document.querySelectorAll("g.dots circle")].map((c) => {
        const r = c.getBoundingClientRect();
        return { name: c.querySelector("title")?.textContent ?? "", x: (r.left + r.right) / 2, y: (r.top + r.bottom) / 2 };
      });
      const labels = [...document.querySelectorAll("g.dot-labels text")].map((t) => {
        const r = t.getBoundingClientRect();
        return { text: t.textContent.trim(), left: r.left, right: r.right, top: r.top, bottom: r.bottom };
      });
      return { dots, labels };
    });
    if (!scatter.dots.length) continue;
    scatters += 1;
    const gap = (d, b) => Math.hypot(Math.max(b.left - d.x, 0, d.x - b.right), Math.max(b.top - d.y, 0, d.y - b.bottom));
    // A name shared by close dots: their names between commas, a family's numbers between
    // slashes after its stem ("quadratic-pow8/16/32").
    const namesIn = (text) => text.split(", ").flatMap((part) => {
      const m = part.match(/^(.*?)(\d+(?:\/\d+)+)$/);
      return m ? m[2].split("/").map((n) => m[1] + n) : [part];
    });
    for (const label of scatter.labels) {
      const names = namesIn(label.text);
      const nearest = scatter.dots.reduce((a, d) => (gap(d, label) < gap(a, label) ? d : a));
      if (!names.includes(nearest.name)) failures.push(`${name}: '${label.text}' stands nearest ${nearest.name}'s dot (${gap(nearest, label).toFixed(1)} px; its own ${Math.min(...scatter.dots.filter((d) => names.includes(d.name)).map((d) => gap(d, label))).toFixed(1)} px)`);
      named += 1;
    }
    for (const dot of scatter.dots) {
      if (!scatter.labels.some((l) => namesIn(l.text).includes(dot.name))) failures.push(`${name}: ${dot.name}'s dot has no name beside it`);
    }
  }
  if (charts.length < 20) failures.push(`only ${charts.length} charts`);
  if (scatters < 4) failures.push(`only ${scatters} scatter charts with named dots`);
  if (messages.length) failures.push(...messages);
  console.log(`report check: ${images.length} images loaded, each a link to itself (${tiled} in tiles), ${labels.length} page labels and ${charts.length} charts' text without overlap, the smallest chart text ${smallest.toFixed(1)} px on the page, ${named} names in ${scatters} scatter charts each nearest its own dot, ${swatches.length} lobe colours distinct; screenshots in ${shots}`);
} finally {
  await browser.close();
}
if (failures.length) {
  console.error(failures.join("\n"));
  process.exit(1);
}
