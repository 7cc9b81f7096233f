#!/usr/bin/env python3
"""Check a MaterialX document with MaterialX's own tools.

    python materialx_check.py DOC.mtlx [--out DIR] [--glslang] [--osl-compile] [--require-tools]

1. Loads the standard data libraries shipped with the `MaterialX` Python package, reads DOC,
   imports the libraries into it and runs `doc.validate()`.
2. For every renderable element (`findRenderableElements`) and every target, generates the
   shader with MaterialX's generator and writes its stages to DIR:

       target  generator                                  files
       glsl    PyMaterialXGenGlsl.GlslShaderGenerator     NAME.glsl.frag, NAME.glsl.vert
       essl    PyMaterialXGenGlsl.EsslShaderGenerator     NAME.essl.frag, NAME.essl.vert
       msl     PyMaterialXGenMsl.MslShaderGenerator       NAME.msl.frag.metal, NAME.msl.vert.metal
       osl     PyMaterialXGenOsl.OslShaderGenerator       NAME.osl
       mdl     PyMaterialXGenMdl.MdlShaderGenerator       NAME.mdl

   Every custom node definition of DOC with a `float` output and a target-independent
   implementation (a node graph or implementation without `target`) is also generated on
   every target through a probe material (`float -> convert -> surface_unlit`), named
   `probe_<nodedef>`, so that the exact lobe graphs are exercised on OSL and MDL too.
3. Optionally validates what was generated:
   --glslang      runs `glslangValidator FILE` on the GLSL and ESSL stages (the stage comes from
                  the `.frag`/`.vert` extension, the version from the `#version` line);
   --osl-compile  compiles the OSL with `oslc` if it is on PATH, else with the OSL compiler
                  inside Blender's `bpy` module (`_cycles.osl_compile`) if that imports, with
                  MaterialX's `mx_funcs.h` beside the source.
   A requested tool that is missing prints `skipped TOOL: reason`; with --require-tools
   that is a failure.

Without the MaterialX package it prints `skipped materialx: ...` and exits 3 (with
--require-tools: `failed materialx: ...`, exit 1).

Prints one line per check: `ok validate`, `ok TARGET FILE...`, `ok glslang FILE`,
`ok oslc FILE`, `failed TARGET: ELEMENT: message` (and `failed validate: message`,
`failed glslang FILE: log`...) or `skipped TOOL: reason`. Exits 1 if anything failed,
2 on bad usage.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

try:
    import MaterialX as mx
    import MaterialX.PyMaterialXGenGlsl as mx_gen_glsl
    import MaterialX.PyMaterialXGenMdl as mx_gen_mdl
    import MaterialX.PyMaterialXGenMsl as mx_gen_msl
    import MaterialX.PyMaterialXGenOsl as mx_gen_osl
    import MaterialX.PyMaterialXGenShader as mx_gen_shader
except ImportError as import_error:
    if "--require-tools" in sys.argv:
        print("failed materialx: %s" % import_error)
        sys.exit(1)
    print("skipped materialx: %s (pip install materialx)" % import_error)
    sys.exit(3)

# (target id, generator factory, [(stage, file suffix)])
HW_STAGES = [(mx_gen_shader.PIXEL_STAGE, "frag"), (mx_gen_shader.VERTEX_STAGE, "vert")]
TARGETS = [
    ("glsl", mx_gen_glsl.GlslShaderGenerator.create,
     [(s, ".glsl." + ext) for s, ext in HW_STAGES]),
    ("essl", mx_gen_glsl.EsslShaderGenerator.create,
     [(s, ".essl." + ext) for s, ext in HW_STAGES]),
    ("msl", mx_gen_msl.MslShaderGenerator.create,
     [(s, ".msl." + ext + ".metal") for s, ext in HW_STAGES]),
    ("osl", mx_gen_osl.OslShaderGenerator.create, [(mx_gen_shader.PIXEL_STAGE, ".osl")]),
    ("mdl", mx_gen_mdl.MdlShaderGenerator.create, [(mx_gen_shader.PIXEL_STAGE, ".mdl")]),
]

PROBE_PREFIX = "probe_"


class Checker:
    def __init__(self):
        self.failed = False

    def ok(self, what, *details):
        print(" ".join(["ok", what] + [str(d) for d in details]), flush=True)

    def fail(self, what, message):
        self.failed = True
        text = str(message).strip().replace("\n", "\n    ")
        print("failed %s: %s" % (what, text), flush=True)

    def skip(self, what, reason, required):
        if required:
            self.fail(what, reason)
        else:
            print("skipped %s: %s" % (what, reason), flush=True)


def one_line(text):
    return " ".join(str(text).split())


def library_root():
    """The folder holding `libraries/` in the installed MaterialX package."""
    return os.path.dirname(os.path.abspath(mx.__file__))


def add_probes(doc, library_names):
    """A probe material for every custom float node definition with a generic implementation."""
    probes = []
    for nodedef in doc.getNodeDefs():
        if nodedef.getName() in library_names:
            continue
        outputs = nodedef.getActiveOutputs()
        if len(outputs) != 1 or outputs[0].getType() != "float":
            continue
        generic = [
            impl for impl in doc.getMatchingImplementations(nodedef.getName())
            if not impl.getTarget()
        ]
        if not generic:
            continue
        base = mx.createValidName(PROBE_PREFIX + nodedef.getName())
        node = doc.addNodeInstance(nodedef, base + "_node")
        convert = doc.addNode("convert", base + "_color", "color3")
        convert.setConnectedNode("in", node)
        unlit = doc.addNode("surface_unlit", base + "_shader", "surfaceshader")
        unlit.setConnectedNode("emission_color", convert)
        material = doc.addMaterialNode(base, unlit)
        probes.append(material.getName())
    return probes


def generate(checker, doc, elements, search_path, out_dir):
    """Generates every element on every target; returns {target: [files]}."""
    written = {target: [] for target, _, _ in TARGETS}
    for target, create, stages in TARGETS:
        shadergen = create()
        context = mx_gen_shader.GenContext(shadergen)
        context.registerSourceCodeSearchPath(search_path)
        shadergen.registerTypeDefs(doc)
        cms = mx_gen_shader.DefaultColorManagementSystem.create(shadergen.getTarget())
        cms.loadLibrary(doc)
        shadergen.setColorManagementSystem(cms)
        units = mx_gen_shader.UnitSystem.create(shadergen.getTarget())
        registry = mx.UnitConverterRegistry.create()
        for unit_type in ("distance", "angle"):
            typedef = doc.getUnitTypeDef(unit_type)
            if typedef:
                registry.addUnitConverter(typedef, mx.LinearUnitConverter.create(typedef))
        units.loadLibrary(doc)
        units.setUnitConverterRegistry(registry)
        shadergen.setUnitSystem(units)
        context.getOptions().targetDistanceUnit = "meter"

        for element in elements:
            name = mx.createValidName(element.getName())
            label = "%s: %s" % (target, name)
            try:
                shader = shadergen.generate(name, element, context)
            except Exception as err:  # MaterialX raises ExceptionShaderGenError and others
                checker.fail(label, one_line(err))
                continue
            if shader is None:
                checker.fail(label, "the generator returned no shader")
                continue
            files = []
            for stage, suffix in stages:
                source = shader.getSourceCode(stage) if shader.hasStage(stage) else ""
                if not source.strip():
                    checker.fail(label, "empty %s stage" % stage)
                    files = None
                    break
                path = os.path.join(out_dir, name + suffix)
                with open(path, "w", encoding="utf-8") as handle:
                    handle.write(source)
                files.append(path)
            if files is not None:
                written[target].extend(files)
                checker.ok(target, *files)
    return written


def check_glslang(checker, files, required):
    tool = shutil.which("glslangValidator")
    if tool is None:
        checker.skip("glslang", "glslangValidator not found (Debian: glslang-tools)", required)
        return
    for path in files:
        run = subprocess.run([tool, path], capture_output=True, text=True)
        if run.returncode == 0:
            checker.ok("glslang", path)
        else:
            checker.fail("glslang " + path, (run.stdout + run.stderr).strip())


# One child interpreter compiles every file: importing `bpy` takes about a second, which
# three imports a document (a probe and one per file) spent three times.
BPY_COMPILE = """
import json, sys
try:
    import bpy, _cycles
except ImportError as error:
    print(json.dumps({"missing": str(error)}))
    sys.exit(0)
if not _cycles.with_osl:
    print(json.dumps({"missing": "this bpy is built without OSL"}))
    sys.exit(0)
print(json.dumps({"compiled": [bool(_cycles.osl_compile(s, d)) for s, d in json.loads(sys.argv[1])]}))
"""


def bpy_osl_compile(pairs):
    """Compiles each (src, dst) with Blender's OSL compiler in one child interpreter: a list
    of (ok, log), or the reason it cannot (no bpy, or one without OSL)."""
    run = subprocess.run([sys.executable, "-c", BPY_COMPILE, json.dumps(pairs)],
                         capture_output=True, text=True, timeout=300)
    log = (run.stdout + run.stderr).strip()
    lines = run.stdout.strip().splitlines()
    try:
        answer = json.loads(lines[-1])
    except (IndexError, ValueError):
        return [(False, log or "Blender's OSL compiler stopped")] * len(pairs)
    if "missing" in answer:
        return answer["missing"]
    return [(ok and os.path.isfile(dst), "" if ok else log)
            for ok, (_, dst) in zip(answer["compiled"], pairs)]


def check_osl(checker, files, required):
    include = os.path.join(library_root(), "libraries", "stdlib", "genosl", "include")
    oslc = shutil.which("oslc")
    with tempfile.TemporaryDirectory() as work:
        jobs = []
        for k, path in enumerate(files):
            # The generated source includes "mx_funcs.h"; Blender's compiler only searches
            # its own shader folder and the source's folder, so the header goes beside it.
            folder = os.path.join(work, str(k))
            os.mkdir(folder)
            shutil.copy(os.path.join(include, "mx_funcs.h"), folder)
            src = os.path.join(folder, os.path.basename(path))
            shutil.copy(path, src)
            jobs.append((path, src, os.path.splitext(path)[0] + ".oso"))
        if oslc:
            kind, results = "oslc", []
            for _, src, dst in jobs:
                run = subprocess.run([oslc, "-q", "-I" + include, "-o", dst, src],
                                     capture_output=True, text=True)
                results.append((run.returncode == 0, (run.stdout + run.stderr).strip()))
        else:
            kind, results = "bpy", bpy_osl_compile([(src, dst) for _, src, dst in jobs])
            if isinstance(results, str):
                checker.skip("oslc", "no oslc, and Blender's bpy cannot compile OSL: " + results,
                             required)
                return
    for (path, _, _), (ok, log) in zip(jobs, results):
        if ok:
            checker.ok("oslc", path, "(%s)" % kind)
        else:
            checker.fail("oslc " + path, log or "compilation failed")


def main():
    parser = argparse.ArgumentParser(
        description="Validate a MaterialX document and generate GLSL, ESSL, MSL, OSL and MDL "
                    "from it with MaterialX's generators.")
    parser.add_argument("document", help="the .mtlx file")
    parser.add_argument("--out", default=None,
                        help="folder for the generated stages (default: a temporary folder)")
    parser.add_argument("--glslang", action="store_true",
                        help="validate the GLSL and ESSL stages with glslangValidator")
    parser.add_argument("--osl-compile", action="store_true",
                        help="compile the OSL with oslc or Blender's bpy")
    parser.add_argument("--require-tools", action="store_true",
                        help="a requested validator that is missing is a failure")
    parser.add_argument("--no-probes", action="store_true",
                        help="generate only the document's own renderable elements")
    opts = parser.parse_args()

    if not os.path.isfile(opts.document):
        print("failed read: no such file: %s" % opts.document)
        return 1
    out_dir = opts.out or tempfile.mkdtemp(prefix="materialx_check_")
    os.makedirs(out_dir, exist_ok=True)
    checker = Checker()

    search_path = mx.getDefaultDataSearchPath()
    library = mx.createDocument()
    try:
        mx.loadLibraries(mx.getDefaultDataLibraryFolders(), search_path, library)
    except Exception as err:
        checker.fail("libraries", one_line(err))
        return 1
    library_names = {nd.getName() for nd in library.getNodeDefs()}

    doc = mx.createDocument()
    try:
        mx.readFromXmlFile(doc, opts.document)
    except Exception as err:
        checker.fail("read", one_line(err))
        return 1
    doc.importLibrary(library)
    valid, message = doc.validate()
    if valid:
        checker.ok("validate")
    else:
        checker.fail("validate", message)

    elements = list(mx_gen_shader.findRenderableElements(doc))
    if not elements:
        checker.fail("renderable", "the document has no renderable element")
    if not opts.no_probes:
        for name in add_probes(doc, library_names):
            elements.append(doc.getChild(name))

    # Source files named by implementations resolve against the document's folder and the
    # MaterialX package root (where `libraries/` is).
    code_path = mx.FileSearchPath(search_path.asString())
    code_path.append(mx.FilePath(os.path.dirname(os.path.abspath(opts.document))))
    written = generate(checker, doc, elements, code_path, out_dir)

    if opts.glslang:
        check_glslang(checker, written["glsl"] + written["essl"], opts.require_tools)
    if opts.osl_compile:
        check_osl(checker, written["osl"], opts.require_tools)

    return 1 if checker.failed else 0


if __name__ == "__main__":
    sys.exit(main())
