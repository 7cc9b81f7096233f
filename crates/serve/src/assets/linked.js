// specula explorer, the linked live views and the pointer: the lit spheres (live.js) and the
// 3D lobe (lobe3d.js) follow the controls at once, drawn by WebGL2 from the exported GLSL;
// dragging the light over the spheres, the incidence over the polar plot or the 3D lobe, and
// the wheel over a plot change the controls, and the server's views follow when a drag ends
// (app.js's schedule). Without WebGL2 the server's sphere image is shown instead.
"use strict";

const live = { spheres: null, lobe: null, slice: null, slicePow: null, teapot: null, chosen: null, frame: 0, key: "", programs: "", lobes: [], drawnLobes: null, dragging: false };
// The polar plot's outgoing angles while a drag redraws it from the GPU (-90 to 90 degrees).
const LIVE_POLAR_DEG = Array.from({ length: 181 }, (_, k) => k - 90);

function liveStart() {
  try {
    live.spheres = new LiveSpheres($("live-spheres"), $("live-ticks"), registry.live);
    live.lobe = new LiveLobe($("lobe3d"));
    live.slice = new LiveSlice($("slice-live"), $("slice"));
    live.slicePow = new LiveSlice($("slice-pow-live"), $("slice-pow"));
  } catch (error) {
    // No WebGL2 (or a driver that cannot compile the shaders): the server's image, as before.
    live.spheres = live.lobe = live.slice = live.slicePow = null;
    $("live-views").hidden = true;
    $("lobe3d-view").hidden = true;
    $("sphere").hidden = false;
    $("live-note").textContent = `Drawn by the server: this browser has no WebGL2 (${error.message}).`;
    return;
  }
  document.body.dataset.live = "webgl2";
  // The teapot's mesh comes once; until then (and for gouraud shading) the server's image.
  getJson("/api/teapot").then((mesh) => {
    live.teapot = new LiveTeapot($("live-teapot"), registry.live, mesh);
    if (live.chosen) live.teapot.setLobe(...live.chosen);
    liveRedraw();
  }, (error) => { $("teapot-by").textContent = `CPU renderer (${error.message})`; });
  $("sphere").hidden = true;
  $("slice-live").hidden = false;
  $("slice-pow-wrap").hidden = false;
  pointerDrag($("live-spheres"), (event) => {
    const at = live.spheres.lightAt(event.clientX, event.clientY);
    if (!at) return;
    $("light_theta").value = String(Math.round(at.theta));
    $("light_phi").value = String(Math.round(at.phi / 5) * 5);
    liveRedraw();
  });
  pointerDrag($("polar"), (event) => {
    const box = $("polar").getBoundingClientRect();
    const [x, y] = [event.clientX - box.left, event.clientY - box.top];
    // The plot's centre sits at the bottom middle (app.js's drawPolar).
    const angle = (Math.atan2(x - box.width / 2, box.height - 20 - y) * 180) / Math.PI;
    setIncidence(Math.abs(angle));
  });
  let last = null;
  pointerDrag($("lobe3d"), (event) => {
    if (last && event.shiftKey) setIncidence(Number($("theta_in").value) + 0.3 * (event.clientX - last.x));
    else if (last) {
      live.lobe.yaw += 0.01 * (event.clientX - last.x);
      live.lobe.pitch = Math.max(-0.2, Math.min(1.5, live.lobe.pitch + 0.01 * (event.clientY - last.y)));
    }
    last = { x: event.clientX, y: event.clientY };
    liveRedraw();
  }, () => { last = null; });
  for (const id of ["cartesian", "error", "polar", "lobe3d", "live-spheres"]) $(id).addEventListener("wheel", wheelExponent, { passive: false });
}

function setIncidence(degrees) {
  $("theta_in").value = String(Math.round(Math.max(0, Math.min(89, degrees))));
  liveRedraw();
}

// The wheel steps n along its logarithmic slider (five steps a notch), as if the slider moved.
function wheelExponent(event) {
  event.preventDefault();
  const slider = $("n");
  slider.value = String(Number(slider.value) + (event.deltaY < 0 ? 5 : -5));
  slider.dispatchEvent(new Event("input", { bubbles: true }));
}

// `move` on every pointer move while a button is held over `element` (captured, so the drag
// may leave it); when the drag ends, `end` and the server's views are brought up to date.
function pointerDrag(element, move, end = () => {}) {
  element.addEventListener("pointerdown", (event) => {
    element.setPointerCapture(event.pointerId);
    live.dragging = true;
    move(event);
  });
  element.addEventListener("pointermove", (event) => { if (live.dragging && element.hasPointerCapture(event.pointerId)) move(event); });
  const finish = (event) => {
    if (!element.hasPointerCapture(event.pointerId)) return;
    element.releasePointerCapture(event.pointerId);
    live.dragging = false;
    end();
    markStale(true);
    schedule();
  };
  element.addEventListener("pointerup", finish);
  element.addEventListener("pointercancel", finish);
}

// Compiles the shown lobe and pow (the spheres), and every drawn lobe (the 3D lobe and the
// polar plot while dragging), once their GLSL has arrived; a newer call wins. In the
// microfacet model the spheres and the teapot draw each lobe's Blinn export (normalisation
// none) as the distribution, with its terms at n (/api/microfacet); the 3D lobe and the
// slices keep showing the lobe itself.
async function liveLobes(state, shown, lobes) {
  if (!live.spheres) return;
  const common = [state.n, state.geometry, state.normalisation];
  const key = JSON.stringify([shown, lobes, common, state.model, state.formula]);
  if (key === live.key) return liveRedraw();
  live.key = key;
  const names = [...new Set([shown || "pow", ...lobes, "pow"])];
  const microfacet = state.model === "microfacet";
  const shaded = [...new Set([shown || "pow", "pow"])];
  const [texts, shadedTexts, terms] = await Promise.all([
    Promise.all(names.map((name) => lobeShader(apiLobe(name), ...common).catch(() => null))),
    microfacet ? Promise.all(shaded.map((name) => lobeShader(apiLobe(name), state.n, "blinn", "none").catch(() => null))) : null,
    microfacet ? Promise.all(shaded.map((name) => lobeMicrofacet(apiLobe(name), state.n).catch(() => null))) : null,
  ]);
  if (live.key !== key) return;
  liveUniforms.u_n = Number(state.n);
  // The same texts (every lobe taking n, inside the ranges they serve) and terms: nothing to
  // compile.
  const programs = JSON.stringify([shown, names, texts.map((text) => text?.glsl), shadedTexts?.map((text) => text?.glsl), terms, state.model]);
  if (programs === live.programs) return liveRedrawAll();
  live.programs = programs;
  const byName = new Map(names.map((name, k) => [name, texts[k]]).filter(([, text]) => text));
  const chosen = byName.get(shown || "pow") ?? byName.get("pow");
  if (!chosen) return;
  const [lobeText, powText] = microfacet ? [shadedTexts[0], shadedTexts.at(-1)] : [chosen, byName.get("pow")];
  const [lobeTerms, powTerms] = microfacet ? [terms[0], terms.at(-1)] : [null, null];
  if (!lobeText || !powText || (microfacet && (!lobeTerms || !powTerms))) return;
  live.spheres.setLobes(lobeText.glsl, powText.glsl, chosen.tonemap, state.model, microfacet ? { lobe: lobeTerms, pow: powTerms } : null);
  live.chosen = [lobeText.glsl, chosen.tonemap, state.model, lobeTerms];
  live.teapot?.setLobe(...live.chosen);
  const first = byName.has(shown) ? shown : "pow";
  live.lobes = [first, ...[...byName.keys()].filter((name) => name !== first)];
  live.lobe.setLobes(live.lobes.map((name) => ({ name, glsl: byName.get(name).glsl, colour: colourOf(name) })));
  live.drawnLobes = lobes.filter((name) => byName.has(name));
  $("lobe3d-name").textContent = first;
  live.slice.setLobe(chosen.glsl);
  live.slicePow.setLobe(byName.get("pow").glsl);
  liveRedrawAll();
}

// Redraws every live view, the slices (which follow n, not the light) with them.
function liveRedrawAll() {
  live.slice.draw();
  // pow's slice beside it, its axes labelled from its peak f(n, n) as the GPU evaluates it.
  const peak = live.lobe.evaluate("pow", [[0, 0, 1]], [0, 0, 1]).values[0];
  drawSlice($("slice-pow"), { lobe: "pow", slice: [peak], slice_size: 1 }, true);
  live.slicePow.draw();
  liveRedraw();
}

// One redraw at the next display frame, however many changes came before it.
function liveRedraw() {
  for (const id of ["theta_in", "light_theta", "light_phi"]) $(id + "-value").textContent = $(id).value + "°";
  if (!live.spheres || live.frame) return;
  live.frame = requestAnimationFrame(() => {
    live.frame = 0;
    const thetaIn = Number($("theta_in").value);
    const wi = [Math.sin((thetaIn * Math.PI) / 180), 0, Math.cos((thetaIn * Math.PI) / 180)];
    live.spheres.light = lightTowards(Number($("light_theta").value), Number($("light_phi").value));
    live.spheres.draw();
    live.lobe.draw(wi);
    // The live teapot shades per pixel or per vertex; flat shading is the server's.
    const teapotLive = Boolean(live.teapot) && ["phong", "gouraud"].includes($("shading").value);
    $("live-teapot").hidden = !teapotLive;
    $("teapot").hidden = teapotLive;
    $("teapot-by").textContent = teapotLive ? "drawn by WebGL2, the triangles specula render rasterizes" : "CPU renderer";
    if (teapotLive) {
      live.teapot.gouraud = $("shading").value === "gouraud";
      live.teapot.light = live.spheres.light;
      live.teapot.draw();
    }
    if (live.dragging && live.drawnLobes) drawPolar($("polar"), livePolar(wi), thetaIn);
  });
}

// The polar plot's curves evaluated on the GPU for the light at `wi` (the plane of incidence).
function livePolar(wi) {
  const directions = LIVE_POLAR_DEG.map((deg) => [Math.sin((deg * Math.PI) / 180), 0, Math.cos((deg * Math.PI) / 180)]);
  return live.drawnLobes.map((name) => ({ lobe: name, polar_deg: LIVE_POLAR_DEG, polar: [...live.lobe.evaluate(name, directions, wi).values] }));
}

// The server's views no longer match the controls (true) or all are drawn again (false).
function markStale(stale) {
  document.querySelectorAll("[data-server]").forEach((view) => view.classList.toggle("stale", stale));
}

// The views of `kinds` (their data-server) match the controls again: the marks left are the
// progress of the update.
function markFresh(...kinds) {
  for (const kind of kinds) document.querySelectorAll(`[data-server="${kind}"]`).forEach((view) => view.classList.remove("stale"));
}

// Frame times for the benchmark (.ci/explorer/frames.mjs): the draws' mean in milliseconds.
function liveFrameTimes() {
  const mean = (list) => list.reduce((a, b) => a + b, 0) / Math.max(1, list.length);
  return live.spheres ? { spheres: mean(live.spheres.frames), lobe: mean(live.lobe.frames) } : null;
}
