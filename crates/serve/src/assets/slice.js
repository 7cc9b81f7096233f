// specula explorer, the image slice drawn live (WebGL2): the chosen lobe's specular term over
// theta_h (across, on BRDF Explorer's square-root scale: theta_h = 90 u^2 degrees at the
// fraction u of the width) and theta_d (down, linear), phi_d = 90 degrees, as the server's
// slice (explorer.rs, `from_half_difference`) but at every pixel; six decades below the peak
// (f at theta_h = theta_d = 0) in viridis, with its colour bar. app.js draws the axes.
"use strict";

// The image's margins in the slice's 2D canvas (app.js's drawSlice) and the bar beside it.
const SLICE_MARGINS = { left: 38, top: 22, right: 62, bottom: 36 };
const SLICE_BAR = { gap: 10, width: 12 };
const SLICE_DECADES = 6;

function sliceFragment(lobe) {
  return `#version 300 es
precision highp float;
${lobe}
${VIRIDIS}
uniform vec2 u_extent;
out vec4 colour;

void main() {
  vec2 p = gl_FragCoord.xy;
  float s;
  if (p.x > u_extent.x) {
    s = p.y / u_extent.y;
  } else {
    float u = p.x / u_extent.x;
    float thetaH = 1.5707963 * u * u;
    float thetaD = 1.5707963 * (1.0 - p.y / u_extent.y);
    // The difference vector at phi_d = 90 degrees, turned so that its z axis is the half vector.
    vec3 d = vec3(0.0, sin(thetaD), cos(thetaD));
    mat3 turn = mat3(cos(thetaH), 0.0, -sin(thetaH), 0.0, 1.0, 0.0, sin(thetaH), 0.0, cos(thetaH));
    vec3 wi = turn * d;
    vec3 wo = turn * vec3(-d.x, -d.y, d.z);
    const vec3 normal = vec3(0.0, 0.0, 1.0);
    float f = wi.z > 0.0 && wo.z > 0.0 ? specula_specular(normal, wo, wi) : 0.0;
    float peak = specula_specular(normal, normal, normal);
    s = f > 0.0 ? 1.0 + log(f / peak) / log(10.0) / ${SLICE_DECADES.toFixed(1)} : 0.0;
  }
  colour = vec4(viridis(clamp(s, 0.0, 1.0)), 1.0);
}`;
}

class LiveSlice {
  constructor(canvas, axes) {
    this.canvas = canvas;
    this.axes = axes;
    this.gl = canvas.getContext("webgl2", { antialias: false });
    if (!this.gl) throw new Error("no WebGL2");
    this.program = null;
  }

  setLobe(text) {
    const gl = this.gl;
    if (this.program) gl.deleteProgram(this.program);
    this.program = linkProgram(gl, FULL_SCREEN_VERTEX, sliceFragment(text));
  }

  // Covers the 2D canvas's image and bar, at its pixel size.
  draw() {
    const gl = this.gl;
    if (!this.program) return;
    const m = SLICE_MARGINS;
    const [w, h] = [this.axes.width - m.left - m.right, this.axes.height - m.top - m.bottom];
    const width = w + SLICE_BAR.gap + SLICE_BAR.width;
    if (this.canvas.width !== width || this.canvas.height !== h) [this.canvas.width, this.canvas.height] = [width, h];
    Object.assign(this.canvas.style, { left: m.left + "px", top: m.top + "px", width: width + "px", height: h + "px" });
    gl.viewport(0, 0, width, h);
    gl.clearColor(1, 1, 1, 0);
    gl.clear(gl.COLOR_BUFFER_BIT);
    gl.useProgram(this.program);
    setUniforms(gl, this.program, { u_extent: [w, h] });
    gl.enable(gl.SCISSOR_TEST);
    for (const [x, span] of [[0, w], [w + SLICE_BAR.gap, SLICE_BAR.width]]) {
      gl.scissor(x, 0, span, h);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    }
    gl.disable(gl.SCISSOR_TEST);
  }
}
