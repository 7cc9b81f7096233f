#!/usr/bin/env python3
"""Render a NIfTI volume with VTK's CPU ray caster (vtkFixedPointVolumeRayCastMapper), the
yardstick specula's volume renderer is compared and timed against, or with its GPU ray caster
(vtkGPUVolumeRayCastMapper, what 3D Slicer and ParaView draw with), optionally shaded by a lobe
module of `specula shader --lang vtk`.

    python vtk_volume.py JOB.json

JOB.json (world = RAS millimetres, as nibabel's affine gives them):

    {"volume": "/abs/file.nii.gz",
     "width": 512, "height": 512,
     "camera": {"position": [x, y, z], "focal_point": [x, y, z], "view_up": [x, y, z],
                "parallel_scale": s},          # parallel projection; s = half the image height, mm
     "sample_distance": 0.5,                   # mm along the ray
     "transfer": [[value, sigma, r, g, b], ...],  # piecewise linear in value, flat beyond the ends;
                                               # sigma = extinction per mm, colour linear RGB
     "shading": {"ambient": 0.25, "diffuse": 0.7, "specular": 0.5, "power": 32} or null,
     "interpolation": "linear" | "nearest",
     "threads": 2, "warmup": 1, "frames": 5,
     "output": "/abs/out.png"}

Optional keys: "mapper": "cpu" (default) or "gpu"; "lobe_module": "/abs/lobe_vtk.py" (GPU
only: its apply_to_volume puts the lobe in place of the specular pow, at the shading's power);
"background" [r, g, b] (default black); "opacity_points_per_segment" (64);
"headlight_ambient_color" [r, g, b] (default: leave the automatic headlight as VTK makes it,
whose ambient colour is black, so that VTK's ambient coefficient has no effect; see
VTK_NOTES.md); "clipping_range" [near, far] in mm from the camera (default:
ResetCameraClippingRange). The ray caster's samples lie at distances near + n d from the
camera plane (n whole), so the near plane fixes the phase of the sampling lattice.

How the job becomes a VTK scene:

- The volume is read with nibabel (on-disk integer type kept when the file has no scaling,
  otherwise float32) into vtkImageData with x fastest. The affine's linear part is split into
  an orthonormal R times diag(spacing) (a shear or a non-orthogonal grid is refused): the
  image gets spacing = the column norms and origin 0, and the vtkVolume's user matrix is
  [R | translation], so VTK computes gradients and measures the sample distance with the
  true spacing (its mapper ignores scaling in the volume's matrix).
- Opacity: a vtkPiecewiseFunction of alpha per unit distance with ScalarOpacityUnitDistance
  1 mm, alpha = 1 - exp(-sigma * 1 mm), sampled at `opacity_points_per_segment` points per
  control-point segment (and at the data's minimum and maximum, flat beyond the ends), so that
  VTK's interpolation linear in alpha follows specula's linear in sigma. VTK then corrects
  alpha per sample as 1 - (1 - alpha)^(sample_distance / 1 mm) = 1 - exp(-sigma d).
- Colour: a vtkColorTransferFunction in RGB space with the control points' colours.
- The GPU caster (mapper "gpu"): vtkGPUVolumeRayCastMapper with AutoAdjustSampleDistances and
  LockSampleDistanceToInputSpacing off, SampleDistance = sample_distance, ImageSampleDistance
  1, jittering off; it shades Phong's R.V (not the CPU caster's Blinn-Phong) and stops a ray at
  1 - 1/255 opacity. Frame times are the wall time of window.Render() and glFinish
  (WaitForCompletion; the mapper's own GetTimeToDraw does not wait for the GPU).
- vtkFixedPointVolumeRayCastMapper: AutoAdjustSampleDistances off,
  LockSampleDistanceToInputSpacing off, SampleDistance = InteractiveSampleDistance =
  sample_distance, ImageSampleDistance 1 (one ray per pixel), `threads` threads (also
  vtkMultiThreader's global maximum and Mesa's LP_NUM_THREADS).
- vtkVolumeProperty: the interpolation asked, ShadeOn with the ambient, diffuse, specular and
  specular power given (ShadeOff for null), IndependentComponents on.
- vtkRenderer: the background, the camera as given with ParallelProjectionOn and
  ResetCameraClippingRange, and VTK's automatic light (checked to be a headlight at the
  camera after the first frame).
- An offscreen vtkRenderWindow (VTK_DEFAULT_OPENGL_WINDOW defaults to vtkEGLRenderWindow:
  Mesa's EGL, no display needed).

`warmup` frames are rendered (the first computes gradients and tables), then `frames` timed
frames, each a full ray cast (checked: the mapper's GetTimeToDraw() is reported per frame).
The last frame's RGB framebuffer (8 bits, the values as VTK composites them, no gamma) is
written to `output` as PNG (vtkWindowToImageFilter, ReadFrontBufferOff, vtkPNGWriter).

Prints one JSON line: {"vtk": version, "mapper": class, "window": class, "scalar_type": ...,
"render_seconds": [...], "draw_seconds": [...], "median_render": s, "median_draw": s,
"light": {...}, "two_sided_lighting": bool, "clipping_range": [near, far],
"first_image_unix": the wall clock when the first frame was drawn, "peak_bytes": the process's
peak resident memory (Python, nibabel's array, VTK's copy, gradients and all)}.
Any failure prints `vtk_volume.py: error: ...` on stderr (one line) and exits 1; without the
vtk package it prints `skipped vtk: ...` and exits 3.
"""

import json
import math
import os
import statistics
import sys
import time


class Failure(Exception):
    """An error reported in one line."""


def vector(value, what, n=3):
    if not (isinstance(value, (list, tuple)) and len(value) == n and all(isinstance(v, (int, float)) for v in value)):
        raise Failure(f"{what} must be a list of {n} numbers")
    if not all(math.isfinite(v) for v in value):
        raise Failure(f"{what} must be finite")
    return [float(v) for v in value]


def read_job(path):
    try:
        with open(path, encoding="utf-8") as f:
            job = json.load(f)
    except (OSError, ValueError) as e:
        raise Failure(f"{path}: {e}")
    if not isinstance(job, dict):
        raise Failure(f"{path}: the job must be a JSON object")
    for key in ("volume", "width", "height", "camera", "sample_distance", "transfer", "output"):
        if key not in job:
            raise Failure(f"{path}: the job has no {key!r}")
    for key in ("width", "height"):
        if not (isinstance(job[key], int) and 1 <= job[key] <= 8192):
            raise Failure(f"{key} must be an integer 1 to 8192")
    camera = job["camera"]
    if not isinstance(camera, dict):
        raise Failure("camera must be an object")
    for key in ("position", "focal_point", "view_up"):
        camera[key] = vector(camera.get(key), f"camera.{key}")
    scale = camera.get("parallel_scale")
    if not (isinstance(scale, (int, float)) and scale > 0):
        raise Failure("camera.parallel_scale must be a positive number (half the image height in mm)")
    d = job["sample_distance"]
    if not (isinstance(d, (int, float)) and d > 0 and math.isfinite(d)):
        raise Failure("sample_distance must be a positive number of millimetres")
    transfer = job["transfer"]
    if not (isinstance(transfer, list) and transfer):
        raise Failure("transfer must be a non-empty list of [value, sigma, r, g, b]")
    points = [vector(p, f"transfer[{n}]", 5) for n, p in enumerate(transfer)]
    if any(b[0] <= a[0] for a, b in zip(points, points[1:])):
        raise Failure("transfer values must increase strictly")
    if any(p[1] < 0 for p in points):
        raise Failure("transfer sigmas must be >= 0")
    job["transfer"] = points
    shading = job.get("shading")
    if shading is not None:
        if not isinstance(shading, dict):
            raise Failure("shading must be an object or null")
        for key in ("ambient", "diffuse", "specular", "power"):
            if not isinstance(shading.get(key), (int, float)):
                raise Failure(f"shading.{key} must be a number")
    job.setdefault("interpolation", "linear")
    if job["interpolation"] not in ("linear", "nearest"):
        raise Failure("interpolation must be 'linear' or 'nearest'")
    for key, default, low in (("threads", 2, 1), ("warmup", 1, 1), ("frames", 5, 1), ("opacity_points_per_segment", 64, 1)):
        job.setdefault(key, default)
        if not (isinstance(job[key], int) and job[key] >= low):
            raise Failure(f"{key} must be an integer >= {low}")
    job["background"] = vector(job.get("background", [0, 0, 0]), "background")
    if job.get("headlight_ambient_color") is not None:
        job["headlight_ambient_color"] = vector(job["headlight_ambient_color"], "headlight_ambient_color")
    job.setdefault("mapper", "cpu")
    if job["mapper"] not in ("cpu", "gpu"):
        raise Failure("mapper must be 'cpu' or 'gpu'")
    module = job.get("lobe_module")
    if module is not None and not (job["mapper"] == "gpu" and isinstance(module, str) and os.path.isfile(module)):
        raise Failure("lobe_module must name an existing file of `specula shader --lang vtk`, with mapper 'gpu'")
    if job.get("clipping_range") is not None:
        near, far = vector(job["clipping_range"], "clipping_range", 2)
        if not 0 < near < far:
            raise Failure("clipping_range must be [near, far] with 0 < near < far")
        job["clipping_range"] = [near, far]
    if not os.path.isfile(job["volume"]):
        raise Failure(f"{job['volume']}: no such file")
    return job


def load_nifti(path):
    """(array [i, j, k], 4x4 affine) with the on-disk integer type kept when unscaled."""
    import nibabel as nib
    import numpy as np

    image = nib.load(path)
    if len(image.shape) != 3:
        raise Failure(f"{path}: a {len(image.shape)}-D image; a volume is 3-D")
    slope, inter = image.dataobj.slope, image.dataobj.inter
    raw_kind = np.dtype(image.get_data_dtype()).kind
    if raw_kind in "iu" and (slope is None or slope == 1 or not np.isfinite(slope)) and (
        inter is None or inter == 0 or not np.isfinite(inter)
    ):
        data = np.asanyarray(image.dataobj)
    else:
        data = image.get_fdata(dtype=np.float32)
    return np.asarray(data), np.asarray(image.affine, dtype=np.float64)


def split_affine(affine):
    """(R orthonormal 3x3, spacing 3, translation 3) of affine = [R diag(spacing) | t]."""
    import numpy as np

    linear = affine[:3, :3]
    spacing = np.linalg.norm(linear, axis=0)
    if np.any(spacing <= 0) or not np.all(np.isfinite(affine)):
        raise Failure("the affine has a zero or non-finite axis")
    rotation = linear / spacing
    error = float(np.abs(rotation.T @ rotation - np.eye(3)).max())
    if error > 1e-4:
        raise Failure(f"the affine's axes are not orthogonal (sheared grid, |R^T R - I| = {error:.2g}); VTK's image data cannot hold it")
    return rotation, spacing, affine[:3, 3]


def alpha_points(transfer, lo, hi, per_segment):
    """(value, alpha per mm) points: linear in sigma between control points, flat beyond."""
    points = []
    values = [p[0] for p in transfer]
    sigmas = [p[1] for p in transfer]
    for (v0, s0), (v1, s1) in zip(zip(values, sigmas), zip(values[1:], sigmas[1:])):
        for k in range(per_segment):
            t = k / per_segment
            points.append((v0 + t * (v1 - v0), s0 + t * (s1 - s0)))
    points.append((values[-1], sigmas[-1]))
    if lo < values[0]:
        points.insert(0, (lo, sigmas[0]))
    if hi > values[-1]:
        points.append((hi, sigmas[-1]))
    return [(v, 1.0 - math.exp(-s * 1.0)) for v, s in points]


def render(job):
    threads = job["threads"]
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    os.environ.setdefault("LP_NUM_THREADS", str(threads))
    try:
        import numpy as np
        import vtk
        from vtk.util import numpy_support
    except ImportError as e:
        print(f"skipped vtk: {e} (pip install vtk)")
        sys.exit(3)

    data, affine = load_nifti(job["volume"])
    rotation, spacing, translation = split_affine(affine)
    flat = np.ascontiguousarray(data.transpose(2, 1, 0)).ravel()  # x fastest
    image = vtk.vtkImageData()
    image.SetDimensions(*[int(n) for n in data.shape])
    image.SetSpacing(*[float(s) for s in spacing])
    image.SetOrigin(0.0, 0.0, 0.0)
    scalars = numpy_support.numpy_to_vtk(flat, deep=True)
    scalars.SetName("values")
    image.GetPointData().SetScalars(scalars)
    lo, hi = float(flat.min()), float(flat.max())

    user = vtk.vtkMatrix4x4()
    for r in range(3):
        for c in range(3):
            user.SetElement(r, c, float(rotation[r, c]))
        user.SetElement(r, 3, float(translation[r]))

    opacity = vtk.vtkPiecewiseFunction()
    for value, alpha in alpha_points(job["transfer"], lo, hi, job["opacity_points_per_segment"]):
        opacity.AddPoint(value, alpha)
    colour = vtk.vtkColorTransferFunction()
    colour.SetColorSpaceToRGB()
    for value, _sigma, r, g, b in job["transfer"]:
        colour.AddRGBPoint(value, r, g, b)

    prop = vtk.vtkVolumeProperty()
    prop.SetIndependentComponents(True)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(1.0)
    prop.SetColor(colour)
    if job["interpolation"] == "linear":
        prop.SetInterpolationTypeToLinear()
    else:
        prop.SetInterpolationTypeToNearest()
    shading = job.get("shading")
    if shading is None:
        prop.ShadeOff()
    else:
        prop.ShadeOn()
        prop.SetAmbient(float(shading["ambient"]))
        prop.SetDiffuse(float(shading["diffuse"]))
        prop.SetSpecular(float(shading["specular"]))
        prop.SetSpecularPower(float(shading["power"]))

    vtk.vtkMultiThreader.SetGlobalMaximumNumberOfThreads(threads)
    gpu = job["mapper"] == "gpu"
    if gpu:
        mapper = vtk.vtkGPUVolumeRayCastMapper()
        mapper.SetUseJittering(0)
    else:
        mapper = vtk.vtkFixedPointVolumeRayCastMapper()
        mapper.SetInteractiveSampleDistance(float(job["sample_distance"]))
        mapper.SetMinimumImageSampleDistance(1.0)
        mapper.SetMaximumImageSampleDistance(1.0)
        mapper.SetNumberOfThreads(threads)
    mapper.SetInputData(image)
    mapper.SetBlendModeToComposite()
    mapper.SetAutoAdjustSampleDistances(0)
    mapper.SetLockSampleDistanceToInputSpacing(0)
    mapper.SetSampleDistance(float(job["sample_distance"]))
    mapper.SetImageSampleDistance(1.0)

    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    volume.SetUserMatrix(user)
    lobe = None
    if job.get("lobe_module") is not None:
        import importlib.util

        try:
            spec = importlib.util.spec_from_file_location("specula_lobe_vtk", job["lobe_module"])
            lobe = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(lobe)
            lobe.apply_to_volume(volume, n=float(shading["power"]) if shading else None)
        except Exception as e:  # the module's refusal, or a module that is not one
            raise Failure(f"{job['lobe_module']}: {e}")

    renderer = vtk.vtkRenderer()
    renderer.SetBackground(*job["background"])
    renderer.AddVolume(volume)
    camera = renderer.GetActiveCamera()
    cam = job["camera"]
    camera.SetPosition(*cam["position"])
    camera.SetFocalPoint(*cam["focal_point"])
    camera.SetViewUp(*cam["view_up"])
    camera.ParallelProjectionOn()
    camera.SetParallelScale(float(cam["parallel_scale"]))
    camera.OrthogonalizeViewUp()
    if job.get("clipping_range") is not None:
        camera.SetClippingRange(*job["clipping_range"])
    else:
        renderer.ResetCameraClippingRange()

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(job["width"], job["height"])
    window.SetMultiSamples(0)
    window.AddRenderer(renderer)
    window_class = window.GetClassName()

    first_image_unix = None
    for _ in range(job["warmup"]):
        window.Render()
        if first_image_unix is None:
            first_image_unix = time.time()
    lights = renderer.GetLights()
    if lights.GetNumberOfItems() != 1:
        raise Failure(f"expected VTK's one automatic light, found {lights.GetNumberOfItems()}")
    light = lights.GetItemAsObject(0)
    position, focal = light.GetPosition(), light.GetFocalPoint()
    at_camera = all(abs(a - b) < 1e-6 for a, b in zip(position, camera.GetPosition())) and all(
        abs(a - b) < 1e-6 for a, b in zip(focal, camera.GetFocalPoint())
    )
    if not (light.LightTypeIsHeadlight() and at_camera):
        raise Failure("VTK's automatic light is not a headlight at the camera")
    if job.get("headlight_ambient_color") is not None:
        light.SetAmbientColor(*job["headlight_ambient_color"])
        window.Render()

    render_seconds, draw_seconds = [], []
    for _ in range(job["frames"]):
        volume.Modified()
        start = time.perf_counter()
        window.Render()
        if gpu:
            window.WaitForCompletion()  # glFinish: the GPU's work, not its queueing
        render_seconds.append(time.perf_counter() - start)
        draw_seconds.append(render_seconds[-1] if gpu else mapper.GetTimeToDraw())
    # The module's watch has seen the shader VTK compiled (from the second frame), with no
    # specular pow left: a shader that failed to compile draws black and is never announced.
    if lobe is not None and lobe.uncovered(volume) != []:
        raise Failure(f"the lobe's shader did not compile or kept a pow: {lobe.uncovered(volume)}")
    if min(draw_seconds) <= 0:
        raise Failure(f"the mapper did not ray cast every frame (draw times {draw_seconds})")

    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    out = os.path.abspath(job["output"])
    tmp = out + ".tmp.png"
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(tmp)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    if not os.path.isfile(tmp) or os.path.getsize(tmp) == 0:
        raise Failure(f"{out}: the PNG was not written")
    os.replace(tmp, out)

    return {
        "vtk": vtk.vtkVersion.GetVTKVersion(),
        "mapper": mapper.GetClassName(),
        "window": window_class,
        "scalar_type": image.GetScalarTypeAsString(),
        "render_seconds": [round(s, 6) for s in render_seconds],
        "draw_seconds": [round(s, 6) for s in draw_seconds],
        "median_render": round(statistics.median(render_seconds), 6),
        "median_draw": round(statistics.median(draw_seconds), 6),
        "light": {
            "headlight": bool(light.LightTypeIsHeadlight()),
            "position": list(position),
            "focal_point": list(focal),
            "intensity": light.GetIntensity(),
            "ambient_color": list(light.GetAmbientColor()),
            "diffuse_color": list(light.GetDiffuseColor()),
            "specular_color": list(light.GetSpecularColor()),
        },
        "two_sided_lighting": bool(renderer.GetTwoSidedLighting()),
        "clipping_range": list(camera.GetClippingRange()),
        "threads": threads if gpu else mapper.GetNumberOfThreads(),
        "first_image_unix": first_image_unix,
        "peak_bytes": peak_bytes(),
    }


def peak_bytes():
    """The process's peak resident memory: Linux's VmHWM, which starts afresh with the
    program (ru_maxrss would carry over the high-water mark of the process that started
    Python); None where there is no /proc."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def main():
    if len(sys.argv) != 2:
        print("usage: vtk_volume.py JOB.json", file=sys.stderr)
        sys.exit(2)
    try:
        job = read_job(sys.argv[1])
        result = render(job)
    except Failure as e:
        print(f"vtk_volume.py: error: {e}", file=sys.stderr)
        sys.exit(1)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
