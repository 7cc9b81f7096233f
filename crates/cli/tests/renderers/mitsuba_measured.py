#!/usr/bin/env python3
"""Evaluates Mitsuba 3's `measured` BSDF at given direction pairs: the reference that
specula's reader of the RGL `.bsdf` files (crates/specula/src/measured) is compared with.

    python mitsuba_measured.py MATERIAL.bsdf PAIRS.json OUT.json

PAIRS.json is a list of `[viewer, light]` pairs, each a local-frame 3-vector (z = normal,
pointing away from the surface, unit length). OUT.json gets, per pair and in order,
`{"eval": [r, g, b], "pdf": p}`: the plugin's `eval(ctx, si, wo=light)` and `pdf(...)` with
`si.wi = viewer`, in the `scalar_rgb` variant. Mitsuba's `wo` is specula's `wi` (the light)
and its `si.wi` specula's `wo` (the viewer); `eval` includes the light's cosine (the table
holds f cos theta_light), so it is specula's `MeasuredBrdf::f_cos`.
"""

import json
import sys

import mitsuba as mi


def main():
    material, pairs_path, out_path = sys.argv[1:4]
    mi.set_variant("scalar_rgb")
    bsdf = mi.load_dict({"type": "measured", "filename": material})
    ctx = mi.BSDFContext()
    si = mi.SurfaceInteraction3f()
    # The shading frame is the identity, so local and world directions coincide.
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    with open(pairs_path) as f:
        pairs = json.load(f)
    results = []
    for viewer, light in pairs:
        si.wi = mi.Vector3f(viewer)
        wo = mi.Vector3f(light)
        value = bsdf.eval(ctx, si, wo)
        results.append(
            {"eval": [float(value[i]) for i in range(3)], "pdf": float(bsdf.pdf(ctx, si, wo))}
        )
    with open(out_path, "w") as f:
        json.dump(results, f)


if __name__ == "__main__":
    main()
