"""Blender/Cycles reference harness for specula's OSL target.

The Rust tests call this script with the Python of a virtual environment that
has Blender-as-a-module (``bpy``) installed. It has two subcommands:

``compile SRC.osl [SRC.osl ...]``
    Compiles each file with Cycles' bundled OSL compiler. Prints exactly one
    line per file on stdout, ``ok PATH`` or ``failed PATH``; the compiler's
    own messages (errors and warnings) go to stderr, each prefixed with
    ``PATH:``. Exit status 1 if any file failed.

``render --osl FILE.osl --mesh FILE.obj --eye X Y Z --target X Y Z
--up X Y Z --fov-y DEG --width W --height H --samples S --light X Y Z
--output OUT.exr [--input NAME=VALUE ...] [--output-socket Emission|BSDF]``
    Renders the mesh, shaded by a Script node running the shader, with Cycles
    on the CPU and the OSL shading system, and writes a scene-linear 32-bit
    float RGBA OpenEXR (no view transform baked in). ``--light`` is the
    direction from the surface towards the light in world space; it is passed
    to the shader's ``Light`` input and, for ``--output-socket BSDF``, also
    orients a Sun lamp of irradiance 1 W/m^2 shining along ``-light``.
    ``--input NAME=VALUE`` sets another input socket: a number, or ``X,Y,Z``
    for vector and colour sockets. Prints ``render time: SECONDS s``.

Any failure exits with status 1 and a single ``error: ...`` line on stderr
(bad command-line syntax: argparse's usage message and status 2).

Scene conventions (world is right-handed, z up, as in specula): the OBJ is
imported without any axis conversion, its ``vn`` normals become the exact
smooth shading normals, the camera's vertical field of view is
``--fov-y`` and pixels are box filtered over exactly one pixel, so a pixel is
the mean radiance over its footprint, like a supersampled rasterizer.

Cycles OSL conventions, measured with bpy 5.0.1 (OSL 1.14.7); the shaders that
specula generates rely on these:

(a) ``I`` points from the shading point towards the viewer (Cycles passes
    its ``wi``, the reverse of the OSL specification's camera-to-point
    direction), so the unit vector towards the viewer is ``wo = normalize(I)``.
    A unit sphere seen from (0, -4, 0) emitting ``max(dot(N, I), 0)`` reads
    0.9999 at the centre pixel, while ``max(dot(N, -I), 0)`` reads 0 there
    (at most 0.001, in silhouette pixels). On a plane seen from (1, 2, 5)
    looking at (0.3, -0.2, 0.25), ``normalize(I)`` at the centre pixel reads
    (0.132, 0.417, 0.899), the direction to the eye (0.133, 0.417, 0.899).
(b) ``W * emission()`` has radiance exactly ``W`` (no 1/pi factor): a plane
    filling the frame with ``0.5 * emission()`` reads 0.5 in every pixel and
    channel of the EXR (which is therefore linear, too: an sRGB encoding
    would read 0.735).
(c) ``P``, ``N`` and ``I`` are in world space (Cycles' "common" space): on
    that plane, z = 0.25, ``P`` at the centre pixel reads (0.301, -0.200,
    0.250), the look-at target, and ``N`` reads (0, 0, 1) everywhere, not a
    camera-space vector. ``N`` is the smooth shading normal, interpolated
    from the vertex normals: on the sphere, whose ``vn`` are the exact radial
    directions (so the interpolated normal is radial too),
    ``|N - normalize(P)|`` is below 1e-7 in every pixel while
    ``|N - Ng|`` reaches 0.041; adding (0.03, 0, 0) to every ``vn`` raises
    ``|N - normalize(P)|`` to 0.030.

Sun lamps: strength is irradiance in W/m^2, so a white ``diffuse(N)`` lit by
the strength-1 sun reads cos(theta) / pi: 0.31831 facing it, 0.25465 at
cos(theta) = 0.8.
"""

import argparse
import contextlib
import math
import os
import sys
import tempfile
import time

import bpy
import mathutils
import numpy

# The bpy wheel keeps Blender's bundled Python packages (``oslquery``, which
# Cycles needs to turn a compiled shader's parameters into node sockets) in
# its own site-packages, which is not on the module's sys.path.
sys.path.append(
    os.path.join(
        bpy.utils.system_resource("PYTHON"),
        "lib",
        "python{}.{}".format(*sys.version_info[:2]),
        "site-packages",
    )
)

import _cycles  # noqa: E402  (only importable once bpy has been imported)
from cycles import osl as cycles_osl  # noqa: E402


class HarnessError(Exception):
    """A failure reported to the caller as one ``error:`` line."""


@contextlib.contextmanager
def captured_stderr():
    """Collects what native code writes to file descriptor 2.

    The OSL compiler prints its diagnostics straight to the C stderr, so
    redirecting ``sys.stderr`` would miss them; the descriptor itself is
    pointed at a temporary file for the duration of the block.
    """
    captured = []
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            captured.append(sink.read().decode(errors="replace"))


def compile_osl(src, dst):
    """Compiles ``src`` to ``dst``; returns (ok, compiler messages)."""
    if not os.path.isfile(src):
        return False, "no such file"
    with captured_stderr() as messages:
        ok = _cycles.osl_compile(src, dst)
    return ok, messages[0].strip()


def command_compile(args):
    all_ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for i, src in enumerate(args.sources):
            ok, messages = compile_osl(src, os.path.join(tmp, f"{i}.oso"))
            print(f"{'ok' if ok else 'failed'} {src}", flush=True)
            for line in messages.splitlines():
                print(f"{src}: {line}", file=sys.stderr, flush=True)
            all_ok &= ok
    return 0 if all_ok else 1


def reset_scene():
    """Empty scene, black world, Cycles with the OSL shading system on the CPU."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene

    world = bpy.data.worlds.new("black")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.shading_system = True
    # Deterministic and unbiased: a fixed seed, no denoiser, no adaptive
    # stopping, no clamping, no light culling threshold.
    cycles.seed = 0
    cycles.use_animated_seed = False
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0
    # Direct lighting only: bounce 0 is the camera ray's hit, whose emission
    # and sampled lamp contributions are all the reference needs.
    cycles.max_bounces = 0
    cycles.diffuse_bounces = 0
    cycles.glossy_bounces = 0
    cycles.transmission_bounces = 0
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = 0
    # A one-pixel box filter averages radiance uniformly over each pixel.
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    cycles.film_exposure = 1.0
    return scene


def read_obj_corners(path):
    """Position and normal of every face corner of an OBJ, in file order."""
    positions, normals, corners = [], [], []
    with open(path) as obj:
        for number, line in enumerate(obj, 1):
            fields = line.split()
            try:
                if fields[:1] == ["v"]:
                    positions.append([float(x) for x in fields[1:4]])
                elif fields[:1] == ["vn"]:
                    normals.append([float(x) for x in fields[1:4]])
                elif fields[:1] == ["f"]:
                    for corner in fields[1:]:
                        # v//vn or v/vt/vn; indices are 1-based, negative
                        # ones count back from the latest element, as in Python.
                        v, _, vn = (corner.split("/") + ["", ""])[:3]
                        corners.append((positions[obj_index(v)], normals[obj_index(vn)]))
            except (ValueError, IndexError):
                raise HarnessError(
                    f"{path}:{number}: malformed, or a face corner without a normal"
                ) from None
    return corners


def obj_index(text):
    """The Python index of a 1-based (or negative, relative) OBJ index."""
    index = int(text)
    if index == 0:
        raise ValueError("OBJ indices start at 1")
    return index - 1 if index > 0 else index


def import_mesh(path, material):
    """Imports the OBJ as-is with its exact normals and gives it ``material``."""
    if not os.path.isfile(path):
        raise HarnessError(f"mesh not found: {path}")
    corners = read_obj_corners(path)
    # The importer's defaults convert from OBJ's usual y-up; forward +y and
    # up +z are the identity, keeping the file's coordinates and normals. One
    # object, faces in file order, lets the corners be matched to the file.
    bpy.ops.wm.obj_import(
        filepath=path,
        forward_axis="Y",
        up_axis="Z",
        use_split_objects=False,
        use_split_groups=False,
    )
    meshes = [obj.data for obj in bpy.context.scene.objects if obj.type == "MESH"]
    if len(meshes) != 1 or len(meshes[0].loops) != len(corners):
        raise HarnessError(f"{path}: imported geometry does not match the file's faces")
    mesh = meshes[0]

    expected = numpy.array([p for p, _ in corners], dtype=numpy.float32)
    vertices = numpy.empty(len(mesh.loops), dtype=numpy.int32)
    mesh.loops.foreach_get("vertex_index", vertices)
    coordinates = numpy.empty(3 * len(mesh.vertices), dtype=numpy.float32)
    mesh.vertices.foreach_get("co", coordinates)
    if not numpy.allclose(coordinates.reshape(-1, 3)[vertices], expected, rtol=1e-6, atol=1e-6):
        raise HarnessError(f"{path}: imported corners are not in file order")

    # The importer keeps ``vn`` as custom normals (and marks every face
    # smooth), but in Blender's 16-bit encoding relative to its own
    # recomputed normals, which rounds small deviations away: on a 96 x 48 UV
    # sphere with exact radial normals Cycles' N was up to 4e-4 off them.
    # Cycles also takes "free" float normals from a corner ``custom_normal``
    # attribute, so the file's normals are stored exactly that way instead.
    normals = numpy.array([n for _, n in corners], dtype=numpy.float64)
    lengths = numpy.linalg.norm(normals, axis=1, keepdims=True)
    if not lengths.all():
        raise HarnessError(f"{path}: zero-length vertex normal")
    mesh.attributes.remove(mesh.attributes["custom_normal"])
    exact = mesh.attributes.new("custom_normal", "FLOAT_VECTOR", "CORNER")
    exact.data.foreach_set("vector", (normals / lengths).astype(numpy.float32).ravel())

    mesh.materials.clear()
    mesh.materials.append(material)


def parse_vector(text, what):
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise HarnessError(f"{what}: expected X,Y,Z, got {text!r}")
    return values


def set_input(node, name, value):
    """Sets a script node input from its command-line text form."""
    socket = node.inputs.get(name)
    if socket is None:
        valid = ", ".join(s.name for s in node.inputs) or "none"
        raise HarnessError(f"no input socket {name!r}; valid inputs: {valid}")
    kind = socket.bl_idname
    try:
        if kind == "NodeSocketFloat":
            socket.default_value = float(value)
        elif kind == "NodeSocketInt":
            socket.default_value = int(value)
        elif kind == "NodeSocketVector":
            socket.default_value = parse_vector(value, name)
        elif kind == "NodeSocketColor":
            socket.default_value = parse_vector(value, name) + (1.0,)
        else:
            raise HarnessError(f"input {name!r} has unsupported type {kind}")
    except ValueError:
        raise HarnessError(f"input {name!r}: {value!r} is not a number") from None


def build_material(oso_path, output_socket, inputs):
    """A material whose surface is the given output of a Script node."""
    material = bpy.data.materials.new("specula")
    tree = material.node_tree
    tree.nodes.clear()
    script = tree.nodes.new("ShaderNodeScript")
    # Pointing the node at the already compiled .oso makes Cycles load it as
    # is: no recompilation and no .oso written next to the caller's .osl.
    script.mode = "EXTERNAL"
    script.filepath = oso_path
    # This is what the node editor's "Script Node Update" button runs; the
    # operator (node.shader_script_update) only polls true inside a node
    # editor, and this call also says whether it worked.
    reports = []
    if not cycles_osl.update_script_node(script, lambda _kind, msg: reports.append(msg)):
        raise HarnessError(f"cannot load shader parameters: {'; '.join(reports)}")

    source = script.outputs.get(output_socket)
    if source is None:
        valid = ", ".join(s.name for s in script.outputs) or "none"
        raise HarnessError(f"no output socket {output_socket!r}; valid outputs: {valid}")
    if source.bl_idname != "NodeSocketShader":
        raise HarnessError(f"output {output_socket!r} is not a closure")
    surface = tree.nodes.new("ShaderNodeOutputMaterial")
    tree.links.new(source, surface.inputs["Surface"])

    for name, value in inputs:
        set_input(script, name, value)
    return material


def add_sun(direction):
    """A sun of irradiance 1 W/m^2 shining along ``-direction``."""
    sun = bpy.data.lights.new("sun", type="SUN")
    sun.energy = 1.0
    sun.color = (1.0, 1.0, 1.0)
    sun.angle = 0.0
    obj = bpy.data.objects.new("sun", sun)
    # A sun shines along its local -z axis.
    obj.rotation_euler = mathutils.Vector(direction).to_track_quat("Z", "Y").to_euler()
    bpy.context.scene.collection.objects.link(obj)


def add_camera(scene, eye, target, up, fov_y):
    camera = bpy.data.cameras.new("camera")
    camera.type = "PERSP"
    camera.sensor_fit = "VERTICAL"
    camera.angle_y = math.radians(fov_y)
    camera.clip_start = 1e-3
    camera.clip_end = 1e6
    obj = bpy.data.objects.new("camera", camera)
    # Blender cameras look along local -z with local +y up.
    eye = mathutils.Vector(eye)
    back = eye - mathutils.Vector(target)
    if back.length == 0:
        raise HarnessError("eye and target coincide")
    back.normalize()
    right = mathutils.Vector(up).cross(back)
    if right.length == 0:
        raise HarnessError("up is parallel to the viewing direction")
    right.normalize()
    true_up = back.cross(right)
    rotation = mathutils.Matrix((right, true_up, back)).transposed()
    obj.matrix_world = mathutils.Matrix.Translation(eye) @ rotation.to_4x4()
    scene.collection.objects.link(obj)
    scene.camera = obj


def configure_output(scene, width, height, samples, path):
    scene.cycles.samples = samples
    render = scene.render
    render.resolution_x = width
    render.resolution_y = height
    render.resolution_percentage = 100
    render.pixel_aspect_x = render.pixel_aspect_y = 1.0
    render.film_transparent = False
    render.use_compositing = False
    render.use_sequencer = False
    render.filepath = path
    render.use_file_extension = False
    # Neutral display settings; they only affect what is shown, since float
    # EXRs are written in the scene-linear space without the view transform.
    view = scene.view_settings
    view.view_transform = "Standard"
    view.look = "None"
    view.exposure = 0.0
    view.gamma = 1.0
    view.use_curve_mapping = False
    image = render.image_settings
    image.file_format = "OPEN_EXR"
    image.color_depth = "32"
    image.color_mode = "RGBA"
    image.exr_codec = "ZIP"
    image.color_management = "FOLLOW_SCENE"
    image.linear_colorspace_settings.name = "Linear Rec.709"


def command_render(args):
    if args.width < 1 or args.height < 1 or args.samples < 1:
        raise HarnessError("width, height and samples must be positive")
    if not any(args.light):
        raise HarnessError("light direction is zero")
    inputs = []
    for item in args.input:
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise HarnessError(f"--input expects NAME=VALUE, got {item!r}")
        inputs.append((name, value))
    light = mathutils.Vector(args.light).normalized()
    # Set like any other input, so a shader without a Light vector is
    # reported the same way.
    inputs.append(("Light", ",".join(map(repr, light))))

    scene = reset_scene()
    with tempfile.TemporaryDirectory() as tmp:
        oso = os.path.join(tmp, "shader.oso")
        started = time.perf_counter()
        ok, messages = compile_osl(args.osl, oso)
        if not ok:
            first = messages.splitlines()[0] if messages else "unknown error"
            raise HarnessError(f"{args.osl} failed to compile: {first}")
        print(f"compile time: {time.perf_counter() - started:.3f} s", flush=True)

        material = build_material(oso, args.output_socket, inputs)
        import_mesh(args.mesh, material)
        if args.output_socket == "BSDF":
            add_sun(light)
        add_camera(scene, args.eye, args.target, args.up, args.fov_y)
        configure_output(scene, args.width, args.height, args.samples, args.output)

        # Removed first, so that a stale image cannot pass the check below.
        if os.path.exists(args.output):
            os.remove(args.output)
        started = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        elapsed = time.perf_counter() - started
    if not os.path.isfile(args.output):
        raise HarnessError(f"Cycles wrote no image to {args.output}")
    print(f"render time: {elapsed:.3f} s", flush=True)
    return 0


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)

    compile_parser = commands.add_parser("compile", help="compile OSL sources")
    compile_parser.add_argument("sources", nargs="+", metavar="SRC.osl")
    compile_parser.set_defaults(run=command_compile)

    render_parser = commands.add_parser("render", help="render a mesh with an OSL shader")
    xyz = {"nargs": 3, "type": float, "metavar": ("X", "Y", "Z"), "required": True}
    render_parser.add_argument("--osl", required=True)
    render_parser.add_argument("--mesh", required=True)
    render_parser.add_argument("--eye", **xyz)
    render_parser.add_argument("--target", **xyz)
    render_parser.add_argument("--up", **xyz)
    render_parser.add_argument("--light", **xyz)
    render_parser.add_argument("--fov-y", type=float, required=True, metavar="DEG")
    render_parser.add_argument("--width", type=int, required=True)
    render_parser.add_argument("--height", type=int, required=True)
    render_parser.add_argument("--samples", type=int, required=True)
    render_parser.add_argument("--output", required=True, metavar="OUT.exr")
    render_parser.add_argument("--input", action="append", default=[], metavar="NAME=VALUE")
    render_parser.add_argument("--output-socket", choices=("Emission", "BSDF"), default="Emission")
    render_parser.set_defaults(run=command_render)
    return parser.parse_args(argv)


def main(argv):
    args = parse_args(argv)
    try:
        return args.run(args)
    except Exception as error:  # bpy raises RuntimeError from operators
        message = " ".join(str(error).split()) or type(error).__name__
        print(f"error: {message}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
