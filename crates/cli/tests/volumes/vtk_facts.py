#!/usr/bin/env python3
"""Probe the behaviours of VTK's CPU ray caster that VTK_NOTES.md describes, on the installed
vtk wheel, through crates/report/src/vtk_volume.py and small synthetic NIfTI volumes (identity affine, 1 mm).

    python vtk_facts.py [--keep DIR]

Prints one line per fact, `ok FACT: measured` or `differs FACT: measured`, and exits 1 if any
fact differs (a new VTK may change them: then VTK_NOTES.md and specula's "alike" set-up need
another look). Without the vtk package: `skipped vtk: ...`, exit 3.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--keep", metavar="DIR")
    args = parser.parse_args()
    try:
        import nibabel as nib
        import numpy as np
        import vtk  # noqa: F401
        from vtk.util import numpy_support
    except ImportError as e:
        print(f"skipped vtk: {e}")
        sys.exit(3)

    folder = args.keep or tempfile.mkdtemp(prefix="vtk_facts-")
    os.makedirs(folder, exist_ok=True)
    results = []

    def save(name, values):
        path = os.path.join(folder, name + ".nii.gz")
        nib.save(nib.Nifti1Image(values.astype(np.int16), np.eye(4)), path)
        return path

    def run(job):
        job.setdefault("output", os.path.join(folder, "probe.png"))
        path = os.path.join(folder, "job.json")
        with open(path, "w") as f:
            json.dump(job, f)
        done = subprocess.run([sys.executable, os.path.join(HERE, "..", "..", "..", "report", "src", "vtk_volume.py"), path], capture_output=True, text=True)
        if done.returncode != 0:
            raise SystemExit(f"vtk_facts.py: vtk_volume.py failed: {done.stderr.strip()}")
        reader = vtk.vtkPNGReader()
        reader.SetFileName(job["output"])
        reader.Update()
        image = reader.GetOutput()
        w, h, _ = image.GetDimensions()
        pixels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[::-1]
        return pixels.astype(float) / 255.0, json.loads(done.stdout)

    def fact(name, good, measured):
        results.append(good)
        print(f"{'ok' if good else 'differs'} {name}: {measured}")

    def looking_down(volume, size, half, **extra):
        job = {
            "volume": volume,
            "width": size[0],
            "height": size[1],
            "camera": {"position": [10, 10, 500], "focal_point": [10, 10, 9.5], "view_up": [0, 1, 0], "parallel_scale": half},
            "sample_distance": 0.5,
            "transfer": [[0, 0, 1, 1, 1], [49, 0, 1, 1, 1], [51, 50, 1, 1, 1]],
            "shading": None,
            "interpolation": "linear",
            "threads": 1,
            "warmup": 1,
            "frames": 1,
        }
        job.update(extra)
        return run(job)

    try:
        # 1. Nearest neighbour takes floor(position), not the nearest voxel.
        slab = np.zeros((20, 20, 20))
        slab[8:12] = 100
        path = save("slab", slab)
        edges = {}
        for interpolation in ("nearest", "linear"):
            pixels, _ = looking_down(path, (200, 20), 1.0, interpolation=interpolation, sample_distance=0.1)
            on = np.flatnonzero(pixels[10, :, 0] > 0.5)
            edges[interpolation] = (round(on.min() * 0.1, 2), round((on.max() + 1) * 0.1, 2))
        fact(
            "nearest-is-floor",
            edges["nearest"] == (8.0, 12.0) and edges["linear"] == (7.5, 11.5),
            f"voxels 8..11 cover x in {edges['nearest']} mm with nearest, {edges['linear']} with linear (threshold at the midpoint)",
        )

        # 2. Opacity correction: 1 - (1 - alpha)^(d / unit) with alpha = 1 - exp(-sigma) gives
        #    Beer-Lambert through a constant block, whatever the sample distance.
        block = np.full((20, 20, 20), 100)
        block[0, 0, 0] = 0  # a range for the tables
        path = save("block", block)
        worst = 0.0
        for sigma, d in ((0.05, 0.5), (0.05, 1.0), (0.02, 0.3)):
            pixels, _ = looking_down(path, (20, 20), 5.0, sample_distance=d, transfer=[[0, 0, 1, 1, 1], [50, sigma, 1, 1, 1]])
            worst = max(worst, abs(pixels[10, 10, 0] - (1 - math.exp(-sigma * 19.0))))
        fact("opacity-correction", worst <= 2.5 / 255, f"largest difference from 1 - exp(-sigma 19 mm): {worst:.4f} (8-bit PNG)")

        # 3. Zero gradients give zero normals, shaded with the ambient term only (black with the
        #    default headlight): a constant block lit by diffuse light alone is black.
        pixels, _ = looking_down(
            path, (20, 20), 5.0, transfer=[[0, 0, 1, 1, 1], [50, 0.05, 1, 1, 1]], shading={"ambient": 0, "diffuse": 1, "specular": 0, "power": 1}
        )
        fact("zero-normal-black", pixels[10, 10, 0] == 0.0, f"constant block, diffuse only: {pixels[10, 10, 0]:.4f}")

        # 4. The automatic headlight's ambient colour is black: the ambient coefficient does
        #    nothing unless the light's ambient colour is set.
        cube = np.zeros((20, 20, 20))
        cube[5:15, 5:15, 5:15] = 100
        path = save("cube", cube)
        ambient_only = {"ambient": 1, "diffuse": 0, "specular": 0, "power": 1}
        dark, info = looking_down(path, (20, 20), 10.0, shading=ambient_only)
        lit, _ = looking_down(path, (20, 20), 10.0, shading=ambient_only, headlight_ambient_color=[1, 1, 1])
        fact(
            "ambient-needs-light-ambient-colour",
            dark[10, 10, 0] == 0.0 and lit[10, 10, 0] > 0.99 and info["light"]["ambient_color"] == [0.0, 0.0, 0.0],
            f"ambient 1 alone: {dark[10, 10, 0]:.3f} with the default headlight (ambient colour {info['light']['ambient_color']}), "
            f"{lit[10, 10, 0]:.3f} with ambient colour white",
        )
        fact(
            "headlight-two-sided",
            info["light"]["headlight"] and info["two_sided_lighting"],
            f"automatic light is a headlight at the camera: {info['light']['headlight']}; renderer two-sided lighting: {info['two_sided_lighting']}",
        )

        # 5. Specular is added as (specular table x alpha), not multiplied by the sample colour:
        #    a black, opaque cube seen face-on with specular 1 alone is white.
        pixels, _ = looking_down(
            path,
            (20, 20),
            10.0,
            transfer=[[0, 0, 0, 0, 0], [49, 0, 0, 0, 0], [51, 50, 0, 0, 0]],
            shading={"ambient": 0, "diffuse": 0, "specular": 1, "power": 1},
        )
        fact("specular-not-times-colour", pixels[10, 10, 0] > 0.99, f"black cube, specular 1 face-on: {pixels[10, 10, 0]:.3f}")

        # 6. With 2 threads the gradients of the slice just below each thread's share of slices
        #    take a one-sided z difference (vtkFixedPointVolumeRayCastMapperComputeCS1CGradients
        #    tests z < z_limit - 1 with the thread's z_limit): a shading seam at z = 31 of 64.
        n = 64
        g = np.mgrid[0:n, 0:n, 0:n].astype(float)
        r = np.sqrt((g[0] - 31.5) ** 2 + (g[1] - 31.5) ** 2 + (g[2] - 44.0) ** 2)
        path = save("sphere", 1000 * np.clip((25 - r) / 3 + 0.5, 0, 1))
        images = {}
        for threads in (1, 2):
            images[threads], _ = looking_down(
                path,
                (256, 256),
                32.0,
                threads=threads,
                camera={"position": [500, 31.5, 31.5], "focal_point": [31.5, 31.5, 31.5], "view_up": [0, 0, 1], "parallel_scale": 32.0},
                transfer=[[0, 0, 1, 1, 1], [400, 0, 1, 1, 1], [600, 5, 1, 1, 1]],
                shading={"ambient": 0, "diffuse": 1, "specular": 0, "power": 1},
            )
        diff = np.abs(images[1][:, :, 0] - images[2][:, :, 0])
        rows = np.flatnonzero(diff.max(axis=1) > 0.02)
        zs = [round(31.5 + 32 * (1 - 2 * (row + 0.5) / 256), 1) for row in rows]
        fact(
            "thread-seam-in-gradients",
            len(rows) > 0 and all(29.5 <= z <= 32.5 for z in zs),
            f"1 vs 2 threads differ by up to {diff.max():.3f}, only at world z {zs[:1]}..{zs[-1:]} (slice 31)",
        )

        # 7. Samples lie at distances near + k d from the camera plane: moving the near
        #    clipping plane by a fraction of d changes how many samples fall in a thin slab.
        thin = np.zeros((20, 20, 20))
        thin[:, :, 10] = 100
        path = save("thin", thin)
        counts = set()
        for near in (400.05, 400.15, 400.25, 400.35):
            pixels, _ = looking_down(
                path,
                (4, 4),
                1.0,
                interpolation="nearest",
                sample_distance=0.4,
                clipping_range=[near, 600.0],
                transfer=[[0, 0, 1, 1, 1], [49, 0, 1, 1, 1], [51, 0.1, 1, 1, 1]],
            )
            counts.add(round(math.log(1 - pixels[2, 2, 0]) / math.log(math.exp(-0.04))))
        fact("samples-anchored-at-near-plane", counts == {2, 3}, f"samples in a 1 mm slab as the near plane moves by 0.1 mm (d 0.4 mm): {sorted(counts)}")
    finally:
        if args.keep is None:
            shutil.rmtree(folder, ignore_errors=True)
    sys.exit(0 if all(results) else 1)


if __name__ == "__main__":
    main()
