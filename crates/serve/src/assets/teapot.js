// specula explorer, the lit teapot drawn live (WebGL2): the triangles `specula render`
// rasterizes (/api/teapot: its mesh in world space and its camera's matrix), each pixel shaded
// by the renderer's formula (live.js's SHADING) with the chosen lobe's exported function, as
// the CPU renderer's per-pixel (phong) shading does, or each vertex shaded and the linear
// radiance interpolated across the triangle (perspective-correct, WebGL's default), as its
// gouraud shading does; the light is a uniform.
"use strict";

function teapotVertex(lobe) {
  return `#version 300 es
${lobe}
${SHADING}
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_view_projection;
uniform vec3 u_eye;
uniform float u_backdrop;
uniform float u_gouraud;
out vec3 v_position;
out vec3 v_normal;
out vec3 v_radiance;
void main() {
  v_position = a_position;
  v_normal = a_normal;
  v_radiance = u_gouraud > 0.5 ? shade(normalize(a_normal), normalize(u_eye - a_position)) : vec3(0.0);
  // The backdrop: one triangle over the whole image, behind everything.
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = u_backdrop > 0.5 ? vec4(2.0 * corner - 1.0, 0.0, 1.0) : u_view_projection * vec4(a_position, 1.0);
}`;
}

function teapotFragment(lobe) {
  return `#version 300 es
precision highp float;
${lobe}
${SHADING}
uniform vec3 u_eye;
uniform vec3 u_background;
uniform float u_backdrop;
uniform float u_gouraud;
in vec3 v_position;
in vec3 v_normal;
in vec3 v_radiance;
out vec4 colour;
void main() {
  vec3 radiance = u_gouraud > 0.5 ? v_radiance : shade(normalize(v_normal), normalize(u_eye - v_position));
  colour = display(u_backdrop > 0.5 ? u_background : radiance);
}`;
}

class LiveTeapot {
  constructor(canvas, scene, mesh) {
    this.canvas = canvas;
    this.scene = scene;
    this.mesh = mesh;
    this.gl = canvas.getContext("webgl2", { antialias: false });
    if (!this.gl) throw new Error("no WebGL2");
    const gl = this.gl;
    this.array = gl.createVertexArray();
    gl.bindVertexArray(this.array);
    [mesh.positions, mesh.normals].forEach((values, location) => {
      gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(values), gl.STATIC_DRAW);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
    });
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(mesh.triangles), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    this.program = null;
    this.light = [0, -1, 0];
    this.gouraud = false;
  }

  // The lobe's program for `model` (classic, physical, microfacet: then `terms` is its
  // /api/microfacet answer).
  setLobe(text, tonemap, model, terms = null) {
    const gl = this.gl;
    if (this.program) gl.deleteProgram(this.program);
    this.program = linkProgram(gl, teapotVertex(text), teapotFragment(text));
    this.reinhard = tonemap === "reinhard" ? 1 : 0;
    this.model = MODEL_IDS[model];
    this.terms = terms;
  }

  // Square, as wide as its box allows (at most 320 pixels), never scaled.
  draw() {
    const gl = this.gl;
    if (!this.program) return;
    const side = Math.max(64, Math.min(320, Math.floor(this.canvas.parentElement.clientWidth)));
    if (this.canvas.width !== side) {
      [this.canvas.width, this.canvas.height] = [side, side];
      Object.assign(this.canvas.style, { width: side + "px", height: side + "px" });
    }
    const s = this.scene;
    gl.viewport(0, 0, side, side);
    gl.useProgram(this.program);
    gl.uniformMatrix4fv(gl.getUniformLocation(this.program, "u_view_projection"), false, this.mesh.view_projection);
    setUniforms(gl, this.program, {
      u_light: this.light, u_eye: this.mesh.eye, u_colour: s.colour, u_ambient: s.ambient, u_background: s.background,
      u_k: [s.ka, s.kd, s.ks], u_model: this.model, u_reinhard: this.reinhard, u_gouraud: this.gouraud ? 1 : 0,
      ...microfacetUniforms(this.terms),
    });
    gl.bindVertexArray(this.array);
    gl.disable(gl.DEPTH_TEST);
    setUniforms(gl, this.program, { u_backdrop: 1 });
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.enable(gl.DEPTH_TEST);
    gl.clear(gl.DEPTH_BUFFER_BIT);
    // As the renderer does: counter-clockwise on screen is the front (WebGL's default too).
    if (this.mesh.cull_back_faces) gl.enable(gl.CULL_FACE);
    setUniforms(gl, this.program, { u_backdrop: 0 });
    gl.drawElements(gl.TRIANGLES, this.mesh.triangles.length, gl.UNSIGNED_INT, 0);
    gl.disable(gl.CULL_FACE);
    gl.bindVertexArray(null);
  }

  // The image's pixels, rows from the top, RGBA, drawn again first.
  read() {
    this.draw();
    return readSquare(this.gl, 0, this.canvas.width);
  }
}
