// specula explorer, the difference of two server images (the environment, the volume, a
// measured material against its fit) and its PSNR. Where WebGL2 is, the difference is drawn by
// the live spheres' own shader (live.js's DIFFERENCE_FRAGMENT: |a - b| in 8-bit levels, the
// larger channel's, on a logarithmic scale in viridis) with its colour bar, so one level shows
// and no image is black or noise; without it, |a - b| per channel times DIFFERENCE_GAIN.
"use strict";

const DIFFERENCE_GAIN = 8;

// One WebGL2 context for every such difference, made at the first; false without WebGL2.
let differ = null;
function differenceContext() {
  if (differ !== null) return differ;
  const canvas = document.createElement("canvas");
  const gl = canvas.getContext("webgl2", { antialias: false });
  differ = gl ? { canvas, gl, program: linkProgram(gl, FULL_SCREEN_VERTEX, DIFFERENCE_FRAGMENT), textures: [gl.createTexture(), gl.createTexture()] } : false;
  return differ;
}

// Draws the log-scale difference of `a` and `b` and its bar onto `canvas`.
function drawLogDifference({ canvas: surface, gl, program, textures }, a, b, canvas) {
  const [w, h] = [a.naturalWidth, a.naturalHeight];
  [surface.width, surface.height] = [w + 8 + BAR_WIDTH, h];
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, true);
  gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
  [a, b].forEach((image, k) => {
    gl.activeTexture(gl.TEXTURE0 + k);
    gl.bindTexture(gl.TEXTURE_2D, textures[k]);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, image);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
  });
  gl.useProgram(program);
  gl.uniform1i(gl.getUniformLocation(program, "u_lobe"), 0);
  gl.uniform1i(gl.getUniformLocation(program, "u_pow"), 1);
  gl.clearColor(1, 1, 1, 1);
  gl.clear(gl.COLOR_BUFFER_BIT);
  gl.viewport(0, 0, w, h);
  setUniforms(gl, program, { u_origin: [0, 0], u_extent: [w, h], u_bar: 0 });
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.viewport(w + 8, 0, BAR_WIDTH, h);
  setUniforms(gl, program, { u_origin: [w + 8, 0], u_extent: [BAR_WIDTH, h], u_bar: 1 });
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.activeTexture(gl.TEXTURE0);
  [canvas.width, canvas.height] = [surface.width + TICKS_WIDTH, h];
  const g = canvas.getContext("2d");
  g.fillStyle = "#fff";
  g.fillRect(0, 0, canvas.width, canvas.height);
  g.drawImage(surface, 0, 0);
  differenceTicks(g, surface.width + 2, h);
}

// The difference of `a` from `b` (named `against`) and the PSNR of a against b over the frame.
function drawDifference(a, b, canvas, caption, against = "pow") {
  const pixelsOf = (img) => {
    const c = Object.assign(document.createElement("canvas"), { width: img.naturalWidth, height: img.naturalHeight });
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    return g.getImageData(0, 0, c.width, c.height);
  };
  const [pa, pb] = [pixelsOf(a), pixelsOf(b)];
  let squares = 0;
  for (let k = 0; k < pa.data.length; k += 4) {
    for (let c = 0; c < 3; c++) squares += (pa.data[k + c] - pb.data[k + c]) ** 2;
  }
  const gpu = differenceContext();
  if (gpu) drawLogDifference(gpu, a, b, canvas);
  else drawAmplifiedDifference(pa, pb, canvas);
  const scale = gpu ? "|a - b| in 8-bit levels on the bar's logarithmic scale" : `|a - b| × ${DIFFERENCE_GAIN}`;
  const mse = squares / (3 * pa.width * pa.height);
  caption.textContent = mse === 0 ? `identical to ${against}` : `PSNR ${(10 * Math.log10(255 * 255 / mse)).toFixed(1)} dB against ${against} (8-bit sRGB); shown: ${scale}`;
}

// |a - b| per 8-bit sRGB channel, amplified.
function drawAmplifiedDifference(pa, pb, canvas) {
  [canvas.width, canvas.height] = [pa.width, pa.height];
  const g = canvas.getContext("2d");
  const out = g.createImageData(pa.width, pa.height);
  for (let k = 0; k < pa.data.length; k += 4) {
    for (let c = 0; c < 3; c++) out.data[k + c] = Math.min(255, DIFFERENCE_GAIN * Math.abs(pa.data[k + c] - pb.data[k + c]));
    out.data[k + 3] = 255;
  }
  g.putImageData(out, 0, 0);
}
