// Drives the explorer's live views (WebGL2, on SwiftShader in headless Chromium): the sphere
// WebGL draws from each lobe's exported GLSL agrees with /api/live-sphere (the renderer's
// shading, computed by the server) pixel by pixel, in the classic model and with lobes as
// microfacet distributions; the 3D lobe's vertex program gives the
// BRDF values /api/evaluate gives; a drag over the sphere changes the light and the image and
// sends no request while it moves; every view of the first screen lies inside 1400 x 900; a
// bad n is marked at its control and the views marked stale. Prints frame times (never
// asserted). Saves a screenshot of the first screen.
// Usage: node live.mjs SPECULA_BINARY SCREENSHOT.png
import { chromium } from "playwright-core";
import { counts, startServer } from "./serve.mjs";

const [binary, screenshot] = process.argv.slice(2);
// The largest difference, in 8-bit sRGB levels, a WebGL pixel may have from the server's, and
// the share of pixels that may differ by more than one level (rounding at a level's edge).
// Measured on SwiftShader: see docs/explorer.md.
const MAX_LEVELS = 1;
const MAX_SHARE_BEYOND_ONE = 0;
// The share of the teapot's inner pixels that may differ from the CPU renderer's by more than
// one level: measured, 0 to 0.024 % (0.045 % for a microfacet teapot lit elsewhere), single
// pixels at the patches' seams, where SwiftShader's rasterizer leaves a crack the CPU's does
// not and the surface behind shows (see docs/explorer.md). EDGE_LEVELS: a step between
// neighbours that marks an outline.
const MAX_TEAPOT_SHARE = 0.0005;
const EDGE_LEVELS = 24;
// The 3D lobe's f32 values against the API's f64, relative to the lobe's peak.
const MAX_RELATIVE = 2e-3;

const { server, url } = await startServer(binary);

// SwiftShader is Chromium's software GPU: these flags give headless Chromium a WebGL2 context.
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
});
const failures = [];
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const messages = [];
  page.on("console", (message) => messages.push(`${message.type()}: ${message.text()}`));
  page.on("pageerror", (error) => messages.push(`pageerror: ${error.message}`));
  const shaderRequests = [];
  page.on("request", (request) => {
    const address = new URL(request.url());
    if (address.pathname === "/api/shader") shaderRequests.push(address.searchParams);
  });
  // The page has drawn the address it holds, and (when given) that address has `key` at `value`.
  const drawn = (key = null, value = null) => page.waitForFunction(([k, v]) => {
    const shown = document.body.dataset.drawn ?? "";
    return shown === location.search && (k === null || new URLSearchParams(shown).get(k) === v);
  }, [key, value], { timeout: 90000 });
  await page.goto(url + "?lobes=schlick,cosquad&render=cosquad&n=32");
  await drawn();
  if ((await page.evaluate(() => document.body.dataset.live)) !== "webgl2") {
    const note = await page.evaluate(() => document.getElementById("live-note").textContent);
    throw new Error(`no WebGL2 context in Chromium: ${note}`);
  }

  // The RGBA pixels of the square PNG the server answers `url` with, `size` a side (defined
  // again after each page load).
  const defineServedPixels = () => page.evaluate(() => {
    window.servedPixels = async (url, size) => {
      const image = new Image();
      image.src = url;
      await image.decode();
      const canvas = Object.assign(document.createElement("canvas"), { width: size, height: size });
      const g = canvas.getContext("2d");
      g.drawImage(image, 0, 0);
      return g.getImageData(0, 0, size, size).data;
    };
  });
  await defineServedPixels();

  // The WebGL sphere of `lobe` against the server's (/api/live-sphere): same lobe, n,
  // geometry, normalisation, model and light; in the microfacet model with the terms
  // /api/microfacet gives for the lobe and pow.
  await page.evaluate(() => {
    window.compareSphere = async ({ lobe, geometry, normalisation, theta, phi, n, model }) => {
      const microfacet = model === "microfacet";
      const [mine, pow, mineTerms, powTerms] = await Promise.all([
        lobeShader(lobe, n, geometry, normalisation), lobeShader("pow", n, geometry, normalisation),
        microfacet ? lobeMicrofacet(lobe, n) : null, microfacet ? lobeMicrofacet("pow", n) : null,
      ]);
      liveUniforms.u_n = n;
      live.spheres.setLobes(mine.glsl, pow.glsl, mine.tonemap, model, microfacet ? { lobe: mineTerms, pow: powTerms } : null);
      live.spheres.light = lightTowards(theta, phi);
      live.spheres.draw();
      const { size, pixels } = live.spheres.read(0);
      const query = new URLSearchParams({ lobe, n, geometry, normalisation, model, light_theta: theta, light_phi: phi, size });
      const reference = await window.servedPixels("/api/live-sphere?" + query, size);
      let worst = 0;
      let beyondOne = 0;
      for (let i = 0; i < reference.length; i += 4) {
        const d = Math.max(...[0, 1, 2].map((c) => Math.abs(reference[i + c] - pixels[i + c])));
        worst = Math.max(worst, d);
        if (d > 1) beyondOne++;
      }
      return { size, worst, share: beyondOne / (size * size) };
    };
  });

  // Every lobe, and a formula, in the classic model; then lobes as microfacet distributions
  // (the Blinn export, normalisation none, as D).
  const lobes = await page.evaluate(() => registry.lobes.map((l) => l.id));
  lobes.push("=let a = (n + 1) / 17; max(0, a * (t - 1) + 1) ^ 16");
  const settings = [["phong", "none", 30, 45, 32], ["blinn", "lobe", 50, -60, 200], ["phong", "lobe", 15, 120, 8]];
  const cases = lobes.map((lobe, k) => {
    const [geometry, normalisation, theta, phi, n] = settings[k % settings.length];
    return { lobe, geometry, normalisation, theta, phi, n, model: "classic" };
  });
  for (const [lobe, n, theta, phi] of [["pow", 32, 30, 45], ["cosquad", 8, 50, -60], ["schlick-mod", 200, 15, 120], ["sg-karis", 64, 60, 30], ["=exp2(n * (t - 1) * 1.4427)", 16, 40, 90]]) {
    cases.push({ lobe, geometry: "blinn", normalisation: "none", theta, phi, n, model: "microfacet" });
  }
  let worstLevels = 0;
  let worstShare = 0;
  for (const sphere of cases) {
    const result = await page.evaluate((sphere) => window.compareSphere(sphere), sphere);
    const { lobe, geometry, normalisation, theta, phi, n, model } = sphere;
    worstLevels = Math.max(worstLevels, result.worst);
    worstShare = Math.max(worstShare, result.share);
    console.log(`sphere ${lobe} (${model}, ${geometry}, ${normalisation}, n = ${n}, light ${theta}/${phi}): ${result.size}^2 px, largest difference ${result.worst} levels, ${(100 * result.share).toFixed(3)} % beyond 1`);
    if (result.worst > MAX_LEVELS || result.share > MAX_SHARE_BEYOND_ONE) failures.push(`the WebGL sphere of ${lobe} (${model}) differs from the server's: ${result.worst} levels, ${(100 * result.share).toFixed(3)} % of pixels beyond 1`);
  }
  console.log(`spheres: largest difference ${worstLevels} levels, at most ${(100 * worstShare).toFixed(3)} % of pixels beyond 1 level`);
  // pow's constants are closed forms of n: its text, fetched once per geometry and
  // normalisation, served every n the loop asked (n as the uniform u_n).
  const powFamilies = new Set(cases.map(({ geometry, normalisation }) => [geometry, normalisation].join("|")));
  const powFetches = shaderRequests.filter((query) => query.get("lobe") === "pow").length;
  console.log(`pow's shader fetched ${powFetches} times for ${lobes.length} spheres at ${new Set(settings.map((s) => s[4])).size} values of n`);
  if (powFetches !== powFamilies.size) failures.push(`pow's shader was fetched ${powFetches} times, not once per geometry and normalisation (${powFamilies.size}): n is not a uniform`);

  // The WebGL teapot against `specula render`'s (the CPU renderer's /api/render) of the same
  // lobe and light, on the pixels whose neighbours are all teapot in both and none more than
  // EDGE levels from them in the CPU's image: the outlines, outer and inner (the spout, handle
  // and lid over the body), depend on each rasterizer's edge rules.
  await page.waitForFunction(() => live.teapot !== null);
  for (const [lobe, geometry, normalisation, n, theta, phi, shading, model = "classic"] of [["pow", "phong", "none", 32, 30, 45, "phong"], ["schlick", "blinn", "lobe", 200, 50, -60, "phong"], ["=exp2(n * (t - 1) * 1.4427)", "phong", "lobe", 64, 20, 100, "phong"], ["cosquad", "phong", "none", 16, 40, 30, "gouraud"], ["logexp", "blinn", "lobe", 64, 20, -100, "gouraud"], ["sg-karis", "blinn", "none", 32, 30, 45, "phong", "microfacet"]]) {
    const result = await page.evaluate(async ({ lobe, geometry, normalisation, n, theta, phi, shading, model, edge }) => {
      const mine = await lobeShader(lobe, n, geometry, normalisation);
      const terms = model === "microfacet" ? await lobeMicrofacet(lobe, n) : null;
      liveUniforms.u_n = n;
      live.teapot.setLobe(mine.glsl, mine.tonemap, model, terms);
      live.teapot.light = lightTowards(theta, phi);
      live.teapot.gouraud = shading === "gouraud";
      const { size, pixels } = live.teapot.read();
      const query = new URLSearchParams({ object: "teapot", lobe, n, geometry, normalisation, shading, model, light_theta: theta, light_phi: phi, size });
      const reference = await window.servedPixels("/api/render?" + query, size);
      const background = (data, k) => [0, 1, 2].every((c) => data[k + c] === data[c]);
      let [compared, worst, beyondOne] = [0, 0, 0];
      for (let y = 1; y < size - 1; y++) {
        for (let x = 1; x < size - 1; x++) {
          let inside = true;
          const at = 4 * (y * size + x);
          for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) {
            const k = 4 * ((y + dy) * size + x + dx);
            const step = Math.max(...[0, 1, 2].map((c) => Math.abs(reference[k + c] - reference[at + c])));
            if (background(pixels, k) || background(reference, k) || step > edge) inside = false;
          }
          if (!inside) continue;
          const k = 4 * (y * size + x);
          const d = Math.max(...[0, 1, 2].map((c) => Math.abs(reference[k + c] - pixels[k + c])));
          compared++;
          worst = Math.max(worst, d);
          if (d > 1) beyondOne++;
        }
      }
      return { size, compared, worst, share: beyondOne / Math.max(1, compared) };
    }, { lobe, geometry, normalisation, n, theta, phi, shading, model, edge: EDGE_LEVELS });
    console.log(`teapot ${lobe} ${shading} (${geometry}, ${normalisation}, n = ${n}, light ${theta}/${phi}): ${result.compared} inner pixels of ${result.size}^2, largest difference ${result.worst} levels, ${(100 * result.share).toFixed(3)} % beyond 1`);
    if (result.compared < 0.2 * result.size * result.size || result.share > MAX_TEAPOT_SHARE) failures.push(`the WebGL teapot of ${lobe} differs from specula render's: ${JSON.stringify(result)}`);
  }

  // The 3D lobe's vertex program against the API's polar values in the plane of incidence.
  for (const [lobe, thetaIn] of [["cosquad", 30], ["schlick", 60]]) {
    const result = await page.evaluate(async ({ lobe, thetaIn }) => {
      const query = new URLSearchParams({ lobe, n: "32", geometry: "phong", normalisation: "lobe", theta_in: thetaIn });
      // The page's programs are its own state's (n = 32), whatever n the checks above set.
      liveUniforms.u_n = 32;
      const api = await getJson("/api/evaluate?" + query);
      const directions = api.polar_deg.map((deg) => [Math.sin((deg * Math.PI) / 180), 0, Math.cos((deg * Math.PI) / 180)]);
      const t = (thetaIn * Math.PI) / 180;
      const wi = [Math.sin(t), 0, Math.cos(t)];
      const { values, positions } = live.lobe.evaluate(lobe, directions, wi);
      const peak = Math.max(...api.polar);
      let worst = 0;
      let radius = 0;
      // The radius is f / f(mirror); the mirror direction is the API's largest value here.
      const mirror = live.lobe.evaluate(lobe, [[-wi[0], 0, wi[2]]], wi).values[0];
      api.polar.forEach((f, k) => {
        worst = Math.max(worst, Math.abs(values[k] - f) / peak);
        const r = Math.hypot(positions[3 * k], positions[3 * k + 1], positions[3 * k + 2]);
        radius = Math.max(radius, Math.abs(r - f / mirror));
      });
      return { worst, radius, count: api.polar.length };
    }, { lobe, thetaIn });
    console.log(`3D lobe ${lobe} at ${thetaIn} degrees: ${result.count} directions, largest difference from the API ${result.worst.toExponential(2)} of the peak; radius off f / f(mirror) by at most ${result.radius.toExponential(2)}`);
    if (!(result.worst < MAX_RELATIVE) || !(result.radius < MAX_RELATIVE)) failures.push(`the 3D lobe of ${lobe} is not the API's BRDF: ${result.worst}, radius ${result.radius}`);
  }

  // Every view of the first screen inside 1400 x 900.
  await page.goto(url + "?lobes=pow,schlick,schlick-mod&render=schlick&n=64");
  await drawn();
  const outside = await page.evaluate(() => ["controls", "n-box", "cartesian", "error", "polar", "lobe3d", "live-spheres", "live-ticks", "render-choice"].map((id) => {
    const box = document.getElementById(id).getBoundingClientRect();
    return { id, box: [box.left, box.top, box.right, box.bottom].map(Math.round) };
  }).filter(({ box: [, top, right, bottom] }) => top < 0 || right > 1400 || bottom > 900 || bottom <= top));
  for (const { id, box } of outside) failures.push(`${id} is not inside the first 1400 x 900 screen: ${box}`);
  await page.screenshot({ path: screenshot });

  // A drag over the sphere: the light and the image change, and nothing is requested until
  // the button is released.
  const requests = [];
  page.on("request", (request) => requests.push(request.url()));
  const box = await page.locator("#live-spheres").boundingBox();
  const before = await page.evaluate(() => ({ light: [$("light_theta").value, $("light_phi").value], pixels: Array.from(live.spheres.read(0).pixels.filter((_, i) => i % 97 === 0)) }));
  const pane = box.height;
  await page.mouse.move(box.x + pane * 0.5, box.y + pane * 0.5);
  await page.mouse.down();
  const frames = [];
  for (let k = 1; k <= 17; k++) {
    await page.mouse.move(box.x + pane * (0.5 - 0.02 * k), box.y + pane * (0.5 - 0.015 * k));
    frames.push(await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(() => resolve($("light_theta").value))))));
  }
  const during = await page.evaluate(() => ({ light: [$("light_theta").value, $("light_phi").value], pixels: Array.from(live.spheres.read(0).pixels.filter((_, i) => i % 97 === 0)) }));
  const sentWhileMoving = requests.length;
  await page.mouse.up();
  await drawn("light_theta", during.light[0]);
  if (sentWhileMoving) failures.push(`dragging the light sent ${sentWhileMoving} requests: ${requests.slice(0, 3).join(", ")}`);
  if (during.light.join() === before.light.join()) failures.push(`dragging did not move the light: ${during.light}`);
  if (during.pixels.join() === before.pixels.join()) failures.push("dragging did not change the sphere's image");
  if (new Set(frames).size < 5) failures.push(`the light took only ${new Set(frames).size} values over a 17-step drag: ${frames}`);
  console.log(`drag: light ${before.light} -> ${during.light} in ${new Set(frames).size} steps, ${sentWhileMoving} requests while moving`);
  if (!requests.some((r) => r.includes("/api/evaluate?"))) failures.push("the server's views were not updated when the drag ended");

  // A drag over the polar plot moves the incidence; the polar plot (from the GPU while it
  // moves) and the 3D lobe follow, with no request until the button is released.
  requests.length = 0;
  const polar = await page.locator("#polar").boundingBox();
  const polarBefore = await page.evaluate(() => ({ theta: $("theta_in").value, plot: $("polar").toDataURL() }));
  await page.mouse.move(polar.x + polar.width / 2 + 40, polar.y + polar.height - 120);
  await page.mouse.down();
  for (let k = 1; k <= 8; k++) await page.mouse.move(polar.x + polar.width / 2 + 40 + 15 * k, polar.y + polar.height - 120 + 8 * k);
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  const polarDuring = await page.evaluate(() => ({ theta: $("theta_in").value, plot: $("polar").toDataURL() }));
  const polarRequests = requests.length;
  await page.mouse.up();
  if (polarRequests) failures.push(`dragging the incidence sent ${polarRequests} requests`);
  if (polarDuring.theta === polarBefore.theta || polarDuring.plot === polarBefore.plot) failures.push(`dragging over the polar plot did not move the incidence and its plot: ${polarBefore.theta} -> ${polarDuring.theta}`);
  console.log(`polar drag: incidence ${polarBefore.theta} -> ${polarDuring.theta} degrees, ${polarRequests} requests while moving`);
  await drawn("theta_in", polarDuring.theta);

  // The wheel over the lobe plot steps n along its slider.
  const nBefore = await page.evaluate(() => $("n-box").value);
  const cartesian = await page.locator("#cartesian").boundingBox();
  await page.mouse.move(cartesian.x + cartesian.width / 2, cartesian.y + cartesian.height / 2);
  await page.mouse.wheel(0, -100);
  const nAfter = await page.evaluate(() => $("n-box").value);
  if (!(Number(nAfter) > Number(nBefore))) failures.push(`the wheel over the lobe plot did not raise n: ${nBefore} -> ${nAfter}`);
  await drawn("n", nAfter);

  // A bad n: marked at the control, the views stale, then mended.
  await page.fill("#n-box", "0");
  await page.waitForFunction(() => document.getElementById("n-error").textContent !== "");
  const bad = await page.evaluate(() => ({ message: $("n-error").textContent, invalid: $("n-box").getAttribute("aria-invalid"), stale: document.querySelectorAll("[data-server].stale").length, box: $("n-error").getBoundingClientRect().bottom }));
  if (bad.invalid !== "true" || bad.stale === 0 || bad.box > 900) failures.push(`a bad n is not marked where it is: ${JSON.stringify(bad)}`);
  console.log(`bad n: "${bad.message}", ${bad.stale} views marked stale`);
  await page.fill("#n-box", "100");
  await drawn("n", "100");
  const mended = await page.evaluate(() => ({ message: $("n-error").textContent, stale: document.querySelectorAll("[data-server].stale").length }));
  if (mended.message || mended.stale) failures.push(`a mended n leaves marks: ${JSON.stringify(mended)}`);

  // A wide screen keeps the first screen's views in it, and a narrow window scrolls down,
  // never across.
  for (const [width, height, first] of [[1920, 1080, true], [700, 900, false]]) {
    await page.setViewportSize({ width, height });
    // The page redraws 100 ms after the window's last change; the spheres then fit their box.
    await page.waitForFunction(() => live.spheres.canvas.width === 3 * live.spheres.paneSize() + BAR_WIDTH + 8);
    const fit = await page.evaluate(([width, height, first]) => {
      const ids = ["cartesian", "error", "polar", "lobe3d", "live-spheres", "live-ticks"];
      const out = first ? ids.filter((id) => document.getElementById(id).getBoundingClientRect().bottom > height) : [];
      // What sticks out, outside any box that scrolls its own content.
      const scrolls = (e) => e.closest("#analysis, #measured-fits");
      const wide = [...document.querySelectorAll("body *")].filter((e) => e.getBoundingClientRect().right > width + 1 && !scrolls(e)).slice(0, 4).map((e) => e.id || e.tagName);
      return { out, across: document.documentElement.scrollWidth - width, wide };
    }, [width, height, first]);
    if (fit.out.length || fit.across > 0) failures.push(`at ${width} x ${height}: ${fit.out.join(", ")} below the first screen, ${fit.across} px of sideways scrolling (${fit.wide.join(", ")})`);
  }
  await page.setViewportSize({ width: 1400, height: 900 });

  // A lobe parameter out of its range: marked at its control, then mended.
  await page.locator('#lobes input[value="cosquad"]').check();
  await page.fill("#param-cosquad-v", "99");
  await page.waitForFunction(() => document.getElementById("lobes-error").textContent !== "");
  const parameter = await page.evaluate(() => ({ message: $("lobes-error").textContent, invalid: $("param-cosquad-v").getAttribute("aria-invalid") }));
  if (parameter.invalid !== "true" || !parameter.message.includes("[")) failures.push(`a bad cosquad v is not marked at its control: ${JSON.stringify(parameter)}`);
  console.log(`bad parameter: "${parameter.message}"`);
  await page.fill("#param-cosquad-v", "4");
  await drawn("lobes", "pow,schlick,schlick-mod,cosquad");
  if (await page.evaluate(() => $("lobes-error").textContent)) failures.push("a mended cosquad v leaves its message");

  // Frame rates, printed and never asserted: 120 display frames, each drawing the spheres at
  // another light, the 3D lobe at another incidence, both, or nothing (the ceiling headless
  // Chromium gives). The draw's share of a frame is what it adds to the empty frame's time;
  // the JavaScript side of a draw (to gl.finish) is printed beside it.
  const rates = {};
  for (const what of ["nothing", "spheres", "lobe", "both"]) {
    rates[what] = await page.evaluate((what) => new Promise((resolve) => {
      const start = performance.now();
      let [count, script] = [0, 0];
      const step = () => {
        const t0 = performance.now();
        if (what === "spheres" || what === "both") {
          live.spheres.light = lightTowards(10 + (count % 60), 45);
          live.spheres.draw();
          live.spheres.gl.finish();
        }
        if (what === "lobe" || what === "both") {
          live.lobe.draw([Math.sin(count / 60), 0, Math.cos(count / 60)]);
          live.lobe.gl.finish();
        }
        script += performance.now() - t0;
        if (++count < 120) requestAnimationFrame(step);
        else resolve({ fps: 120000 / (performance.now() - start), script: script / 120 });
      };
      requestAnimationFrame(step);
    }), what);
  }
  const paneSide = await page.evaluate(() => live.spheres.canvas.height);
  for (const what of ["spheres", "lobe", "both"]) {
    const { fps, script } = rates[what];
    const share = Math.max(0, 1 - fps / rates.nothing.fps);
    console.log(`frames (${what}): ${fps.toFixed(1)} per second (${rates.nothing.fps.toFixed(1)} drawing nothing); the draw takes ${(100 * share).toFixed(0)} % of a frame, ${script.toFixed(1)} ms of it in JavaScript (spheres: 3 panes of ${paneSide} px)`);
  }

  // The page itself in the microfacet model: its own controls' state drives the spheres
  // (liveLobes: the Blinn exports and /api/microfacet's terms), which must be the server's.
  await page.goto(url + "?lobes=schlick,cosquad&render=cosquad&n=24&model=microfacet&light_theta=35&light_phi=50");
  await drawn("model", "microfacet");
  await page.waitForFunction(() => live.spheres?.model === 2 && live.spheres.terms !== null);
  await defineServedPixels();
  const byPage = await page.evaluate(async () => {
    const { size, pixels } = live.spheres.read(0);
    const query = new URLSearchParams({ lobe: "cosquad", n: 24, geometry: "phong", normalisation: $("normalisation").value, model: "microfacet", light_theta: 35, light_phi: 50, size });
    const reference = await window.servedPixels("/api/live-sphere?" + query, size);
    let worst = 0;
    for (let i = 0; i < reference.length; i += 4) worst = Math.max(worst, ...[0, 1, 2].map((c) => Math.abs(reference[i + c] - pixels[i + c])));
    return { size, worst };
  });
  console.log(`the page in the microfacet model: cosquad's sphere ${byPage.size}^2 px, largest difference from the server's ${byPage.worst} levels`);
  if (byPage.worst > MAX_LEVELS) failures.push(`the page's microfacet sphere differs from the server's by ${byPage.worst} levels`);

  const noisy = messages.filter(counts);
  if (noisy.length) failures.push("console: " + noisy.join(" | "));
} catch (error) {
  failures.push(error.message);
} finally {
  await browser.close();
  server.kill();
}
if (failures.length) {
  console.error("explorer live check failed:\n  " + failures.join("\n  "));
  process.exit(1);
}
console.log("explorer live check: ok");
