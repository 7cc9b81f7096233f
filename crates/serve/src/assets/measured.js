// specula explorer, the measured-materials view: a material of the server's --data folder,
// every lobe and GGX fitted to it (n shared by the channels), and polar plots of the
// measurement (black dots) against the fits drawn (each lobe in the page's colour and dash).
// Loaded before app.js, which calls measuredStart() once the lobes' registry is in and folds
// measuredAddress() into the address, so the view is shared with the rest of the page.
"use strict";

// GGX is no lobe of the registry: Paul Tol's indigo, none of the built-in lobes' colours.
const GGX_STYLE = { colour: "#332288", dashed: false };
// Blinn fits are drawn thinner than Phong ones, the same colour and dash.
const LINE_WIDTH = { phong: 2.25, blinn: 1.1 };
const MEASURED_RENDER = { size: "256", spp: "16" };

const measured = {
  list: null,
  data: null,
  // From the address until the list says what is offered.
  material: new URLSearchParams(location.search).get("material") ?? "",
  fits: (new URLSearchParams(location.search).get("material_fits") ?? "").split(",").filter((f) => f),
  generation: 0,
};

// The view's part of the address (nothing while no material is chosen).
function measuredAddress() {
  return measured.material ? { material: measured.material, material_fits: measured.fits.join(",") } : {};
}

function fitStyle(fit) {
  if (fit.family === "ggx") return { ...GGX_STYLE, width: LINE_WIDTH.phong };
  const lobe = lobeOf(fit.family);
  return { colour: lobe.colour, dashed: lobe.dashed, width: LINE_WIDTH[fit.geometry] ?? LINE_WIDTH.phong };
}

function measuredStatus(text) { document.getElementById("measured-status").textContent = text; }

async function measuredStart() {
  try {
    measured.list = await getJson("/api/materials");
  } catch (error) {
    measuredStatus(error.message);
    return;
  }
  const names = measured.list.materials.map((m) => m.name);
  if (!names.length) {
    document.getElementById("measured-controls").hidden = true;
    measuredStatus("No measured materials: start the explorer with `specula serve --data DIR`, DIR a folder of RGL .bsdf files (the isotropic RGB ones).");
    if (measured.material) { measured.material = ""; schedule(); }
    return;
  }
  const select = document.getElementById("material");
  select.replaceChildren(new Option("choose a material", ""), ...names.map((name) => new Option(name, name)));
  const offered = `${names.length} material${names.length === 1 ? "" : "s"} offered; fitting one takes a few seconds the first time.`;
  if (measured.material && !names.includes(measured.material)) {
    measuredStatus(`From the address: material '${measured.material}' is not offered. ${offered}`);
    measured.material = "";
    schedule();
  } else if (!measured.material) {
    measuredStatus(offered);
  }
  select.value = measured.material;
  select.addEventListener("change", () => {
    measured.material = select.value;
    measured.fits = [];
    schedule();
    measuredUpdate();
  });
  document.getElementById("measured-scale").addEventListener("change", () => measuredDraw());
  if (measured.material) measuredUpdate();
}

// The fits drawn by default: pow's better geometry, GGX and the best other lobe.
function defaultFits(fits) {
  const best = (pick) => fits.filter(pick).reduce((a, b) => (b.error < a.error ? b : a), { error: Infinity });
  return [best((f) => f.family === "pow"), best((f) => f.family !== "pow" && f.family !== "ggx"), best((f) => f.family === "ggx")]
    .filter((f) => f.label).map((f) => f.label);
}

async function measuredUpdate() {
  const mine = ++measured.generation;
  const name = measured.material;
  measured.data = null;
  measuredDraw();
  if (!name) { measuredStatus(""); return; }
  const fitted = measured.list.materials.find((m) => m.name === name)?.fitted;
  measuredStatus(fitted ? `Loading ${name}…` : `Fitting every lobe and GGX to ${name}: a few seconds, once per material…`);
  let data;
  try {
    data = await getJson("/api/fits?" + new URLSearchParams({ material: name }));
  } catch (error) {
    if (mine === measured.generation) measuredStatus(error.message);
    return;
  }
  if (mine !== measured.generation) return;
  const entry = measured.list.materials.find((m) => m.name === name);
  if (entry) entry.fitted = true;
  const labels = data.fits.map((f) => f.label);
  const asked = measured.fits.filter((label) => labels.includes(label));
  const dropped = measured.fits.filter((label) => !labels.includes(label));
  measured.fits = asked.length ? asked : defaultFits(data.fits);
  measured.data = data;
  measuredStatus(`${data.description ? data.description + ". " : ""}Fitted in ${data.seconds.toFixed(1)} s (once; kept by the server).${dropped.length ? ` From the address: no fit ${dropped.join(", ")}.` : ""}`);
  schedule();
  measuredTable();
  measuredDraw();
  await measuredRenders(mine);
}

function measuredTable() {
  const data = measured.data;
  const number = (v) => (v === undefined || v === null ? "" : Number(v.toPrecision(3)));
  const triple = (v) => v.map(number).join(", ");
  const costs = data.fits.find((f) => f.costs)?.costs ?? [];
  const rows = [...data.fits].sort((a, b) => a.error - b.error).map((f) => {
    const style = fitStyle(f);
    const swatch = style.dashed ? `repeating-linear-gradient(90deg, ${style.colour} 0 4px, #fff 4px 6px)` : style.colour;
    const parameter = f.n !== undefined ? `n = ${number(f.n)}` : `α = ${number(f.alpha)}`;
    const cells = (f.costs ?? costs.map(() => null)).map((c) => `<td>${c ? c.versus_pow.toFixed(2) + "x" : ""}</td>`).join("");
    return `<tr><td><label class="inline"><input type="checkbox" value="${f.label}"${measured.fits.includes(f.label) ? " checked" : ""}> <span class="swatch" style="background:${swatch}"></span> ${f.label}</label></td><td>${parameter}</td><td>${triple(f.kd)}</td><td>${triple(f.k)}</td><td>${number(f.error)}</td><td>${number(f.relative_to_pow_best)}</td><td>${number(f.relative_to_ggx)}</td><td>${triple(f.albedo_at_normal)}</td>${f.family === "ggx" ? costs.map(() => "<td></td>").join("") : cells}</tr>`;
  });
  const heads = costs.map((c) => `<th title="${c.unit}">x pow's throughput: ${c.target}</th>`).join("");
  const table = document.getElementById("measured-fits");
  table.innerHTML = `<table><thead><tr><th>fit (draw)</th><th>n or α</th><th>kd (r, g, b)</th><th>K (r, g, b)</th><th>error E</th><th>E / pow's best</th><th>E / GGX's</th><th>albedo at normal</th>${heads}</tr></thead><tbody>${rows.join("")}</tbody></table>`
    + `<p class="note">Shared n, best first. f = kd/π + K lobe(t), K = ks N(n). E: ${data.error_measure}; pow's best E ${number(data.reference_error)}, GGX's ${number(data.ggx_error)}.${costs.length ? " Costs: throughput over pow's at the fitted n, higher is better; rates in " + costs.map((c) => `${c.target}: ${c.unit}`).join("; ") + "." : ""}</p>`;
  table.querySelectorAll("input[type=checkbox]").forEach((box) => box.addEventListener("change", () => {
    measured.fits = measured.fits.filter((label) => label !== box.value);
    // The fit checked last is the one rendered.
    if (box.checked) measured.fits.push(box.value);
    schedule();
    measuredDraw();
    measuredRenders(measured.generation);
  }));
}

// One polar plot: the plane of incidence seen from theta_o, the light's elevation across.
function measuredPolar(canvas, elevations, view, drawn, cubeRoot) {
  const g = canvas.getContext("2d");
  const [w, h] = [canvas.width, canvas.height];
  const [cx, cy, radius] = [w / 2, h - 22, Math.min(w / 2, h) - 30];
  g.clearRect(0, 0, w, h);
  g.strokeStyle = "#ccc"; g.lineWidth = 1; g.setLineDash([]);
  for (const r of [0.25, 0.5, 0.75, 1]) { g.beginPath(); g.arc(cx, cy, r * radius, Math.PI, 2 * Math.PI); g.stroke(); }
  g.beginPath(); g.moveTo(cx - radius, cy); g.lineTo(cx + radius, cy); g.stroke();
  const series = drawn.map(({ index }) => view.fits[index]);
  const peak = Math.max(1e-12, ...view.measured, ...series.flat());
  const scale = (v) => { const x = Math.max(0, v) / peak; return cubeRoot ? Math.cbrt(x) : x; };
  const at = (deg, r) => [cx + r * radius * Math.sin((deg * Math.PI) / 180), cy - r * radius * Math.cos((deg * Math.PI) / 180)];
  g.strokeStyle = "#e0a000"; g.setLineDash([4, 3]);
  g.beginPath(); g.moveTo(cx, cy); g.lineTo(...at(view.theta_o_deg, 1)); g.stroke();
  drawn.forEach(({ fit }, k) => {
    const style = fitStyle(fit);
    g.strokeStyle = style.colour; g.lineWidth = style.width; g.setLineDash(style.dashed ? DASH : []);
    g.beginPath();
    elevations.forEach((deg, i) => { const p = at(deg, scale(series[k][i])); i ? g.lineTo(...p) : g.moveTo(...p); });
    g.stroke();
  });
  g.setLineDash([]); g.fillStyle = "#000";
  elevations.forEach((deg, i) => { const [x, y] = at(deg, scale(view.measured[i])); g.beginPath(); g.arc(x, y, 1.8, 0, 2 * Math.PI); g.fill(); });
  g.fillStyle = "#444"; g.font = "11px sans-serif";
  g.fillText(`viewer (dashed) at ${view.theta_o_deg}°; radius: ${cubeRoot ? "cube root of " : ""}f cos θi / ${peak.toPrecision(3)}`, 8, 14);
}

function measuredDraw() {
  const data = measured.data;
  const plots = document.getElementById("measured-polars");
  if (!data) {
    plots.replaceChildren();
    document.getElementById("legend-measured").innerHTML = "";
    document.getElementById("measured-fits").innerHTML = "";
    document.getElementById("measured-renders").hidden = true;
    return;
  }
  const drawn = measured.fits.map((label) => ({ index: data.fits.findIndex((f) => f.label === label) }))
    .filter(({ index }) => index >= 0).map(({ index }) => ({ index, fit: data.fits[index] }));
  const cubeRoot = document.getElementById("measured-scale").checked;
  if (plots.children.length !== data.polar.length) {
    plots.replaceChildren(...data.polar.map((view, k) => Object.assign(document.createElement("canvas"), { id: `measured-polar-${k}`, width: 380, height: 220 })));
  }
  data.polar.forEach((view, k) => measuredPolar(plots.children[k], data.polar_elevations_deg, view, drawn, cubeRoot));
  const entry = (background, name) => `<span class="entry"><span class="line" style="background:${background}"></span>${name}</span>`;
  const lines = drawn.map(({ fit }) => {
    const style = fitStyle(fit);
    return entry(style.dashed ? `repeating-linear-gradient(90deg, ${style.colour} 0 5px, transparent 5px 8px)` : style.colour, fit.label);
  });
  document.getElementById("legend-measured").innerHTML = entry("radial-gradient(circle, #000 0 2px, transparent 2px) 0 0 / 6px 3px", "measured") + lines.join("")
    + (drawn.some(({ fit }) => fit.geometry === "blinn") ? '<span class="entry">(thin: Blinn geometry)</span>' : "");
}

// The measured material and the fit checked last under the sky, and their difference.
async function measuredRenders(mine) {
  const data = measured.data;
  const shown = measured.fits[measured.fits.length - 1];
  document.getElementById("measured-renders").hidden = !data || !shown;
  if (!data || !shown) return;
  document.getElementById("measured-fit-name").textContent = shown;
  document.getElementById("measured-fit-image").style.borderColor = fitStyle(data.fits.find((f) => f.label === shown)).colour;
  document.getElementById("measured-psnr").textContent = "rendering…";
  const render = (fit) => "/api/material-render?" + new URLSearchParams({ material: data.material, fit, ...MEASURED_RENDER });
  try {
    await Promise.all([loadImage(document.getElementById("measured-image"), render("measured")), loadImage(document.getElementById("measured-fit-image"), render(shown))]);
  } catch (error) {
    if (mine === measured.generation) measuredStatus(error.message);
    return;
  }
  if (mine !== measured.generation || shown !== measured.fits[measured.fits.length - 1]) return;
  drawDifference(document.getElementById("measured-fit-image"), document.getElementById("measured-image"), document.getElementById("measured-diff"), document.getElementById("measured-psnr"), "the measurement");
}
