// specula explorer: controls -> URL -> API -> plots. No dependencies; everything drawn on
// canvases. The state lives in the address (history.replaceState), so a view can be shared.
"use strict";

// Each lobe's colour and dash come from the library (/api/models), the same as the report's.
const DASH = [7, 4];
// Phong geometry with the lobe's own normalisation: energy-conserving (albedo <= 1) for every
// lobe, so the first view is physically sensible.
const DEFAULTS = { lobes: "pow,schlick,schlick-mod", formula: "", n: "64", geometry: "phong", normalisation: "lobe", shading: "phong", model: "classic", theta_in: "30", light_theta: "30", light_phi: "45", log: "0", render: "", volume: "phantom", view: "anterior", gpu: "sm_89" };
const $ = (id) => document.getElementById(id);
let registry = null;
let generation = 0;
// The lobe the renders show: the one the user chose last.
let renderLobe = "";
// The text box's lobe, as the page names it; the API gets its text as `lobe==FORMULA`.
const FORMULA = "formula";
// Paul Tol's wine: a user's lobe never looks like a built-in one (the library's first user colour).
const FORMULA_STYLE = { colour: "#882255", dashed: false };
// Typing pauses this long before the formula is sent.
const FORMULA_DEBOUNCE_MS = 300;
// The longest request target the server reads (hyper's), in bytes, and the room the
// longest request (a render's) needs beside the formula.
const MAX_ADDRESS = 65534;
const ADDRESS_ROOM = 512;

function readState() {
  const query = new URLSearchParams(location.search);
  const state = {};
  for (const key of Object.keys(DEFAULTS)) state[key] = query.get(key) ?? DEFAULTS[key];
  return state;
}

// The slider is logarithmic and lands on integers; the number box takes any n in [1, 1000].
function nFromSlider(v) { return Math.min(1000, Math.max(1, Math.round(Math.pow(10, v / 100)))); }
function sliderFromN(n) { return Math.round(100 * Math.log10(n)); }

// A lobe as the API names it: its id, and each parameter that differs from its default
// (`cosquad:v=2`).
function lobeName(box) {
  const lobe = registry.lobes.find((l) => l.id === box.value);
  const given = (lobe.params ?? [])
    .map((p) => [p, Number(document.getElementById(`param-${lobe.id}-${p.name}`).value)])
    .filter(([p, value]) => value !== p.default)
    .map(([p, value]) => `${p.name}=${value}`);
  return given.length ? `${lobe.id}:${given.join(",")}` : lobe.id;
}

// The formula in the text box, if any (blank counts as none).
function formulaText() { return $("formula").value.trim() ? $("formula").value : ""; }

// A lobe's name as the API takes it: the page's `formula` is the text box's text.
function apiLobe(name) { return name === FORMULA ? "=" + formulaText() : name; }

function currentState() {
  const boxes = [...document.querySelectorAll("#lobes input[type=checkbox]:checked")];
  const lobes = boxes.map(lobeName);
  const ids = boxes.map((box) => box.value);
  const formula = formulaText();
  // The formula's lobe comes after the boxes' and may be the one the renders show.
  const names = formula ? [...lobes, FORMULA] : lobes;
  if (formula) ids.push(FORMULA);
  if (!ids.includes(renderLobe)) renderLobe = ids.length ? ids[ids.length - 1] : "";
  fillRenderChoice(ids, renderLobe);
  return {
    lobes: lobes.join(","),
    formula,
    n: $("n-box").value,
    geometry: $("geometry").value,
    normalisation: $("normalisation").value,
    shading: $("shading").value,
    model: $("model").value,
    theta_in: $("theta_in").value,
    light_theta: $("light_theta").value,
    light_phi: $("light_phi").value,
    log: $("log").checked ? "1" : "0",
    render: names[ids.indexOf(renderLobe)] ?? "",
    volume: $("volume").value,
    view: $("view").value,
    gpu: $("gpu").value,
    // The measured-materials view's (measured.js), when a material is chosen.
    ...measuredAddress(),
  };
}

function fillSelect(id, values, chosen) {
  const select = $(id);
  select.replaceChildren(...values.map((v) => new Option(v, v, false, v === chosen)));
}

function buildControls(state) {
  // What the address asked for and could not have is said, not silently replaced.
  const notes = [];
  const known = new Set(registry.lobes.map((l) => l.id));
  const asked = state.lobes.split(",").filter((name) => name);
  const idOf = (name) => name.split(":")[0];
  const paramsOf = (name) => Object.fromEntries((name.split(":")[1] ?? "").split(",").filter((p) => p).map((p) => p.split("=")));
  for (const name of asked.filter((name) => !known.has(idOf(name)))) notes.push(`unknown lobe '${name}' left out`);
  const chosen = new Map(asked.filter((name) => known.has(idOf(name))).map((name) => [idOf(name), paramsOf(name)]));
  $("lobes").replaceChildren(...registry.lobes.map((lobe) => {
    const label = document.createElement("label");
    const box = Object.assign(document.createElement("input"), { type: "checkbox", value: lobe.id, checked: chosen.has(lobe.id) });
    box.addEventListener("change", () => { if (box.checked) renderLobe = lobe.id; });
    const swatch = Object.assign(document.createElement("span"), { className: "swatch", title: lobe.formula });
    swatch.style.background = lobe.dashed
      ? `repeating-linear-gradient(90deg, ${lobe.colour} 0 4px, #fff 4px 6px)`
      : lobe.colour;
    label.append(box, swatch, lobe.id);
    // Every lobe parameter gets a control (cosquad's v).
    for (const p of lobe.params ?? []) {
      const asked = Number((chosen.get(lobe.id) ?? {})[p.name] ?? p.default);
      const valid = Number.isInteger(asked) && asked >= p.min && asked <= p.max;
      if (!valid) notes.push(`${lobe.id} ${p.name} = '${asked}' is outside [${p.min}, ${p.max}]; using ${p.default}`);
      const input = Object.assign(document.createElement("input"), {
        type: "number", id: `param-${lobe.id}-${p.name}`, min: p.min, max: p.max, step: 1,
        value: valid ? asked : p.default, title: p.description, className: "param",
      });
      input.setAttribute("aria-label", `${lobe.id} ${p.name}`);
      label.append(` ${p.name} `, input);
    }
    label.title = lobe.summary;
    return label;
  }));
  const select = (id, values) => {
    if (!values.includes(state[id])) {
      notes.push(`${id} '${state[id]}' is not one of ${values.join(", ")}; using ${DEFAULTS[id]}`);
      state[id] = DEFAULTS[id];
    }
    fillSelect(id, values, state[id]);
  };
  select("geometry", registry.geometries);
  select("normalisation", registry.normalisations);
  select("shading", registry.shadings);
  select("model", registry.models);
  select("volume", registry.volumes);
  select("view", registry.views);
  select("gpu", registry.gpus.map((gpu) => gpu.id));
  // An address from before every panel followed the chosen lobe.
  if (new URLSearchParams(location.search).has("volume_lobe")) notes.push("volume_lobe is no longer a choice of its own: the volume shows the chosen lobe, as every panel does");
  $("formula").value = state.formula;
  const limits = registry.formula;
  $("formula-help").textContent = `An expression of t (the cosine, 0 to 1) and n (the exponent), after any "let NAME = ...;". Operators + - * / ^; comparisons < <= > >= as the condition of select or if; # starts a comment. Functions: ${limits.functions.join(", ")}; constants pi, e. Its value must stay in [0, 1]; up to ${limits.max_bytes} bytes.`;
  let n = Number(state.n);
  if (!(n >= 1 && n <= 1000)) {
    notes.push(`n = '${state.n}' is outside [1, 1000]; using ${DEFAULTS.n}`);
    n = Number(DEFAULTS.n);
  }
  $("n-box").value = String(n);
  $("n").value = sliderFromN(n);
  renderLobe = [...chosen.keys()].includes(idOf(state.render)) ? idOf(state.render)
    : state.render === FORMULA && formulaText() ? FORMULA : "";
  for (const id of ["theta_in", "light_theta", "light_phi"]) $(id).value = state[id];
  $("log").checked = state.log === "1";
  $("notes").textContent = notes.length ? "From the address: " + notes.join("; ") + "." : "";
}

// `shown` has the lobes the renders draw: the state's, unless the formula is refused.
// The lobes drawn, offered to the images' choice; `chosen` selected.
function fillRenderChoice(ids, chosen) {
  const select = $("render-choice");
  const same = [...select.options].map((o) => o.value).join(",") === ids.join(",");
  if (!same) select.replaceChildren(...ids.map((id) => new Option(id, id)));
  select.value = chosen;
}

function showValues(state, shown) {
  $("render-lobe").textContent = shown.render || "no lobe";
  $("environment-lobe").textContent = shown.render || "no lobe";
  $("environment-image").style.borderColor = colourOf(shown.render);
  $("environment-pow").style.borderColor = colourOf("pow");
  $("volume-lobe-name").textContent = shown.render || "pow";
  $("volume-image").style.borderColor = colourOf(shown.render || "pow");
  $("volume-pow").style.borderColor = colourOf("pow");
  $("theta_in-value").textContent = state.theta_in + "°";
  $("light_theta-value").textContent = state.light_theta + "°";
  $("light_phi-value").textContent = state.light_phi + "°";
}

function lobeOf(name) {
  if (name === FORMULA) return FORMULA_STYLE;
  return registry.lobes.find((l) => l.id === name.split(":")[0]) ?? { colour: "#000", dashed: false };
}
function colourOf(id) { return lobeOf(id).colour; }
function dashOf(id) { return lobeOf(id).dashed ? DASH : []; }

// The API's JSON; a refusal throws an Error whose `refusal` is the API's one-line `error`.
async function getJson(url, signal = undefined, view = "") {
  const response = await fetch(url, { signal, headers: view ? viewHeader(view) : {} });
  const text = await response.text();
  let body = null;
  try { body = JSON.parse(text); } catch { /* not JSON: an HTTP-level refusal (414) */ }
  if (!response.ok || body === null) {
    const refusal = body?.error ?? `the server answered ${response.status} ${response.statusText}`.trim();
    throw Object.assign(new Error(refusal + (body?.valid ? " (valid: " + body.valid + ")" : "")), { refusal });
  }
  return body;
}

// Why the formula cannot be sent in `url`, or "" if it can: the API's length limit, said
// before the server refuses it, and the longest address the server reads.
function formulaTooLong(url) {
  const bytes = new TextEncoder().encode(formulaText()).length;
  if (bytes > registry.formula.max_bytes) return `the formula is ${bytes} bytes long; the limit is ${registry.formula.max_bytes}`;
  if (url.length + ADDRESS_ROOM > MAX_ADDRESS) return `the formula is too long to send: ${url.length} characters once percent-encoded, and the server reads addresses of up to ${MAX_ADDRESS}`;
  return "";
}

// The formula's refusal beside the text box (empty: none).
function showFormulaError(message) {
  $("formula-error").textContent = message;
  $("formula").setAttribute("aria-invalid", message ? "true" : "false");
}

function analysisTable(reports) {
  const pct = (v) => (100 * v).toPrecision(3) + " %";
  const costs = reports.length ? reports[0].costs : [];
  const costHeads = costs.map((c) => `<th title="${c.unit}">x pow's throughput: ${c.target}</th>`).join("");
  const rows = reports.map((r) => `<tr><td>${r.lobe}</td><td>${pct(r.epicentre_max_rel)}</td><td>${r.bloom_max_abs.toPrecision(3)}</td><td>${r.rms.toPrecision(3)}</td><td>${r.energy_ratio.toPrecision(4)}</td><td>${r.max_albedo.toPrecision(4)}</td>${r.costs.map((c) => `<td title="${Number(c.value.toPrecision(3))} ${c.unit}">${c.versus_pow.toFixed(2)}x</td>`).join("")}</tr>`);
  const units = costs.map((c) => `${c.target}: ${c.unit}`).join("; ");
  return `<table><thead><tr><th>lobe</th><th>epicentre max rel</th><th>bloom max abs</th><th>rms</th><th>energy ratio</th><th>max albedo (lobe-normalised)</th>${costHeads}</tr></thead><tbody>${rows.join("")}</tbody></table>${units ? `<p class="note">Costs: each lobe's throughput over pow's at this n on the target, higher is better (each cell's own rate on hover); rates in ${units}.</p>` : ""}`;
}

// The page's name for itself in the views it asks for (supersede.rs): a newer request for
// the same view makes the server skip an older one still waiting for its turn.
const PAGE_ID = Math.random().toString(36).slice(2, 10);

// The header naming a view, its name as URL-encoded ASCII (a formula lobe names views too).
function viewHeader(view) {
  return { "X-Specula-View": `${PAGE_ID}/${encodeURIComponent(view)}` };
}

// `url`'s image into `img` (its address kept in data-source), fetched with the view's name so
// that the server drops a superseded one, and aborted with `signal`. An image already showing
// `url` is left alone: the volume renders take the server a while, and most controls do not
// change them.
async function loadImage(img, url, signal = undefined) {
  if (img.dataset.source === url && img.complete && img.naturalWidth > 0) return;
  const response = await fetch(url, { signal, headers: viewHeader(img.id) });
  if (!response.ok) throw new Error("render failed: " + url.split("?")[0] + ` (${response.status})`);
  const address = URL.createObjectURL(await response.blob());
  await new Promise((resolve, reject) => {
    img.onload = () => resolve();
    img.onerror = () => reject(new Error("render failed: " + url.split("?")[0]));
    if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
    img.src = address;
  });
  img.dataset.source = url;
}

// A control's refusal beside it (empty: none), and the control marked.
function showControlError(id, message) {
  $(id + "-error").textContent = message;
  $(id === "n" ? "n-box" : id).setAttribute("aria-invalid", message ? "true" : "false");
}

// Requests of the update a newer one superseded are cancelled.
let inFlight = null;

async function update() {
  const state = currentState();
  showValues(state, state);
  const n = Number(state.n);
  const [low, high] = registry.n;
  if (state.n.trim() === "" || !(n >= low && n <= high)) {
    showControlError("n", `n = '${state.n}' is outside [${low}, ${high}]: type a number from ${low} to ${high}; the views still show the last valid n`);
    markStale(true);
    return;
  }
  showControlError("n", "");
  // A drawn lobe's parameter (its box ticked) outside its range.
  const badParameter = [...document.querySelectorAll("#lobes .param")].find((input) => {
    const v = Number(input.value);
    if (!input.closest("label").querySelector("input[type=checkbox]").checked) return false;
    return input.value.trim() === "" || !Number.isInteger(v) || v < Number(input.min) || v > Number(input.max);
  });
  document.querySelectorAll("#lobes .param").forEach((input) => input.setAttribute("aria-invalid", String(input === badParameter)));
  $("lobes-error").textContent = badParameter ? `${badParameter.getAttribute("aria-label")} = '${badParameter.value}' must be a whole number in [${badParameter.min}, ${badParameter.max}]` : "";
  if (badParameter) {
    markStale(true);
    return;
  }
  const query = "?" + new URLSearchParams(state).toString();
  history.replaceState(null, "", query);
  const mine = ++generation;
  inFlight?.abort();
  inFlight = new AbortController();
  const signal = inFlight.signal;
  // Each lobe's curves and analysis are a view of their own.
  const json = (url) => {
    const address = new URL(url, location.href);
    return getJson(url, signal, address.pathname + "/" + address.searchParams.get("lobe"));
  };
  const boxes = state.lobes ? state.lobes.split(",") : [];
  const common = { n: state.n, geometry: state.geometry, normalisation: state.normalisation };
  const evaluate = (name) => "/api/evaluate?" + new URLSearchParams({ lobe: apiLobe(name), ...common, theta_in: state.theta_in });
  liveLobes(state, state.render, state.formula ? [...boxes, FORMULA] : boxes);
  try {
    // The formula's own request settles apart: its refusal is shown beside the text box, and
    // the other lobes are drawn all the same.
    const tooLong = state.formula ? formulaTooLong(evaluate(FORMULA)) : "";
    const formula = !state.formula ? Promise.resolve({})
      : tooLong ? Promise.resolve({ refusal: tooLong })
      : json(evaluate(FORMULA)).then((data) => ({ data }), (error) => ({ refusal: error.refusal ?? error.message }));
    const [builtIn, typed] = await Promise.all([Promise.all(boxes.map((lobe) => json(evaluate(lobe)))), formula]);
    if (mine !== generation) return;
    showFormulaError(typed.refusal ?? "");
    const lobes = typed.data ? [...boxes, FORMULA] : boxes;
    // The page names the formula's lobe `formula`, whatever the server numbered it.
    const data = typed.data ? [...builtIn, { ...typed.data, lobe: FORMULA }] : builtIn;
    const reports = await Promise.all(lobes.map((lobe) => json("/api/analyze?" + new URLSearchParams({ lobe: apiLobe(lobe), n: state.n })).then((r) => ({ ...r, lobe }))));
    if (mine !== generation) return;
    // A refused formula is drawn nowhere: every panel shows the last box's lobe instead.
    const shown = {
      render: state.render === FORMULA && !typed.data ? boxes[boxes.length - 1] ?? "" : state.render,
    };
    showValues(state, shown);
    liveLobes(state, shown.render, lobes);
    draw(data, { ...state, render: shown.render });
    warnAboutAlbedo(data, state);
    $("analysis").innerHTML = lobes.length ? analysisTable(reports) : "<p>Choose a lobe.</p>";
    markFresh("plots", "analysis");
    await updateIsa(apiLobe(shown.render || "pow"), shown.render || "pow", state.n, signal);
    if (mine !== generation) return;
    if (shown.render) {
      const render = (object) => "/api/render?" + new URLSearchParams({ object, lobe: apiLobe(shown.render), ...common, shading: state.shading, model: state.model, light_theta: state.light_theta, light_phi: state.light_phi, size: "512" });
      // The sphere is drawn live (linked.js); the server's is for a browser without WebGL2.
      const sphere = live.spheres ? Promise.resolve() : loadImage($("sphere"), render("sphere"), signal);
      const teapot = live.teapot && ["phong", "gouraud"].includes(state.shading) ? Promise.resolve() : loadImage($("teapot"), render("teapot"), signal);
      await Promise.all([sphere, teapot]);
      if (mine !== generation) return;
      markFresh("teapot");
      const environment = (lobe) => "/api/environment?" + new URLSearchParams({ lobe, ...common, size: "384", spp: "16" });
      await Promise.all([loadImage($("environment-image"), environment(apiLobe(shown.render)), signal), loadImage($("environment-pow"), environment("pow"), signal)]);
      if (mine !== generation) return;
      drawDifference($("environment-image"), $("environment-pow"), $("environment-diff"), $("environment-psnr"));
      markFresh("environment");
    }
    const volume = (lobe) => "/api/volume?" + new URLSearchParams({ volume: state.volume, view: state.view, lobe, ...common, size: "256" });
    await Promise.all([loadImage($("volume-image"), volume(apiLobe(shown.render || "pow")), signal), loadImage($("volume-pow"), volume("pow"), signal)]);
    if (mine !== generation) return;
    drawDifference($("volume-image"), $("volume-pow"), $("volume-diff"), $("volume-psnr"));
    markFresh("volume");
    $("status").textContent = "";
    markStale(false);
    // What is on the page now: the count of finished updates and the state they drew.
    document.body.dataset.drawn = query;
    document.body.dataset.updates = String(Number(document.body.dataset.updates) + 1);
  } catch (error) {
    if (mine === generation) $("status").textContent = error.message;
  }
}

// What the plots show now, for a redraw at another width.
let lastDrawn = null;
let resizing = 0;

// A plot canvas as wide as its section, in the proportion it was drawn at (560 x 320).
function fitWidth(canvas) {
  const style = getComputedStyle(canvas.parentElement);
  const inner = canvas.parentElement.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
  const width = Math.max(320, Math.floor(inner));
  if (canvas.width !== width) [canvas.width, canvas.height] = [width, Math.round(width * 320 / 560)];
}

function draw(data, state) {
  lastDrawn = [data, state];
  for (const id of ["cartesian", "error", "polar", "albedo"]) fitWidth($(id));
  const right = Math.max(1e-3, ...data.map((d) => d.angles_deg[d.angles_deg.length - 1]));
  const first = data[0];
  const bands = first ? [[0, first.epicentre_deg, "rgba(255,200,0,0.18)"], [first.epicentre_deg, first.bloom_deg, "rgba(0,120,255,0.08)"]] : [];
  const logY = state.log === "1";
  plot($("cartesian"), {
    series: data.map((d) => ({ points: zip(d.angles_deg, d.values), colour: colourOf(d.lobe), dash: dashOf(d.lobe) })).concat(first ? [{ points: zip(first.angles_deg, first.reference), colour: "#888", width: 1, dash: [5, 4] }] : []),
    x: [0, right], y: logY ? [1e-4, 1] : [0, 1.05], logY, bands,
    xLabel: "angle from the lobe's axis (degrees); dashed: t^n", yLabel: "lobe",
  });
  const errors = data.flatMap((d) => d.error);
  const spread = Math.max(1e-6, ...errors.map(Math.abs));
  plot($("error"), { series: data.map((d) => ({ points: zip(d.angles_deg, d.error), colour: colourOf(d.lobe), dash: dashOf(d.lobe) })), x: [0, right], y: [-spread * 1.05, spread * 1.05], bands, xLabel: "angle (degrees)", yLabel: "lobe - t^n" });
  drawPolar($("polar"), data, Number(state.theta_in));
  const albedoTop = Math.max(1.05, ...data.flatMap((d) => d.albedo));
  plot($("albedo"), { series: data.map((d) => ({ points: zip(d.albedo_deg, d.albedo), colour: colourOf(d.lobe), dash: dashOf(d.lobe) })), x: [0, 90], y: [0, albedoTop], xLabel: "angle of incidence (degrees)", yLabel: "albedo" });
  // The slice is of the lobe every panel shows (the chosen one), else the first.
  const chosen = data.find((d) => d.lobe === state.render || d.lobe === state.render.split(":")[0]) ?? first;
  if (chosen) drawSlice($("slice"), chosen, Boolean(live.slice));
  // A legend under each plot: every lobe drawn, in its colour and dash.
  const entry = (colour, dashed, name) => {
    const line = dashed ? `repeating-linear-gradient(90deg, ${colour} 0 5px, transparent 5px 8px)` : colour;
    return `<span class="entry"><span class="line" style="background:${line}"></span>${name}</span>`;
  };
  const entries = data.map((d) => entry(colourOf(d.lobe), lobeOf(d.lobe).dashed, d.lobe)).join("");
  $("legend-cartesian").innerHTML = entries + (first ? entry("#888", true, "t<sup>n</sup>") : "");
  for (const id of ["error", "polar", "albedo"]) $("legend-" + id).innerHTML = entries;
}

// Above 1, the BRDF reflects more than it receives: said whenever it happens.
function warnAboutAlbedo(data, state) {
  let worst = null;
  for (const d of data) {
    const top = Math.max(...d.albedo);
    if (!worst || top > worst.top) worst = { lobe: d.lobe, top };
  }
  $("warning").textContent = worst && worst.top > 1.0005
    ? `Albedo reaches ${worst.top.toPrecision(3)} (${worst.lobe}, ${state.geometry} geometry, ${state.normalisation} normalisation): above 1, this BRDF creates energy. Phong geometry with the lobe normalisation conserves it.`
    : "";
}

let pending = null;
function schedule() {
  clearTimeout(pending);
  markStale(true);
  liveRedraw();
  // While a drag moves, only the live views follow; the server's when it ends.
  if (!live.dragging) pending = setTimeout(update, 60);
}

async function start() {
  registry = await getJson("/api/models");
  buildControls(readState());
  liveStart();
  // Not awaited: the measured view fills itself in while the rest of the page draws.
  measuredStart().catch((error) => measuredStatus(error.message));
  $("n").addEventListener("input", () => { $("n-box").value = String(nFromSlider(Number($("n").value))); });
  $("n-box").addEventListener("input", () => {
    const n = Number($("n-box").value);
    if (n >= 1 && n <= 1000) $("n").value = sliderFromN(n);
  });
  document.querySelectorAll("#controls input, #controls select, #volume-controls select, #isa-controls select").forEach((el) => el.addEventListener("input", schedule));
  $("lobes").addEventListener("change", schedule);
  $("render-choice").addEventListener("change", () => { renderLobe = $("render-choice").value; schedule(); });
  $("design-run").addEventListener("click", runDesign);
  // Typing in the formula makes it the lobe every panel shows; a pause sends it.
  $("formula").addEventListener("input", () => {
    if (formulaText()) renderLobe = FORMULA;
    clearTimeout(pending);
    pending = setTimeout(update, FORMULA_DEBOUNCE_MS);
  });
  // The plots take the width their sections have, redrawn when the window changes.
  window.addEventListener("resize", () => {
    clearTimeout(resizing);
    resizing = setTimeout(() => { if (lastDrawn) draw(...lastDrawn); liveRedraw(); }, 100);
  });
  await update();
}

// `specula design` through /api/design: its verdict under the button, and the cheapest
// designed lobe that meets the bound put in the formula box, where it is drawn and rendered.
async function runDesign() {
  const query = new URLSearchParams({ target: $("design-target").value, low: $("design-low").value, high: $("design-high").value, max_error: $("design-error").value });
  $("design-run").disabled = true;
  $("design-result").textContent = "designing...";
  try {
    const answer = await getJson("/api/design?" + query);
    const best = answer.designed.find((lobe) => lobe.meets);
    $("design-result").textContent = answer.verdict;
    if (best) {
      $("formula").value = best.formula;
      $("formula").dispatchEvent(new Event("input"));
    }
  } catch (error) {
    $("design-result").textContent = error.message;
  } finally {
    $("design-run").disabled = false;
  }
}

start().catch((error) => { $("status").textContent = error.message; });
