#!/usr/bin/env python3
"""Checks a generated Mitsuba 3 BSDF plugin: its sampling (chi-square) and a reference render.

    python mitsuba_check.py chi2 --plugin FILE.py --bsdf specula_pow --variant llvm_ad_rgb \
        [--n 8 64 512] [--theta 0 35 70] [--geometry phong blinn] [--kd 0] [--ks 1]
    python mitsuba_check.py eval --plugin FILE.py --bsdf specula_pow --model microfacet \
        [--n 64] [--kd 0] [--ks 1] [--f0 1] < PAIRS.json
    python mitsuba_check.py render --plugin FILE.py --bsdf specula_pow --scene SCENE.json \
        --output OUT.exr --variant scalar_rgb|llvm_ad_rgb [--frames N] [--threads T]

render writes the first frame; with --frames it then times N more frames (new seeds) on T
threads and prints `{"seconds": [...], "first": s, "mitsuba": version, "threads": T}`.

chi2 prints one line per case, `pass|fail bsdf=... n=... geometry=... theta=... p=...`, then
`N passed, M failed`, and exits 1 if any case fails.

JIT variants run Mitsuba's own `mitsuba.chi2.ChiSquareTest` with `BSDFAdapter`. That class
needs JIT arrays (`dr.arange`, vector PCG32, `ScalarBoundingBox2f`), so in scalar variants the
same test (same (phi, cos theta) grid, Pearson statistic, pooling, Sidak correction) is done
here with one plugin call per sample and an adaptive integration of the density per cell.

SCENE.json (paths relative to the JSON file):

    {"environment": "sky.exr",
     "meshes": [{"obj": "sphere.obj", "n": 64, "kd": [0.1, 0.2, 0.3], "ks": [1, 1, 1],
                 "geometry": "phong", "normalisation": "lobe"}],
     "camera": {"eye": [0, -4, 1], "target": [0, 0, 0], "up": [0, 0, 1], "fov": 40,
                "width": 64, "height": 48},
     "spp": 64, "seed": 0}

A mesh's kd and ks are a number or rgb (default 0 and 1), n defaults to 64, geometry to
"phong", normalisation to "lobe"; "face_normals": true shades flat (else the OBJ's normals,
or smooth ones Mitsuba computes). In place of "obj", "sphere": {"centre": [x, y, z],
"radius": r} is Mitsuba's own analytic sphere. The environment is an EXR or HDR in specula's layout.

Conventions, matched to specula's renderer (world right-handed, z up):
- specula's lat-long map has z up and its middle column looking along +y; Mitsuba's
  `envmap` has y up and its middle column along +z, so it gets
  `to_world = [[-1,0,0],[0,0,1],[0,1,0]]` (checked by rendering, through a camera looking
  along +y, a map with soft spots placed at +y, 30 degrees towards +x and 45 degrees up by
  specula's own mapping: each lands on the pixel the camera model predicts, within 0.5 px);
- Mitsuba 3.9 centres row y of H at v = y / (H - 1) (the first and last rows sit on the
  poles) where specula centres it at (y + 0.5) / H; columns agree, both at (x + 0.5) / W;
- Mitsuba interpolates the map bilinearly, specula takes the nearest texel: compare renders
  only on smooth maps;
- the camera is `perspective` with `fov_axis = "y"` and `to_world = look_at(eye, target,
  up)`; Mitsuba's look_at puts camera +x on the viewer's left and its film flips x back, so
  the image is not mirrored: something at +x seen from -y lies on the image's right.
"""

import argparse
import glob
import importlib.util
import json
import os
import re
import sys
import time

# specula's map (z up, middle column +y) seen through Mitsuba's envmap (y up, middle +z).
ENVMAP_TO_WORLD = [[-1, 0, 0, 0], [0, 0, 1, 0], [0, 1, 0, 0], [0, 0, 0, 1]]

# Chi-square settings. The JIT ones are Mitsuba's own test at 4x its default grid in cos
# theta and 8x its integration points: the default (res 101, ires 4) cannot integrate a
# lobe of n = 512 (about 0.002 wide in cos theta) and rejects a correct sampler.
JIT_CHI2 = {"sample_count": 1_000_000, "res": 401, "ires": 32}
# Scalar variants call the plugin once per sample (about 12 us) and integrate adaptively.
SCALAR_CHI2 = {"sample_count": 100_000, "res": 101}
SIGNIFICANCE = 0.01
MASS_TOLERANCE = 0.005
# LLVM 15 aborts on Dr.Jit 1.5's kernels; 19 works (16 to 18 untried).
MIN_LLVM = 16


# --------------------------------------------------------------------------- set-up

def pick_libllvm():
    """(version, path) of the newest libLLVM on the machine, or None.

    Dr.Jit loads whichever libLLVM it finds first, and Dr.Jit 1.5 emits `fmaximum`
    reductions that LLVM 15 cannot select (the process aborts with "LLVM ERROR: Cannot
    select"), so it is pointed at the newest one. Tested with Debian's libllvm19.
    """
    found = []
    for path in glob.glob("/usr/lib/x86_64-linux-gnu/libLLVM*.so*") + \
            glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so*"):
        match = re.search(r"libLLVM(?:-|\.so\.)(\d+)", os.path.basename(path))
        if match:
            found.append((int(match.group(1)), path))
    return max(found) if found else None


def init_mitsuba(variant):
    """Import Mitsuba with `variant` set (DRJIT_LIBLLVM_PATH must be set before import)."""
    if variant.startswith("llvm") and not os.environ.get("DRJIT_LIBLLVM_PATH"):
        newest = pick_libllvm()
        if newest is None or newest[0] < MIN_LLVM:
            sys.exit("%s needs libLLVM %d or newer (Debian: apt-get install libllvm19), "
                     "or DRJIT_LIBLLVM_PATH; found %s" % (variant, MIN_LLVM, newest))
        os.environ["DRJIT_LIBLLVM_PATH"] = newest[1]
    import mitsuba as mi
    mi.set_variant(variant)
    return mi


def load_plugin(path):
    """Execute the plugin file: it registers its BSDF with the variant now set."""
    name = "specula_plugin_" + re.sub(r"\W", "_", os.path.splitext(os.path.basename(path))[0])
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def rgb(value):
    """A JSON/CLI colour: a number (grey) or three numbers."""
    if isinstance(value, (int, float)):
        return [float(value)] * 3
    if len(value) == 1:
        return [float(value[0])] * 3
    return [float(v) for v in value]


def bsdf_dict(bsdf, n, geometry, kd, ks, normalisation="lobe", model="classic", f0=1.0):
    return {"type": bsdf, "n": float(n), "geometry": geometry,
            "normalisation": normalisation, "kd": rgb(kd), "ks": rgb(ks), "model": model,
            "f0": rgb(f0)}


# --------------------------------------------------------------------------- chi-square

def local_view(theta_deg):
    """Mitsuba's si.wi (specula's wo) at `theta_deg` from the normal, in the xz plane."""
    import math
    a = math.radians(theta_deg)
    return [math.sin(a), 0.0, math.cos(a)]


def chi2_jit(mi, spec, theta, test_count, seed):
    """Mitsuba's own test: returns (passed, p, messages)."""
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain
    sample_func, pdf_func = BSDFAdapter(spec["type"], spec, wi=local_view(theta))
    test = ChiSquareTest(SphericalDomain(), sample_func, pdf_func, sample_dim=3,
                         seed=seed, **JIT_CHI2)
    # quiet: on failure run() would also write chi2_data.py into the working directory.
    passed = test.run(SIGNIFICANCE, test_count, quiet=True)
    messages = test.messages.replace(' Target density and histogram were written to '
                                     '"chi2_data.py".', '')
    drawn, integrated = test.histogram_sum[0], test.pdf_sum[0]
    mass_ok, note = mass_check(drawn, integrated, JIT_CHI2["sample_count"])
    return passed and mass_ok, test.p_value, messages + note


def mass_check(drawn, integrated, count):
    """The density must integrate to the fraction of draws that succeed. Pearson's test on a
    fine grid spreads a global excess over thousands of cells and barely sees it, so this is
    checked apart: within 5 binomial standard errors plus MASS_TOLERANCE for the grid's
    integration error (at most 0.0024 seen, for n = 1000 at the pole)."""
    error = 5.0 * (max(integrated * (1.0 - integrated), 0.0) / count) ** 0.5
    ok = abs(drawn - integrated) <= error + MASS_TOLERANCE
    return ok, "mass: drawn %.6f, pdf integrates to %.6f: %s\n" % (
        drawn, integrated, "ok" if ok else "MISMATCH")


class ScalarChi2:
    """Mitsuba's ChiSquareTest for scalar variants, on the same domain: x = phi in [-pi, pi]
    (res / 2 cells), y = -cos theta in [-1, 1] (res cells); the map is area-preserving, so
    the expected count of a cell is N times the density integrated over (x, y)."""

    def __init__(self, mi, spec, theta, seed):
        import numpy as np
        self.mi, self.np = mi, np
        self.bsdf = mi.load_dict(spec)
        self.ctx = mi.BSDFContext()
        self.si = mi.SurfaceInteraction3f()
        self.si.wi = mi.Vector3f(*local_view(theta))
        self.count, res = SCALAR_CHI2["sample_count"], SCALAR_CHI2["res"]
        self.nx, self.ny = res // 2, res
        self.seed = seed

    def histogram(self):
        """Counts of the directions drawn with nonzero weight, per cell."""
        np, mi = self.np, self.mi
        u = np.random.default_rng(self.seed).random((self.count, 3))
        drawn = []
        for u0, u1, u2 in u.tolist():
            bs, weight = self.bsdf.sample(self.ctx, self.si, u0, mi.Point2f(u1, u2))
            if max(weight) != 0.0:  # BSDFAdapter's rule: all-zero weight = no sample
                drawn.append((bs.wo[0], bs.wo[1], bs.wo[2]))
        d = np.array(drawn).reshape(-1, 3)
        x = (np.arctan2(d[:, 1], d[:, 0]) + np.pi) / (2 * np.pi) * self.nx
        y = (-d[:, 2] + 1.0) / 2.0 * self.ny
        ix = np.clip(x.astype(int), 0, self.nx - 1)
        iy = np.clip(y.astype(int), 0, self.ny - 1)
        counts = np.zeros((self.ny, self.nx))
        np.add.at(counts, (iy, ix), 1.0)
        return counts

    def density(self, x, y):
        """The plugin's pdf at the point (phi, -cos theta)."""
        import math
        c = -y
        s = math.sqrt(max(0.0, 1.0 - c * c))
        wo = self.mi.Vector3f(math.cos(x) * s, math.sin(x) * s, c)
        return float(self.bsdf.pdf(self.ctx, self.si, wo))

    def simpson(self, x0, y0, hx, hy, k):
        """Simpson's rule with k x k points (k odd) over one cell."""
        np = self.np
        w = np.ones(k)
        w[1:-1:2], w[2:-1:2] = 4.0, 2.0
        w *= 1.0 / (3.0 * (k - 1))
        xs, ys = x0 + hx * np.linspace(0, 1, k), y0 + hy * np.linspace(0, 1, k)
        f = np.array([[self.density(x, y) for x in xs] for y in ys])
        return float(w @ f @ w) * hx * hy

    def cell(self, x0, y0, hx, hy):
        """Expected count of one cell, refined until the integral is settled far below the
        count's Poisson noise (peaks, the horizon and the lobe's cut-off need it)."""
        prev = self.simpson(x0, y0, hx, hy, 3) * self.count
        for k in (5, 9, 17, 33, 65):
            cur = self.simpson(x0, y0, hx, hy, k) * self.count
            if abs(cur - prev) <= 0.02 * max(cur, 1.0) ** 0.5 + 1e-3:
                return cur
            prev = cur
        return prev

    def expected(self):
        import math
        hx, hy = 2 * math.pi / self.nx, 2.0 / self.ny
        return self.np.array([[self.cell(-math.pi + i * hx, -1.0 + j * hy, hx, hy)
                               for i in range(self.nx)] for j in range(self.ny)])

    def run(self, test_count):
        """(passed, p, messages), as ChiSquareTest.run decides them."""
        np, mi = self.np, self.mi
        obs, exp = self.histogram().ravel(), self.expected().ravel()
        order = np.argsort(exp, kind="stable")
        stat, dof, pooled_in, pooled_out = mi.math_py.chi2(obs[order], exp[order], 5)
        msg = "pooled %d cells into %d; histogram sum %.6f, pdf sum %.6f; chi2 %.3f dof %d" % (
            pooled_in, pooled_out, obs.sum() / self.count, exp.sum() / self.count, stat, dof)
        if dof < 1 or np.any((exp == 0) & (obs != 0)):
            return False, 0.0, msg + "; samples where the pdf is 0 or too few dof"
        p = 1.0 - mi.math_py.rlgamma(dof / 2.0, stat / 2.0)
        alpha = 1.0 - (1.0 - SIGNIFICANCE) ** (1.0 / test_count)
        mass_ok, note = mass_check(obs.sum() / self.count, exp.sum() / self.count, self.count)
        return bool(p >= alpha) and mass_ok, p, msg + "\n" + note


def override_settings(settings, args):
    """--samples, --res and --ires replace the defaults (ires only exists for JIT)."""
    for key, value in (("sample_count", args.samples), ("res", args.res), ("ires", args.ires)):
        if value is not None and key in settings:
            settings[key] = value


def run_case(job):
    """One chi-square case: (passed, p, messages, seconds). Runs in the main process for JIT
    variants and in a worker process for scalar ones."""
    variant, plugin, spec, theta, seed, test_count, settings = job
    mi = init_worker(variant, plugin)
    start = time.time()
    if variant.startswith("scalar"):
        SCALAR_CHI2.update(settings)
        result = ScalarChi2(mi, spec, theta, seed).run(test_count)
    else:
        JIT_CHI2.update(settings)
        result = chi2_jit(mi, spec, theta, test_count, seed)
    return result + (time.time() - start,)


_WORKER = {}


def init_worker(variant, plugin):
    """Mitsuba and the plugin, once per process (registering a plugin twice is pointless)."""
    if "mi" not in _WORKER:
        _WORKER["mi"] = init_mitsuba(variant)
        load_plugin(plugin)
    return _WORKER["mi"]


def run_cases(jobs, scalar):
    """Results in the cases' order. Scalar cases go to one process per core: each is one
    Python loop holding the GIL. JIT cases stay here: Dr.Jit already uses every core."""
    if not scalar:
        yield from map(run_case, jobs)
        return
    import concurrent.futures
    import multiprocessing
    with concurrent.futures.ProcessPoolExecutor(
            max_workers=min(len(jobs), os.cpu_count() or 1),
            mp_context=multiprocessing.get_context("spawn")) as pool:
        yield from pool.map(run_case, jobs)


def cmd_chi2(args):
    scalar = args.variant.startswith("scalar")
    settings = dict(SCALAR_CHI2 if scalar else JIT_CHI2)
    override_settings(settings, args)
    cases = [(n, g, t) for n in args.n for g in args.geometry for t in args.theta]
    jobs = [(args.variant, os.path.abspath(args.plugin),
             bsdf_dict(args.bsdf, n, g, args.kd, args.ks, model=args.model, f0=args.f0), t,
             args.seed, len(cases), settings)
            for n, g, t in cases]
    print("# chi2 variant=%s model=%s kd=%s ks=%s %s" % (
        args.variant, args.model, args.kd, args.ks, settings))
    failed = 0
    for (n, geometry, theta), (passed, p, messages, seconds) in zip(
            cases, run_cases(jobs, scalar)):
        failed += not passed
        print("%s bsdf=%s n=%g geometry=%s theta=%g p=%.6g time=%.2fs" % (
            "pass" if passed else "fail", args.bsdf, n, geometry, theta, p, seconds),
            flush=True)
        if not passed or args.verbose:
            print("  " + messages.strip().replace("\n", "\n  "))
    print("%d passed, %d failed" % (len(cases) - failed, failed))
    return 1 if failed else 0


# --------------------------------------------------------------------------- render

def envmap_dict(mi, path):
    return {"type": "envmap", "filename": path,
            "to_world": mi.ScalarTransform4f(ENVMAP_TO_WORLD)}


def sensor_dict(mi, camera, spp, seed):
    to_world = mi.ScalarTransform4f().look_at(origin=camera["eye"], target=camera["target"],
                                              up=camera["up"])
    return {
        "type": "perspective", "fov": float(camera["fov"]), "fov_axis": "y",
        "to_world": to_world,
        "film": {"type": "hdrfilm", "width": int(camera["width"]),
                 "height": int(camera["height"]), "pixel_format": "rgb",
                 "component_format": "float32",
                 # box: each sample counts for its own pixel only, as in specula
                 "rfilter": {"type": "box"}},
        "sampler": {"type": "independent", "sample_count": int(spp), "seed": int(seed)},
    }


def mesh_dict(mesh, bsdf, base):
    if "sphere" in mesh:
        # Mitsuba's own sphere, traced exactly, as a Mitsuba user draws one.
        shape = {"type": "sphere", "center": mesh["sphere"]["centre"],
                 "radius": float(mesh["sphere"]["radius"])}
    else:
        shape = {"type": "obj", "filename": os.path.join(base, mesh["obj"])}
    shape["bsdf"] = bsdf_dict(bsdf, mesh.get("n", 64), mesh.get("geometry", "phong"),
                              mesh.get("kd", 0.0), mesh.get("ks", 1.0),
                              mesh.get("normalisation", "lobe"))
    if mesh.get("face_normals"):
        shape["face_normals"] = True
    return shape


def scene_dict(mi, scene, bsdf, base):
    d = {"type": "scene",
         # one emitter draw and one BSDF draw per sample, combined by MIS (power heuristic)
         "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 1},
         "sensor": sensor_dict(mi, scene["camera"], scene.get("spp", 16), scene.get("seed", 0)),
         "environment": envmap_dict(mi, os.path.join(base, scene["environment"]))}
    for i, mesh in enumerate(scene.get("meshes", [])):
        d["mesh_%d" % i] = mesh_dict(mesh, bsdf, base)
    return d


def cmd_render(args):
    mi = init_mitsuba(args.variant)
    if args.threads:
        import drjit as dr
        dr.set_thread_count(args.threads)
    load_plugin(args.plugin)
    with open(args.scene) as f:
        scene = json.load(f)
    base = os.path.dirname(os.path.abspath(args.scene))
    start = time.time()
    loaded = mi.load_dict(scene_dict(mi, scene, args.bsdf, base))
    seed, spp = int(scene.get("seed", 0)), int(scene.get("spp", 16))
    image = mi.render(loaded, seed=seed, spp=spp)
    # Linear float32 RGB EXR; no tone mapping or sRGB curve.
    mi.Bitmap(image, pixel_format=mi.Bitmap.PixelFormat.RGB).write(args.output)
    first = time.time() - start
    print("wrote %s (%s, %.2fs)" % (args.output, args.variant, first), flush=True)
    if args.frames:
        # Timed frames after the first (which loaded the scene and compiled the kernels):
        # each renders and waits for the whole image, as specula's frames do.
        import drjit as dr
        seconds = []
        for frame in range(args.frames):
            begin = time.perf_counter()
            image = mi.render(loaded, seed=seed + 1 + frame, spp=spp)
            dr.eval(image)
            dr.sync_thread()
            seconds.append(time.perf_counter() - begin)
        print(json.dumps({"seconds": seconds, "first": first, "mitsuba": mi.__version__,
                          "threads": dr.thread_count()}), flush=True)
    return 0


# --------------------------------------------------------------------------- eval

def cmd_eval(args):
    """The plugin's `eval` (f cos theta_i, Mitsuba's wo being specula's wi) and `pdf` at the
    direction pairs read from stdin as JSON, [[wo, wi], ...] in the local frame; prints them
    as JSON, [r, g, b, pdf] per pair."""
    import json
    mi = init_mitsuba(args.variant)
    load_plugin(args.plugin)
    bsdf = mi.load_dict(bsdf_dict(args.bsdf, args.n, args.geometry, args.kd, args.ks,
                                  model=args.model, f0=args.f0))
    ctx, si = mi.BSDFContext(), mi.SurfaceInteraction3f()
    values = []
    for wo, wi in json.load(sys.stdin):
        si.wi = mi.Vector3f(*wo)
        value = bsdf.eval(ctx, si, mi.Vector3f(*wi))
        pdf = bsdf.pdf(ctx, si, mi.Vector3f(*wi))
        values.append([float(dr_index(value, c)) for c in range(3)] + [float(dr_scalar(pdf))])
    print(json.dumps(values))
    return 0


def dr_index(value, channel):
    """One channel of a Color3f as a Python float, in any variant."""
    return dr_scalar(value[channel])


def dr_scalar(value):
    """A one-element Dr.Jit value as a Python float, in any variant."""
    import drjit as dr
    return dr.slice(value) if dr.is_jit_v(value) else value


# --------------------------------------------------------------------------- main

def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("chi2", "render", "eval"):
        p = sub.add_parser(name)
        p.add_argument("--plugin", required=True)
        p.add_argument("--bsdf", required=True)
        p.add_argument("--variant", default="scalar_rgb")
    for name in ("chi2", "eval"):
        p = sub.choices[name]
        p.add_argument("--model", choices=["classic", "microfacet"], default="classic")
        p.add_argument("--f0", type=float, nargs="+", default=[1.0])
    c = sub.choices["chi2"]
    c.add_argument("--n", type=float, nargs="+", default=[8, 64, 512])
    c.add_argument("--theta", type=float, nargs="+", default=[0, 35, 70])
    c.add_argument("--geometry", nargs="+", default=["phong", "blinn"])
    c.add_argument("--kd", type=float, nargs="+", default=[0.0])
    c.add_argument("--ks", type=float, nargs="+", default=[1.0])
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--samples", type=int, help="sample count (default: per variant kind)")
    c.add_argument("--res", type=int, help="grid rows in cos theta (default: per variant kind)")
    c.add_argument("--ires", type=int, help="integration points per cell side (JIT only)")
    c.add_argument("--verbose", action="store_true")
    e = sub.choices["eval"]
    e.add_argument("--n", type=float, default=64.0)
    e.add_argument("--geometry", default="blinn")
    e.add_argument("--kd", type=float, nargs="+", default=[0.0])
    e.add_argument("--ks", type=float, nargs="+", default=[1.0])
    r = sub.choices["render"]
    r.add_argument("--scene", required=True)
    r.add_argument("--output", required=True)
    r.add_argument("--frames", type=int, default=0,
                   help="then time this many frames and print their seconds as JSON")
    r.add_argument("--threads", type=int, default=0, help="Dr.Jit's threads (default: all)")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    return {"chi2": cmd_chi2, "eval": cmd_eval, "render": cmd_render}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
