// specula explorer, the views the browser draws itself (WebGL2): the lit sphere of the chosen
// lobe beside pow's and their difference, from each lobe's GLSL ES 3.00 export (/api/shader,
// what `specula shader --lang glsl --glsl-version 300es` writes). The lobe's formula is never
// written here: its text is spliced into the shaders as the server exported it. Where the
// lobe's constants are closed forms of n, the export takes n as an argument (`--n-input`) and
// the page passes the uniform u_n, so a new n inside the range the text serves redraws
// without the server; a fitted lobe's text has n baked in, and a new n fetches a new one. The
// light and the camera are uniforms, so dragging the light never asks the server.
"use strict";

// The uniforms every live program reads where it declares them: n, for the texts that take it.
const liveUniforms = { u_n: 64 };

// The illumination models as SHADING's u_model.
const MODEL_IDS = { classic: 0, physical: 1, microfacet: 2 };

// The microfacet model's uniforms from an /api/microfacet answer (none for the other models).
function microfacetUniforms(terms) {
  return terms ? { u_normaliser: terms.normaliser, u_masking: terms.masking } : {};
}

// The lobe's microfacet terms at n (/api/microfacet), fetched once per lobe and n.
const microfacetTerms = new Map();
function lobeMicrofacet(lobe, n) {
  const key = [lobe, n].join("|");
  if (!microfacetTerms.has(key)) {
    const terms = getJson("/api/microfacet?" + new URLSearchParams({ lobe, n }));
    terms.catch(() => microfacetTerms.delete(key));
    microfacetTerms.set(key, terms);
  }
  return microfacetTerms.get(key);
}

// Where the export takes n as its first argument, the page's calls without it read u_n.
const N_UNIFORM = `
uniform float u_n;
float specula_specular(vec3 normal, vec3 wo, vec3 wi) { return specula_specular(u_n, normal, wo, wi); }
`;

// One GLSL ES 3.00 text per lobe, geometry and normalisation and the exponents it serves:
// fetched for one n, kept for every n in its range (all of them, one at a time, where n is
// baked in).
const shaderTexts = new Map();
const shaderRanges = new Map();
function lobeShader(lobe, n, geometry, normalisation) {
  const family = [lobe, geometry, normalisation].join("|");
  const served = (shaderRanges.get(family) ?? []).find(({ n_range: [low, high] }) => low <= n && n <= high);
  if (served) return Promise.resolve(served);
  const key = [family, n].join("|");
  if (!shaderTexts.has(key)) {
    const text = getJson("/api/shader?" + new URLSearchParams({ lobe, n, geometry, normalisation })).then((shader) => {
      if (!shader.n_range) return shader;
      const taking = { ...shader, glsl: shader.glsl + N_UNIFORM };
      shaderRanges.set(family, [...(shaderRanges.get(family) ?? []), taking]);
      return taking;
    });
    text.catch(() => shaderTexts.delete(key));
    shaderTexts.set(key, text);
  }
  return shaderTexts.get(key);
}

// A linked program, or an Error carrying the compiler's log.
function linkProgram(gl, vertex, fragment, varyings = null) {
  const program = gl.createProgram();
  for (const [type, source] of [[gl.VERTEX_SHADER, vertex], [gl.FRAGMENT_SHADER, fragment]]) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error("WebGL2 shader: " + gl.getShaderInfoLog(shader));
    gl.attachShader(program, shader);
  }
  if (varyings) gl.transformFeedbackVaryings(program, varyings, gl.SEPARATE_ATTRIBS);
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error("WebGL2 program: " + gl.getProgramInfoLog(program));
  return program;
}

// Sets each uniform the program has, the shared ones (liveUniforms) first; `values` maps
// names to numbers or arrays.
function setUniforms(gl, program, values) {
  for (const [name, value] of Object.entries({ ...liveUniforms, ...values })) {
    const at = gl.getUniformLocation(program, name);
    if (at === null) continue;
    if (typeof value === "number") gl.uniform1f(at, value);
    // A longer array is an array of floats (the microfacet model's masking table).
    else if (value.length > 4) gl.uniform1fv(at, value);
    else [null, gl.uniform1fv, gl.uniform2fv, gl.uniform3fv, gl.uniform4fv][value.length].call(gl, at, value);
  }
}

// Every pixel of a viewport: one triangle larger than the screen.
const FULL_SCREEN_VERTEX = `#version 300 es
void main() {
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * corner - 1.0, 0.0, 1.0);
}`;

// The renderer's shading (Shader::shade) of one point for the directional light: ambient,
// then the light's diffuse and N(n) lobe(t) terms when it and the viewer are above the
// surface; tone mapped and sRGB-encoded as the renders' PNGs are. Spliced after a lobe's
// exported functions. The illumination model u_model is 0 (classic), 1 (physical) or 2
// (microfacet: the lobe's Blinn export, normalisation none, as the distribution D, scaled by
// /api/microfacet's normaliser, with G2 from its masking table; the scene's specular colour is
// white, so Fresnel is 1: Shader::microfacet_contribution).
const SHADING = `
uniform vec3 u_light;
uniform vec3 u_colour;
uniform vec3 u_ambient;
uniform vec3 u_k;
uniform float u_model;
uniform float u_reinhard;
uniform float u_normaliser;
uniform float u_masking[64];

// G1 from the table at the cosines (k / 63)^2, linear in sqrt(cos): MicrofacetTerms::g1.
float maskingG1(float c) {
  float x = sqrt(clamp(c, 0.0, 1.0)) * 63.0;
  int at = min(int(x), 62);
  return u_masking[at] + (x - float(at)) * (u_masking[at + 1] - u_masking[at]);
}

vec3 shade(vec3 normal, vec3 wo) {
  vec3 radiance = u_k.x * u_colour * u_ambient;
  float cosIn = dot(normal, u_light);
  float cosOut = dot(normal, wo);
  if (cosOut > 0.0 && cosIn > 0.0) {
    vec3 diffuse = u_k.y * u_colour * (u_model > 0.5 ? 0.3183098862 : 1.0);
    float lobe = specula_specular(normal, wo, u_light);
    if (u_model > 1.5) {
      float a = maskingG1(cosOut);
      float b = maskingG1(cosIn);
      float denominator = a + b - a * b;
      float g2 = denominator > 0.0 ? a * b / denominator : 0.0;
      radiance += diffuse * cosIn + u_k.z * (u_normaliser * lobe * g2 / (4.0 * cosOut));
    } else {
      float specular = u_k.z * lobe;
      radiance += u_model > 0.5 ? (diffuse + specular) * cosIn : diffuse * cosIn + specular;
    }
  }
  return radiance;
}

float encode(float x) {
  x = u_reinhard > 0.5 ? max(x, 0.0) / (1.0 + max(x, 0.0)) : clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

vec4 display(vec3 radiance) { return vec4(encode(radiance.r), encode(radiance.g), encode(radiance.b), 1.0); }
`;

// The sphere /api/live-sphere draws (crates/serve/src/live.rs, `sphere_radiance`): a ray
// through each pixel centre from the camera at (0, -eye, 0) looking along +y with z up, the
// first hit on the unit sphere shaded.
function sphereFragment(lobe) {
  return `#version 300 es
precision highp float;
${lobe}
${SHADING}
uniform vec2 u_origin;
uniform float u_size;
uniform float u_eye;
uniform float u_tan_half;
uniform vec3 u_background;
out vec4 colour;

void main() {
  vec2 p = gl_FragCoord.xy - u_origin;
  vec3 d = normalize(vec3((2.0 * p.x / u_size - 1.0) * u_tan_half, 1.0, (2.0 * p.y / u_size - 1.0) * u_tan_half));
  vec3 o = vec3(0.0, -u_eye, 0.0);
  float b = dot(o, d);
  float discriminant = b * b - (dot(o, o) - 1.0);
  colour = display(discriminant >= 0.0 ? shade(normalize(o + (-b - sqrt(discriminant)) * d), -d) : u_background);
}`;
}

// A polynomial fit of viridis (perceptually uniform, readable in grey), for t in [0, 1].
const VIRIDIS = `
vec3 viridis(float t) {
  const vec3 c0 = vec3(0.2777273272, 0.0054073445, 0.3340998053);
  const vec3 c1 = vec3(0.1050930431, 1.4046134113, 1.3845901617);
  const vec3 c2 = vec3(-0.3308618287, 0.2148475595, 0.0950952426);
  const vec3 c3 = vec3(-4.6342304774, -5.7991007409, -19.3324409281);
  const vec3 c4 = vec3(6.2282699363, 14.1799333668, 56.6905526007);
  const vec3 c5 = vec3(4.7763849259, -13.7451453777, -65.3530326334);
  const vec3 c6 = vec3(-5.4354558559, 4.6458526122, 26.3124352495);
  return clamp(c0 + t * (c1 + t * (c2 + t * (c3 + t * (c4 + t * (c5 + t * c6))))), 0.0, 1.0);
}
`;

// The difference of two sphere images in 8-bit sRGB code values (the largest channel's), on a
// logarithmic scale: s = log2(1 + d) / 8, so 1, 3, 15 and 255 levels sit at 1/8, 2/8, 4/8 and
// 1; shown in an approximation of viridis (perceptually uniform). A strip of the same map with
// `u_bar` set is the colour bar.
const DIFFERENCE_FRAGMENT = `#version 300 es
precision highp float;
uniform sampler2D u_lobe;
uniform sampler2D u_pow;
uniform vec2 u_origin;
uniform vec2 u_extent;
uniform float u_bar;
out vec4 colour;

${VIRIDIS}
void main() {
  vec2 p = gl_FragCoord.xy - u_origin;
  float s;
  if (u_bar > 0.5) {
    s = p.y / u_extent.y;
  } else {
    ivec2 at = ivec2(p);
    vec3 a = texelFetch(u_lobe, at, 0).rgb;
    vec3 b = texelFetch(u_pow, at, 0).rgb;
    vec3 d = round(abs(a - b) * 255.0);
    s = log2(1.0 + max(d.r, max(d.g, d.b))) / 8.0;
  }
  colour = vec4(clamp(viridis(clamp(s, 0.0, 1.0)), 0.0, 1.0), 1.0);
}`;

const COPY_FRAGMENT = `#version 300 es
precision highp float;
uniform sampler2D u_image;
uniform vec2 u_origin;
out vec4 colour;
void main() { colour = texelFetch(u_image, ivec2(gl_FragCoord.xy - u_origin), 0); }`;

// Where the difference's colour bar puts its labels: d levels at s = log2(1 + d) / 8.
const DIFFERENCE_TICKS = [0, 1, 3, 15, 63, 255];
const BAR_WIDTH = 14;
const TICKS_WIDTH = 40;

// The three panes (the chosen lobe, pow, their difference) and the colour bar on one canvas.
class LiveSpheres {
  constructor(canvas, ticks, scene) {
    this.canvas = canvas;
    this.ticks = ticks;
    this.scene = scene;
    this.gl = canvas.getContext("webgl2", { antialias: false });
    if (!this.gl) throw new Error("no WebGL2");
    const gl = this.gl;
    this.copy = linkProgram(gl, FULL_SCREEN_VERTEX, COPY_FRAGMENT);
    this.difference = linkProgram(gl, FULL_SCREEN_VERTEX, DIFFERENCE_FRAGMENT);
    this.programs = { lobe: null, pow: null };
    this.targets = { lobe: this.target(), pow: this.target() };
    this.light = [0, -1, 0];
    this.frames = [];
  }

  target() {
    const gl = this.gl;
    const texture = gl.createTexture();
    const framebuffer = gl.createFramebuffer();
    return { texture, framebuffer, size: 0 };
  }

  resize(texture, size) {
    const gl = this.gl;
    if (texture.size === size) return;
    gl.bindTexture(gl.TEXTURE_2D, texture.texture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, size, size, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    gl.bindFramebuffer(gl.FRAMEBUFFER, texture.framebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture.texture, 0);
    texture.size = size;
  }

  // Compiles the chosen lobe's and pow's spheres from their exported functions, for `model`
  // (classic, physical, microfacet: then `terms` holds each one's /api/microfacet answer).
  setLobes(lobeText, powText, tonemap, model, terms = null) {
    const gl = this.gl;
    for (const p of Object.values(this.programs)) if (p) gl.deleteProgram(p);
    this.programs = {
      lobe: linkProgram(gl, FULL_SCREEN_VERTEX, sphereFragment(lobeText)),
      pow: linkProgram(gl, FULL_SCREEN_VERTEX, sphereFragment(powText)),
    };
    this.reinhard = tonemap === "reinhard" ? 1 : 0;
    this.model = MODEL_IDS[model];
    this.terms = terms;
  }

  // The pane side in pixels, for the canvas's width on the page.
  // The canvas is drawn at its own pixel size (never scaled, so a pixel is a ray), three panes
  // and the bar in the width its box leaves beside the bar's labels.
  paneSize() {
    const room = this.canvas.parentElement.clientWidth - TICKS_WIDTH - BAR_WIDTH - 16;
    return Math.max(64, Math.min(320, Math.floor(room / 3)));
  }

  draw() {
    const gl = this.gl;
    if (!this.programs.lobe) return;
    const started = performance.now();
    const size = this.paneSize();
    const width = 3 * size + BAR_WIDTH + 8;
    if (this.canvas.width !== width || this.canvas.height !== size) {
      [this.canvas.width, this.canvas.height] = [width, size];
      Object.assign(this.canvas.style, { width: width + "px", height: size + "px" });
      drawDifferenceTicks(this.ticks, size);
    }
    const s = this.scene;
    for (const which of ["lobe", "pow"]) {
      const target = this.targets[which];
      this.resize(target, size);
      gl.bindFramebuffer(gl.FRAMEBUFFER, target.framebuffer);
      gl.viewport(0, 0, size, size);
      gl.useProgram(this.programs[which]);
      setUniforms(gl, this.programs[which], {
        u_origin: [0, 0], u_size: size, u_light: this.light, u_eye: s.eye_distance,
        u_tan_half: Math.tan((s.fov_y_deg * Math.PI) / 360), u_colour: s.colour, u_ambient: s.ambient,
        u_background: s.background, u_k: [s.ka, s.kd, s.ks], u_model: this.model, u_reinhard: this.reinhard,
        ...microfacetUniforms(this.terms?.[which]),
      });
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT);
    ["lobe", "pow"].forEach((which, k) => {
      gl.viewport(k * size, 0, size, size);
      gl.useProgram(this.copy);
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, this.targets[which].texture);
      setUniforms(gl, this.copy, { u_origin: [k * size, 0] });
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    });
    gl.useProgram(this.difference);
    gl.uniform1i(gl.getUniformLocation(this.difference, "u_lobe"), 0);
    gl.uniform1i(gl.getUniformLocation(this.difference, "u_pow"), 1);
    gl.activeTexture(gl.TEXTURE0); gl.bindTexture(gl.TEXTURE_2D, this.targets.lobe.texture);
    gl.activeTexture(gl.TEXTURE1); gl.bindTexture(gl.TEXTURE_2D, this.targets.pow.texture);
    gl.viewport(2 * size, 0, size, size);
    setUniforms(gl, this.difference, { u_origin: [2 * size, 0], u_extent: [size, size], u_bar: 0 });
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.viewport(3 * size + 8, 0, BAR_WIDTH, size);
    setUniforms(gl, this.difference, { u_origin: [3 * size + 8, 0], u_extent: [BAR_WIDTH, size], u_bar: 1 });
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.activeTexture(gl.TEXTURE0);
    this.frames.push(performance.now() - started);
    if (this.frames.length > 120) this.frames.shift();
  }

  // A pane's pixels, rows from the top, RGBA (pane 0: the chosen lobe, 1: pow, 2: difference),
  // drawn again first: the canvas keeps a frame only until it is shown.
  read(pane) {
    this.draw();
    this.gl.bindFramebuffer(this.gl.FRAMEBUFFER, null);
    return readSquare(this.gl, pane * this.canvas.height, this.canvas.height);
  }

  // The light towards the sphere's normal under the pointer, as (theta, phi) in degrees, or
  // null off the sphere (clientX, clientY: the event's).
  lightAt(clientX, clientY) {
    const box = this.canvas.getBoundingClientRect();
    const size = box.height;
    const x = ((clientX - box.left) % size) / size;
    const y = (clientY - box.top) / size;
    if (clientX - box.left > 2 * size) return null;
    const s = this.scene;
    const half = Math.tan((s.fov_y_deg * Math.PI) / 360);
    const d = normalise([(2 * x - 1) * half, 1, (1 - 2 * y) * half]);
    const b = -s.eye_distance * d[1];
    const discriminant = b * b - (s.eye_distance * s.eye_distance - 1);
    if (discriminant < 0) return null;
    const t = -b - Math.sqrt(discriminant);
    const normal = [t * d[0], t * d[1] - s.eye_distance, t * d[2]];
    const theta = Math.min(89, (Math.acos(Math.max(-1, Math.min(1, -normal[1]))) * 180) / Math.PI);
    const phi = (Math.atan2(normal[2], normal[0]) * 180) / Math.PI;
    return { theta, phi };
  }
}

// The square of `size` pixels at `x` of the drawn frame, RGBA, rows from the top (WebGL's
// are from the bottom).
function readSquare(gl, x, size) {
  const pixels = new Uint8Array(4 * size * size);
  gl.readPixels(x, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const rows = new Uint8Array(pixels.length);
  for (let y = 0; y < size; y++) rows.set(pixels.subarray(4 * size * (size - 1 - y), 4 * size * (size - y)), 4 * size * y);
  return { size, pixels: rows };
}

function normalise(v) {
  const length = Math.hypot(...v);
  return v.map((c) => c / length);
}

// The direction towards a light at `theta` from the camera's axis and azimuth `phi`, degrees
// (live.rs's `light_towards`).
function lightTowards(theta, phi) {
  const [t, p] = [(theta * Math.PI) / 180, (phi * Math.PI) / 180];
  return [Math.sin(t) * Math.cos(p), -Math.cos(t), Math.sin(t) * Math.sin(p)];
}

// The colour bar's labels, at `x` in `g`, for a bar `height` pixels tall.
function differenceTicks(g, x, height) {
  g.font = "11px sans-serif"; g.fillStyle = "#333";
  for (const d of DIFFERENCE_TICKS) {
    const y = (height - 1) * (1 - Math.log2(1 + d) / 8);
    g.fillText(String(d), x, Math.min(height - 2, Math.max(10, y + 4)));
  }
}

// The labels of the live spheres' bar, on their own canvas beside the WebGL one.
function drawDifferenceTicks(canvas, size) {
  [canvas.width, canvas.height] = [TICKS_WIDTH, size];
  const g = canvas.getContext("2d");
  g.clearRect(0, 0, canvas.width, canvas.height);
  differenceTicks(g, 2, size);
}
