"""Renders a unit sphere with VTK, offscreen through Mesa's EGL, shaded by a lobe module of
`specula shader --lang vtk` (or by VTK's own pow without one), specular only: ambient and
diffuse 0, specular 1, white, so that each pixel is the specular term alone.

    python vtk_lobe_render.py JOB.json [JOB.json ...]

Each JOB.json (VTK imported once for them all): {"module": "/abs/lobe_vtk.py" or null, "n": 32, "side": 160,
           "kind": "surface" | "volume", "lights": "headlight" | "directional" | "positional" | "kit",
           "output": "/abs/out.rgb"}

- surface: vtkSphereSource (512 x 512 facets, exact vertex normals) drawn by
  vtkOpenGLPolyDataMapper with Phong interpolation;
- volume: a radial phantom, 128^3 voxels over [-1.25, 1.25]^3, value 1 - r (so that the
  isovalue 0 is the unit sphere and the gradient is radial), opacity a step to 1 at 0, drawn by
  vtkOpenGLGPUVolumeRayCastMapper with linear interpolation and a 0.002 sample distance, so the
  first sample past the surface is opaque and shows that sample's shading.

The camera looks down -z at the origin, parallel projection, parallel scale 1 (the sphere
fills the height). Writes the framebuffer's RGB bytes, bottom row first (VTK's order), to
`output`, and prints one JSON line per job: {"vtk": version, "uncovered": [...] or null
(no shader seen), "mapper": class}. A job with "control": true drops the module's
replacements, so that its watch must report the pows left.
"""

import importlib.util
import json
import os
import sys

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import numpy as np  # noqa: E402
import vtk  # noqa: E402
from vtk.util import numpy_support  # noqa: E402


def load(path):
    spec = importlib.util.spec_from_file_location(os.path.basename(path)[:-3], path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def surface(n):
    source = vtk.vtkSphereSource()
    source.SetRadius(1.0)
    source.SetThetaResolution(512)
    source.SetPhiResolution(512)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputConnection(source.GetOutputPort())
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetInterpolationToPhong()
    prop.SetAmbient(0.0)
    prop.SetDiffuse(0.0)
    prop.SetSpecular(1.0)
    prop.SetSpecularColor(1.0, 1.0, 1.0)
    prop.SetSpecularPower(n)
    return actor, mapper


def volume(n):
    side = 128
    axis = np.linspace(-1.25, 1.25, side, dtype=np.float64)
    z, y, x = np.meshgrid(axis, axis, axis, indexing="ij")
    values = (1.0 - np.sqrt(x * x + y * y + z * z)).astype(np.float32)
    image = vtk.vtkImageData()
    image.SetDimensions(side, side, side)
    spacing = 2.5 / (side - 1)
    image.SetSpacing(spacing, spacing, spacing)
    image.SetOrigin(-1.25, -1.25, -1.25)
    scalars = numpy_support.numpy_to_vtk(values.ravel(), deep=True)
    image.GetPointData().SetScalars(scalars)
    opacity = vtk.vtkPiecewiseFunction()
    opacity.AddPoint(-1.0, 0.0)
    opacity.AddPoint(-1e-4, 0.0)
    opacity.AddPoint(0.0, 1.0)
    opacity.AddPoint(1.0, 1.0)
    colour = vtk.vtkColorTransferFunction()
    colour.AddRGBPoint(-1.0, 1.0, 1.0, 1.0)
    colour.AddRGBPoint(1.0, 1.0, 1.0, 1.0)
    prop = vtk.vtkVolumeProperty()
    prop.SetScalarOpacity(opacity)
    prop.SetColor(colour)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOn()
    prop.SetAmbient(0.0)
    prop.SetDiffuse(0.0)
    prop.SetSpecular(1.0)
    prop.SetSpecularPower(n)
    mapper = vtk.vtkGPUVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetAutoAdjustSampleDistances(0)
    mapper.SetSampleDistance(0.002)
    mapper.SetUseJittering(0)
    prop_volume = vtk.vtkVolume()
    prop_volume.SetMapper(mapper)
    prop_volume.SetProperty(prop)
    return prop_volume, mapper


def lights(renderer, which):
    """VTK's automatic headlight, one directional or one positional scene light (intensity 1,
    no cone, no attenuation, so that a pixel is the specular term itself), or a light kit."""
    if which == "kit":
        vtk.vtkLightKit().AddLightsToRenderer(renderer)
    elif which in ("directional", "positional"):
        light = vtk.vtkLight()
        light.SetLightTypeToSceneLight()
        light.SetPositional(which == "positional")
        light.SetPosition(-1.5, 0.75, 6.0)
        light.SetFocalPoint(0.0, 0.0, 0.0)
        light.SetConeAngle(180.0)
        renderer.AddLight(light)
    elif which != "headlight":
        raise SystemExit(f"lights must be headlight, directional, positional or kit, not {which!r}")


def main():
    for path in sys.argv[1:]:
        render(path)


def render(path):
    with open(path, encoding="utf-8") as f:
        job = json.load(f)
    n, side = float(job["n"]), int(job["side"])
    prop, mapper = surface(n) if job["kind"] == "surface" else volume(n)
    module = load(job["module"]) if job.get("module") else None
    if module is not None and job.get("control"):
        # The watch's own test: without the replacements every specular pow is left.
        module.VOLUME_SITES, module.SURFACE_SITES = (), ()
    if module is not None:
        if job["kind"] == "surface":
            module.apply_to_actor(prop, n=n)
        else:
            module.apply_to_volume(prop, n=n)
    renderer = vtk.vtkRenderer()
    renderer.SetBackground(0.0, 0.0, 0.0)
    if job["kind"] == "surface":
        renderer.AddActor(prop)
    else:
        renderer.AddVolume(prop)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(0.0, 0.0, 5.0)
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.ParallelProjectionOn()
    camera.SetParallelScale(1.0)
    camera.SetClippingRange(1.0, 10.0)
    lights(renderer, job["lights"])
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(side, side)
    window.AddRenderer(renderer)
    # Twice: the ray caster announces its shader (which the module checks) when it reuses it.
    window.Render()
    prop.Modified()
    window.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    pixels = numpy_support.vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars())
    with open(job["output"], "wb") as f:
        f.write(np.ascontiguousarray(pixels, dtype=np.uint8).tobytes())
    print(json.dumps({
        "vtk": vtk.vtkVersion.GetVTKVersion(),
        "mapper": mapper.GetClassName(),
        "uncovered": module.uncovered(prop) if module else [],
    }))


if __name__ == "__main__":
    main()
