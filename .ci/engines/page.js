// The browser side of check.mjs and bench.mjs: one engine per page (?engine=three | tsl |
// babylon), the scene built from the mesh at /work/mesh.json, rendered into a float render
// target and read back linear, rows top first (WebGPU stores them so, WebGL bottom first).
const engineName = new URLSearchParams(location.search).get("engine");

const toBase64 = (f32) => {
  const u8 = new Uint8Array(f32.buffer, f32.byteOffset, f32.byteLength);
  let s = "";
  for (let i = 0; i < u8.length; i += 0x8000) s += String.fromCharCode.apply(null, u8.subarray(i, i + 0x8000));
  return btoa(s);
};
const flipRows = (src, W, H) => {
  const out = new Float32Array(W * H * 4);
  for (let y = 0; y < H; y++) out.set(src.subarray((H - 1 - y) * W * 4, (H - y) * W * 4), y * W * 4);
  return out;
};

// ---- three.js: WebGLRenderer (WebGL2) or WebGPURenderer + TSL ----
async function threeBackend(cfg, node) {
  const THREE = node ? await import("three/webgpu") : await import("three");
  const canvas = document.createElement("canvas");
  document.body.appendChild(canvas);
  const info = {};
  let renderer;
  if (node) {
    let adapter = null;
    try { adapter = navigator.gpu ? await navigator.gpu.requestAdapter() : null; } catch (e) { info.adapterError = e.message; }
    info.adapter = adapter ? `${adapter.info?.vendor ?? "?"} ${adapter.info?.architecture ?? ""} ${adapter.info?.description ?? ""}`.trim()
      : null;
    renderer = new THREE.WebGPURenderer({ canvas, antialias: false, forceWebGL: !adapter });
    await renderer.init();
    info.backend = renderer.backend.isWebGPUBackend ? "WebGPU" : "WebGL2 (forceWebGL: no WebGPU adapter)";
  } else {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    const gl = renderer.getContext();
    info.backend = gl.getParameter(gl.VERSION);
  }
  const webgpu = !!renderer.backend?.isWebGPUBackend;
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.setPixelRatio(1);
  renderer.setSize(cfg.W, cfg.H, false);
  renderer.setClearColor(0x000000, 0);
  const rtType = node ? THREE.RenderTarget : THREE.WebGLRenderTarget;
  const rt = new rtType(cfg.W, cfg.H, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
  const scene = new THREE.Scene();
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(cfg.mesh.positions), 3));
  geometry.setAttribute("normal", new THREE.BufferAttribute(new Float32Array(cfg.mesh.normals), 3));
  geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(cfg.mesh.indices), 1));
  const mesh = new THREE.Mesh(geometry);
  mesh.frustumCulled = false;
  scene.add(mesh);
  for (const l of cfg.lights) {
    const light = new THREE.DirectionalLight(0xffffff, 1);
    light.color.setRGB(...l.intensity, THREE.LinearSRGBColorSpace);
    light.position.fromArray(l.towards).multiplyScalar(10); // its target stays at the origin
    scene.add(light);
  }
  const c = cfg.camera;
  const camera = new THREE.PerspectiveCamera(c.fov, cfg.W / cfg.H, c.near, c.far);
  camera.up.fromArray(c.up);
  camera.position.fromArray(c.eye);
  camera.lookAt(new THREE.Vector3(...c.target));
  const buffer = new Float32Array(cfg.W * cfg.H * 4), one = new Float32Array(4);
  return {
    info,
    async material(v) {
      const m = node ? new THREE.MeshPhongNodeMaterial() : new THREE.MeshPhongMaterial();
      m.shininess = v.n;
      m.color.setRGB(...v.color, THREE.LinearSRGBColorSpace);
      m.specular.setRGB(...v.specular, THREE.LinearSRGBColorSpace);
      m.emissive.setRGB(0, 0, 0);
      if (v.module) {
        const mod = await import(v.module);
        if (node) await mod.speculaPhongNode(m, { n: v.n }); else mod.speculaPhong(m, { n: v.n });
      }
      return {
        use: () => { mesh.material = m; },
        setN: (n) => { m.userData.specula.n.value = n; },
        dispose: () => m.dispose(),
      };
    },
    draw() { renderer.setRenderTarget(rt); renderer.render(scene, camera); },
    async read() {
      if (node) {
        const px = await renderer.readRenderTargetPixelsAsync(rt, 0, 0, cfg.W, cfg.H);
        const f = new Float32Array(px.buffer, px.byteOffset, cfg.W * cfg.H * 4);
        return webgpu ? f.slice() : flipRows(f, cfg.W, cfg.H);
      }
      renderer.readRenderTargetPixels(rt, 0, 0, cfg.W, cfg.H, buffer);
      return flipRows(buffer, cfg.W, cfg.H);
    },
    async sync() {
      if (node) await renderer.readRenderTargetPixelsAsync(rt, 0, 0, 1, 1);
      else renderer.readRenderTargetPixels(rt, 0, 0, 1, 1, one);
    },
    programs: () => (node ? null : renderer.info.programs.length),
  };
}

// ---- Babylon.js: Engine (WebGL2), StandardMaterial ----
async function babylonBackend(cfg) {
  const B = "@babylonjs/core/";
  const [{ Engine }, { Constants }, { Scene }, { Vector3 }, { Color3, Color4 }, { TargetCamera },
    { DirectionalLight }, { StandardMaterial }, { RenderTargetTexture }, { Mesh }, { VertexData }] =
    await Promise.all(["Engines/engine.js", "Engines/constants.js", "scene.js", "Maths/math.vector.js",
      "Maths/math.color.js", "Cameras/targetCamera.js", "Lights/directionalLight.js",
      "Materials/standardMaterial.js", "Materials/Textures/renderTargetTexture.js", "Meshes/mesh.js",
      "Meshes/mesh.vertexData.js"].map((p) => import(B + p)));
  const canvas = document.createElement("canvas");
  canvas.width = cfg.W; canvas.height = cfg.H;
  document.body.appendChild(canvas);
  const engine = new Engine(canvas, false, { preserveDrawingBuffer: false, stencil: false }, false);
  engine.setSize(cfg.W, cfg.H);
  const scene = new Scene(engine);
  scene.useRightHandedSystem = true;
  scene.imageProcessingConfiguration.isEnabled = false; // no tone mapping, no gamma
  scene.ambientColor = new Color3(0, 0, 0);
  scene.clearColor = new Color4(0, 0, 0, 0);
  const c = cfg.camera;
  const camera = new TargetCamera("camera", new Vector3(...c.eye), scene);
  camera.upVector = new Vector3(...c.up);
  camera.setTarget(new Vector3(...c.target));
  camera.fov = (c.fov * Math.PI) / 180; // vertical
  camera.minZ = c.near; camera.maxZ = c.far;
  scene.activeCamera = camera;
  for (const [i, l] of cfg.lights.entries()) {
    const light = new DirectionalLight(`light${i}`, new Vector3(...l.towards).scale(-1), scene);
    light.diffuse = new Color3(...l.intensity);
    light.specular = new Color3(...l.intensity);
    light.intensity = 1;
  }
  const mesh = new Mesh("mesh", scene);
  const data = new VertexData();
  data.positions = cfg.mesh.positions;
  data.normals = cfg.mesh.normals;
  data.indices = cfg.mesh.indices;
  data.applyToMesh(mesh);
  mesh.alwaysSelectAsActiveMesh = true;
  const rtt = new RenderTargetTexture("rt", { width: cfg.W, height: cfg.H }, scene, {
    generateMipMaps: false, type: Constants.TEXTURETYPE_FLOAT, format: Constants.TEXTUREFORMAT_RGBA,
    samplingMode: Constants.TEXTURE_NEAREST_SAMPLINGMODE, generateDepthBuffer: true, doNotChangeAspectRatio: true,
  });
  rtt.renderList = [mesh];
  rtt.activeCamera = camera;
  rtt.clearColor = new Color4(0, 0, 0, 0);
  let count = 0;
  const effects = () => Object.keys(engine._compiledEffects ?? {}).length;
  return {
    info: { backend: `WebGL${engine.webGLVersion}` },
    async material(v) {
      const m = new StandardMaterial(`m${count++}`, scene);
      m.diffuseColor = new Color3(...v.color);
      m.specularColor = new Color3(...v.specular);
      m.emissiveColor = new Color3(0, 0, 0);
      m.ambientColor = new Color3(0, 0, 0);
      m.specularPower = v.n;
      // the mesh's triangles are counter-clockwise seen from outside (specula's and three's rule)
      m.sideOrientation = Constants.MATERIAL_CounterClockWiseSideOrientation;
      let plugin = null;
      if (v.module) plugin = (await import(v.module)).speculaPlugin(m, { n: v.n });
      return {
        use: async () => {
          mesh.material = m;
          await scene.whenReadyAsync();
          for (let k = 0; k < 500 && !(m.isReady(mesh) && rtt.isReadyForRendering()); k++) {
            await new Promise((r) => setTimeout(r, 10));
          }
        },
        setN: (n) => { plugin.n = n; },
        dispose: () => m.dispose(),
      };
    },
    draw() { rtt.render(); },
    async read() {
      let px = await rtt.readPixels(0, 0, null, true);
      // the first frames after a compile may come out empty while the effect links
      for (let k = 0; k < 50 && !px.some((x) => x !== 0); k++) {
        await new Promise((r) => setTimeout(r, 20));
        rtt.render();
        px = await rtt.readPixels(0, 0, null, true);
      }
      return flipRows(new Float32Array(px.buffer, px.byteOffset, cfg.W * cfg.H * 4), cfg.W, cfg.H);
    },
    async sync() { await rtt.readPixels(0, 0, null, true, false, 0, 0, 1, 1); },
    programs: effects,
  };
}

let backend = null;
window.specula = {
  async init(cfg) {
    cfg.mesh = await (await fetch("/work/mesh.json")).json();
    backend = engineName === "babylon" ? await babylonBackend(cfg)
      : await threeBackend(cfg, engineName === "tsl");
    return backend.info;
  },
  // v: { module (URL or null: the engine's own material), n, color, specular, thenN }:
  // the image (RGBA f32, base64), and with thenN a second one after n is set to thenN.
  async render(v) {
    const m = await backend.material(v);
    await m.use();
    backend.draw();
    const out = { image: toBase64(await backend.read()) };
    if (v.thenN !== undefined) {
      const before = backend.programs();
      m.setN(v.thenN);
      backend.draw();
      out.imageThen = toBase64(await backend.read());
      const after = backend.programs();
      out.newPrograms = before === null ? null : after - before;
    }
    m.dispose();
    return out;
  },
  // The message of the error the module throws for n, or null.
  async refuses(module, n) {
    try { await backend.material({ module, n, color: [0, 0, 0], specular: [1, 1, 1] }); return null; }
    catch (e) { return `${e.name}: ${e.message}`; }
  },
  // Frame times: variants compiled and warmed up, then `rounds` rounds over all of them (so that
  // drift spreads evenly), each `frames` frames and one 1-pixel read to wait for the GPU.
  async bench(variants, { rounds, frames, warmup }) {
    const ms = variants.map(() => []);
    const ms_ = [];
    for (const v of variants) ms_.push(await backend.material(v));
    for (const m of ms_) { await m.use(); for (let i = 0; i < warmup; i++) backend.draw(); await backend.sync(); }
    for (let r = 0; r < rounds; r++) {
      for (const [i, m] of ms_.entries()) {
        await m.use();
        backend.draw(); await backend.sync();
        const t0 = performance.now();
        for (let f = 0; f < frames; f++) backend.draw();
        await backend.sync();
        ms[i].push((performance.now() - t0) / frames);
      }
    }
    for (const m of ms_) m.dispose();
    return ms;
  },
};
window.speculaReady = true;
