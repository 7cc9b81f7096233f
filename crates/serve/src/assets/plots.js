// specula explorer, the 2D plots: line plots with round ticks, the polar plot and the image
// slice's axes (and its image where WebGL2 is missing), drawn on canvases.
"use strict";

// A line plot: axes with ticks, optional shaded bands, one polyline per series.
// Ticks at multiples of 1, 2 or 5 times a power of ten, the step giving the count nearest
// `count` across [lo, hi], each labelled with the digits its step needs (0.05, not
// 0.0516).
function niceTicks(lo, hi, count = 5) {
  const power = Math.pow(10, Math.floor(Math.log10((hi - lo) / count)));
  const misses = (step) => Math.abs((hi - lo) / step - count);
  const step = [1, 2, 5, 10].map((f) => f * power).reduce((best, s) => (misses(s) < misses(best) ? s : best));
  const digits = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  const ticks = [];
  for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k++) {
    const v = k * step;
    ticks.push([v, (Math.abs(v) < step / 2 ? 0 : v).toFixed(digits)]);
  }
  return ticks;
}

// The whole powers of ten in [10^lo, 10^hi], as exponents.
function decades(lo, hi) {
  const exponents = [];
  for (let k = Math.ceil(lo - 1e-9); k <= hi + 1e-9; k++) exponents.push(k);
  return exponents;
}

function plot(canvas, { series, x, y, logY = false, bands = [], xLabel = "", yLabel = "" }) {
  const g = canvas.getContext("2d");
  const [w, h] = [canvas.width, canvas.height];
  const m = { l: 66, r: 12, t: 10, b: 36 };
  g.clearRect(0, 0, w, h);
  const ty = (v) => (logY ? Math.log10(Math.max(v, y[0])) : v);
  const [y0, y1] = logY ? [Math.log10(y[0]), Math.log10(y[1])] : y;
  const px = (v) => m.l + ((v - x[0]) / (x[1] - x[0])) * (w - m.l - m.r);
  const py = (v) => h - m.b - ((ty(v) - y0) / (y1 - y0)) * (h - m.t - m.b);
  for (const [from, to, colour] of bands) {
    g.fillStyle = colour;
    g.fillRect(px(from), m.t, px(Math.min(to, x[1])) - px(from), h - m.t - m.b);
  }
  g.strokeStyle = "#999"; g.fillStyle = "#444"; g.font = "11px sans-serif"; g.lineWidth = 1;
  g.strokeRect(m.l, m.t, w - m.l - m.r, h - m.t - m.b);
  g.textAlign = "center";
  for (const [v, label] of niceTicks(x[0], x[1])) {
    g.beginPath(); g.moveTo(px(v), h - m.b); g.lineTo(px(v), h - m.b + 4); g.stroke();
    g.fillText(label, px(v), h - m.b + 15);
  }
  g.textAlign = "right";
  const yTicks = logY
    ? decades(y0, y1).map((k) => [Math.pow(10, k), `1e${k}`])
    : niceTicks(y0, y1);
  for (const [v, label] of yTicks) {
    g.beginPath(); g.moveTo(m.l - 4, py(v)); g.lineTo(m.l, py(v)); g.stroke();
    g.fillText(label, m.l - 6, py(v) + 4);
  }
  // The axis label centred under the plot, its type smaller (never under 10 px) where the
  // canvas is narrow, so it is never cut at the edge.
  g.textAlign = "center";
  for (let size = 11; size >= 10; size--) {
    g.font = `${size}px sans-serif`;
    if (g.measureText(xLabel).width <= w - 8) break;
  }
  const half = Math.min(g.measureText(xLabel).width, w - 8) / 2;
  g.fillText(xLabel, Math.min(w - 4 - half, Math.max(4 + half, (m.l + w - m.r) / 2)), h - 6, w - 8);
  g.font = "11px sans-serif";
  g.textAlign = "left";
  g.save(); g.translate(12, h / 2 + 30); g.rotate(-Math.PI / 2); g.fillText(yLabel, 0, 0); g.restore();
  g.save(); g.beginPath(); g.rect(m.l, m.t, w - m.l - m.r, h - m.t - m.b); g.clip();
  for (const s of series) {
    g.strokeStyle = s.colour; g.lineWidth = s.width ?? 2; g.setLineDash(s.dash ?? []);
    g.beginPath();
    s.points.forEach(([a, b], i) => (i ? g.lineTo(px(a), py(b)) : g.moveTo(px(a), py(b))));
    g.stroke();
  }
  g.restore();
}

function zip(xs, ys) { return xs.map((v, i) => [v, ys[i]]); }

function drawPolar(canvas, data, thetaIn) {
  const g = canvas.getContext("2d");
  const [w, h] = [canvas.width, canvas.height];
  const [cx, cy, radius] = [w / 2, h - 20, Math.min(w / 2, h) - 30];
  g.clearRect(0, 0, w, h);
  g.strokeStyle = "#ccc"; g.lineWidth = 1;
  for (const r of [0.25, 0.5, 0.75, 1]) { g.beginPath(); g.arc(cx, cy, r * radius, Math.PI, 2 * Math.PI); g.stroke(); }
  g.beginPath(); g.moveTo(cx - radius, cy); g.lineTo(cx + radius, cy); g.stroke();
  const peak = Math.max(1e-12, ...data.flatMap((d) => d.polar));
  const at = (theta, r) => [cx + r * radius * Math.sin(theta), cy - r * radius * Math.cos(theta)];
  // The light: a thin grey line ending in a disc, a style no lobe has (an amber dash was
  // schlick-mod's orange dash to the eye).
  const light = at((thetaIn * Math.PI) / 180, 1);
  g.strokeStyle = "#666"; g.fillStyle = "#666"; g.setLineDash([]);
  g.beginPath(); g.moveTo(cx, cy); g.lineTo(...light); g.stroke();
  g.beginPath(); g.arc(...light, 4, 0, 2 * Math.PI); g.fill();
  for (const d of data) {
    g.strokeStyle = colourOf(d.lobe); g.lineWidth = 2; g.setLineDash(dashOf(d.lobe)); g.beginPath();
    d.polar_deg.forEach((deg, i) => { const p = at((deg * Math.PI) / 180, d.polar[i] / peak); i ? g.lineTo(...p) : g.moveTo(...p); });
    g.stroke();
  }
  g.setLineDash([]);
  g.fillStyle = "#444"; g.font = "11px sans-serif";
  g.fillText("light (grey, with a disc) at " + thetaIn + "°; radius: f / " + peak.toPrecision(3), 8, 14);
}

// The slice's colour map, from 0 (the bottom of the range) to 1 (its top).
function sliceColour(s) {
  return [255 * Math.min(1, 1.6 * s), 255 * Math.max(0, 2 * s - 1) * 0.9, 255 * (0.3 + 0.7 * Math.max(0, s - 0.5))];
}

// The slice with its axes: theta_h across on the API's square-root scale (column i at
// 90 (i / (size - 1))^2 degrees), theta_d down, and a colour bar in decades of f. With
// `live`, slice.js draws the image and the bar at every pixel over it, and only the axes and
// labels are drawn here.
function drawSlice(canvas, d, live = false) {
  const g = canvas.getContext("2d");
  const size = d.slice_size;
  const { left, top, right, bottom } = SLICE_MARGINS;
  const [w, h] = [canvas.width - left - right, canvas.height - top - bottom];
  const logs = d.slice.map((v) => (v > 0 ? Math.log10(v) : -Infinity));
  const high = Math.max(...logs.filter(Number.isFinite));
  const low = high - 6;
  const image = g.createImageData(size, size);
  logs.forEach((v, k) => {
    const s = Number.isFinite(v) ? Math.min(1, Math.max(0, (v - low) / (high - low))) : 0;
    image.data.set([...sliceColour(s), 255], 4 * k);
  });
  const scratch = Object.assign(document.createElement("canvas"), { width: size, height: size });
  scratch.getContext("2d").putImageData(image, 0, 0);
  g.clearRect(0, 0, canvas.width, canvas.height);
  g.imageSmoothingEnabled = false;
  if (!live) g.drawImage(scratch, left, top, w, h);
  g.fillStyle = "#333"; g.strokeStyle = "#333"; g.font = "11px sans-serif"; g.lineWidth = 1;
  g.fillText(`${d.lobe}: specular term f, log scale, phi_d = 90°`, left, 14);
  // Ticks sit at the centre of the column or row that holds the angle.
  const column = live ? (deg) => left + w * Math.sqrt(deg / 90) : (deg) => left + ((size - 1) * Math.sqrt(deg / 90) + 0.5) * (w / size);
  const row = live ? (deg) => top + h * (deg / 90) : (deg) => top + ((size - 1) * (deg / 90) + 0.5) * (h / size);
  g.textAlign = "center";
  for (const deg of [0, 1, 5, 10, 20, 45, 90]) {
    const x = column(deg);
    g.beginPath(); g.moveTo(x, top + h); g.lineTo(x, top + h + 4); g.stroke();
    g.fillText(String(deg), x, top + h + 15);
  }
  g.fillText("θh (degrees, square-root scale)", left + w / 2, top + h + 30);
  g.textAlign = "right";
  for (const deg of [0, 15, 30, 45, 60, 75, 90]) {
    const y = row(deg);
    g.beginPath(); g.moveTo(left - 4, y); g.lineTo(left, y); g.stroke();
    g.fillText(String(deg), left - 6, y + 4);
  }
  g.save(); g.translate(10, top + h / 2); g.rotate(-Math.PI / 2); g.textAlign = "center";
  g.fillText("θd (degrees)", 0, 0); g.restore();
  // The colour bar: its top is the slice's largest value, six decades down is black.
  const [barX, barW] = [left + w + SLICE_BAR.gap, SLICE_BAR.width];
  for (let y = 0; y < h && !live; y++) {
    g.fillStyle = `rgb(${sliceColour(1 - y / (h - 1)).join(",")})`;
    g.fillRect(barX, top + y, barW, 1);
  }
  g.fillStyle = "#333"; g.textAlign = "left";
  for (const k of decades(low, high)) {
    const y = top + (h - 1) * (1 - (k - low) / (high - low));
    g.beginPath(); g.moveTo(barX + barW, y); g.lineTo(barX + barW + 3, y); g.stroke();
    g.fillText(`1e${k}`, barX + barW + 5, y + 4);
  }
  g.textAlign = "left";
}

