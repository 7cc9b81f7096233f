// specula explorer, the 3D lobe (WebGL2): for the light at the polar plot's incidence, every
// outgoing direction above the surface at a distance from the origin proportional to the
// specular term f(wo, wi) (the lobe's exported `specula_specular`, the polar plot's quantity),
// scaled so that the mirror direction, where t = 1, reaches 1. Orbited with the pointer.
"use strict";

// The mesh is a grid about the mirror direction, denser near it (the polar angle from it goes
// as the square of the grid's coordinate), so a narrow lobe at n = 1000 still has rings.
const LOBE_RINGS = 96;
const LOBE_SEGMENTS = 128;

function lobeVertex(lobe) {
  return `#version 300 es
precision highp float;
${lobe}
layout(location = 0) in vec3 a_point;
uniform vec3 u_wi;
uniform float u_explicit;
uniform mat3 u_rotation;
uniform float u_scale;
out float v_value;
out vec3 v_position;

// a_point is a direction itself (u_explicit), or the grid's (u, v) about the mirror direction.
vec3 direction(vec3 mirror) {
  if (u_explicit > 0.5) return a_point;
  vec3 side = normalize(abs(mirror.z) < 0.999 ? cross(vec3(0.0, 0.0, 1.0), mirror) : vec3(1.0, 0.0, 0.0));
  vec3 other = cross(mirror, side);
  float polar = 3.14159265 * a_point.x * a_point.x;
  float azimuth = 6.28318531 * a_point.y;
  return cos(polar) * mirror + sin(polar) * (cos(azimuth) * side + sin(azimuth) * other);
}

void main() {
  const vec3 normal = vec3(0.0, 0.0, 1.0);
  vec3 mirror = vec3(-u_wi.x, -u_wi.y, u_wi.z);
  vec3 wo = direction(mirror);
  v_value = wo.z > 0.0 ? specula_specular(normal, wo, u_wi) : 0.0;
  float peak = max(specula_specular(normal, mirror, u_wi), 1e-30);
  v_position = wo * (v_value / peak);
  vec3 q = u_rotation * v_position;
  gl_Position = vec4(q.x * u_scale, (q.z - 0.4) * u_scale, q.y * 0.3, 1.0);
  gl_PointSize = 1.0;
}`;
}

// Shaded by the surface's own facet normal (from the position's derivatives).
const LOBE_FRAGMENT = `#version 300 es
precision highp float;
in float v_value;
in vec3 v_position;
uniform vec3 u_colour;
uniform mat3 u_rotation;
out vec4 colour;
void main() {
  vec3 facet = normalize(cross(dFdx(v_position), dFdy(v_position)));
  vec3 towards = transpose(u_rotation) * normalize(vec3(-0.4, -1.0, 0.6));
  float lit = 0.35 + 0.65 * abs(dot(facet, towards));
  colour = vec4(u_colour * lit, 1.0);
}`;

const LINE_VERTEX = `#version 300 es
layout(location = 0) in vec3 a_point;
uniform mat3 u_rotation;
uniform float u_scale;
void main() {
  vec3 q = u_rotation * a_point;
  gl_Position = vec4(q.x * u_scale, (q.z - 0.4) * u_scale, q.y * 0.3, 1.0);
}`;

const LINE_FRAGMENT = `#version 300 es
precision highp float;
uniform vec3 u_colour;
out vec4 colour;
void main() { colour = vec4(u_colour, 1.0); }`;

// Column-major rotation: the azimuth `yaw` about z, then the elevation `pitch` about x.
function orbitRotation(yaw, pitch) {
  const [cy, sy, cp, sp] = [Math.cos(yaw), Math.sin(yaw), Math.cos(pitch), Math.sin(pitch)];
  // Rx(pitch) * Rz(yaw), rows: [cy, -sy, 0], [cp sy, cp cy, -sp], [sp sy, sp cy, cp].
  return [cy, cp * sy, sp * sy, -sy, cp * cy, sp * cy, 0, -sp, cp];
}

function hexColour(hex) {
  const v = parseInt(hex.slice(1), 16);
  return [(v >> 16) / 255, ((v >> 8) & 255) / 255, (v & 255) / 255];
}

class LiveLobe {
  constructor(canvas) {
    this.canvas = canvas;
    // No multisampling: on SwiftShader it cost a quarter of the frame rate (18.7 against 25 per
    // second, measured by live.mjs).
    this.gl = canvas.getContext("webgl2", { antialias: false });
    if (!this.gl) throw new Error("no WebGL2");
    const gl = this.gl;
    this.lines = linkProgram(gl, LINE_VERTEX, LINE_FRAGMENT);
    this.programs = new Map();
    this.program = null;
    this.yaw = -0.6;
    this.pitch = 0.35;
    this.mesh = this.gridMesh();
    this.lineBuffer = gl.createBuffer();
    this.lineArray = gl.createVertexArray();
    this.frames = [];
  }

  gridMesh() {
    const gl = this.gl;
    const points = [];
    for (let i = 0; i <= LOBE_RINGS; i++) for (let j = 0; j <= LOBE_SEGMENTS; j++) points.push(i / LOBE_RINGS, j / LOBE_SEGMENTS, 0);
    const indices = [];
    const at = (i, j) => i * (LOBE_SEGMENTS + 1) + j;
    for (let i = 0; i < LOBE_RINGS; i++) {
      for (let j = 0; j < LOBE_SEGMENTS; j++) indices.push(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
    const array = gl.createVertexArray();
    gl.bindVertexArray(array);
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(points), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(indices), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    return { array, count: indices.length };
  }

  // `lobes`: [{name, glsl, colour}], the first one drawn; each can be evaluated.
  setLobes(lobes) {
    const gl = this.gl;
    for (const program of this.programs.values()) gl.deleteProgram(program);
    this.programs = new Map(lobes.map((l) => [l.name, linkProgram(gl, lobeVertex(l.glsl), LOBE_FRAGMENT, ["v_value", "v_position"])]));
    this.program = lobes.length ? this.programs.get(lobes[0].name) : null;
    this.shown = lobes[0]?.name ?? "";
    this.colour = lobes.length ? hexColour(lobes[0].colour) : [0, 0, 0];
  }

  // The view's uniforms: a unit is 0.72 of the half-width, which fits the lobe (it reaches 1)
  // and its axes.
  view() { return { u_rotation: orbitRotation(this.yaw, this.pitch), u_scale: 0.72 }; }

  draw(wi) {
    const gl = this.gl;
    if (!this.program) return;
    const started = performance.now();
    const side = Math.max(120, Math.floor(this.canvas.clientWidth));
    if (this.canvas.width !== side) [this.canvas.width, this.canvas.height] = [side, side];
    gl.viewport(0, 0, side, side);
    gl.clearColor(1, 1, 1, 1);
    gl.enable(gl.DEPTH_TEST);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const view = this.view();
    gl.useProgram(this.program);
    gl.uniformMatrix3fv(gl.getUniformLocation(this.program, "u_rotation"), false, view.u_rotation);
    setUniforms(gl, this.program, { u_wi: wi, u_explicit: 0, u_scale: view.u_scale, u_colour: this.colour });
    gl.bindVertexArray(this.mesh.array);
    gl.drawElements(gl.TRIANGLES, this.mesh.count, gl.UNSIGNED_INT, 0);
    this.drawAxes(wi, view);
    gl.bindVertexArray(null);
    this.frames.push(performance.now() - started);
    if (this.frames.length > 120) this.frames.shift();
  }

  // The surface's rim and normal (grey) and the direction to the light (dark grey, as the
  // polar plot draws it).
  drawAxes(wi, view) {
    const gl = this.gl;
    const rim = [];
    for (let k = 0; k < 64; k++) {
      const [a, b] = [(2 * Math.PI * k) / 64, (2 * Math.PI * (k + 1)) / 64];
      rim.push(Math.cos(a), Math.sin(a), 0, Math.cos(b), Math.sin(b), 0);
    }
    const segments = [
      [rim, [0.6, 0.6, 0.6]],
      [[0, 0, 0, 0, 0, 1.2], [0.6, 0.6, 0.6]],
      [[0, 0, 0, ...wi.map((c) => 1.3 * c)], [0.2, 0.2, 0.2]],
    ];
    gl.useProgram(this.lines);
    gl.uniformMatrix3fv(gl.getUniformLocation(this.lines, "u_rotation"), false, view.u_rotation);
    setUniforms(gl, this.lines, { u_scale: view.u_scale });
    gl.bindVertexArray(this.lineArray);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.lineBuffer);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    for (const [points, colour] of segments) {
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(points), gl.STREAM_DRAW);
      setUniforms(gl, this.lines, { u_colour: colour });
      gl.drawArrays(gl.LINES, 0, points.length / 3);
    }
  }

  // Lobe `name`'s mesh program run on `directions` (unit, [x, y, z] each) by transform
  // feedback: each one's f(wo, wi) and the position the 3D lobe puts it at.
  evaluate(name, directions, wi) {
    const gl = this.gl;
    const program = this.programs.get(name);
    const count = directions.length;
    const input = gl.createBuffer();
    const array = gl.createVertexArray();
    gl.bindVertexArray(array);
    gl.bindBuffer(gl.ARRAY_BUFFER, input);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(directions.flat()), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    const [values, positions] = [gl.createBuffer(), gl.createBuffer()];
    for (const [index, buffer, floats] of [[0, values, 1], [1, positions, 3]]) {
      gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, buffer);
      gl.bufferData(gl.TRANSFORM_FEEDBACK_BUFFER, 4 * floats * count, gl.STREAM_READ);
      gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, index, buffer);
    }
    gl.useProgram(program);
    const view = this.view();
    gl.uniformMatrix3fv(gl.getUniformLocation(program, "u_rotation"), false, view.u_rotation);
    setUniforms(gl, program, { u_wi: wi, u_explicit: 1, u_scale: view.u_scale });
    gl.enable(gl.RASTERIZER_DISCARD);
    gl.beginTransformFeedback(gl.POINTS);
    gl.drawArrays(gl.POINTS, 0, count);
    gl.endTransformFeedback();
    gl.disable(gl.RASTERIZER_DISCARD);
    const read = (buffer, floats) => {
      const out = new Float32Array(floats * count);
      gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, buffer);
      gl.getBufferSubData(gl.TRANSFORM_FEEDBACK_BUFFER, 0, out);
      return out;
    };
    const result = { values: read(values, 1), positions: read(positions, 3) };
    for (let index = 0; index < 2; index++) gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, index, null);
    gl.bindVertexArray(null);
    for (const buffer of [input, values, positions]) gl.deleteBuffer(buffer);
    gl.deleteVertexArray(array);
    return result;
  }
}
