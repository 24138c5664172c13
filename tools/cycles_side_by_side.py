"""A photonbound render beside Blender's Cycles, from the same file, view, lights and sky.

  python3 -m tools.cycles_side_by_side RENDER.exr [--out DIR] [--samples 1024] [--principled]
                                       [--blender EXE]

For users who want to check a glTF file against Cycles (issue 37). RENDER.exr is a photonbound
render: its metadata names the scene, the view (photonbound:view_from, view_at, view_up,
view_fov), the resolution and the sky. Blender (Debian 12: 3.4; installed with apt-get when
missing and the script runs as root, never in CI) imports the same file with its glTF importer,
lights in the importer's compatibility units (a point light's glTF intensity as W/sr, which is
how photonbound reads it), and Cycles renders it from that view (tools/cycles_peer.py: box
pixel filter, no clamping, no denoising, caustics on, 64 bounces). Blender 3.4's importer
reads neither KHR_materials_specular nor glTF's "Lambertian" (metallic 0, specular 0): the
materials photonbound reads as Lambertian get Cycles' Diffuse BSDF instead of the Principled
BSDF (whose Disney diffuse and default specular layer make a white room 25-30% brighter), the
others Principled's Specular from the file's specular factor; --principled keeps the import as
Blender makes it. A one-sided emitter (glTF's default) emits from its front only, as in
photonbound; Cycles' meshes emit from both sides (a lamp under a ceiling lights it from its
back). The sky is photonbound's:
uniform radiance 1 times --environment-scale when the scene has no light, none otherwise
(environment maps are not translated).

It prints the ratio photonbound / Cycles per channel of the mean over the pixels a surface
covers at least half of (Cycles' alpha, with the sky put back where it is below 1), and
writes to DIR (default: beside RENDER.exr, RENDER_cycles/):
cycles.exr, side_by_side.png (photonbound left, Cycles right, one exposure), difference.png
(photonbound minus Cycles: red where photonbound is brighter, blue where darker, full colour at
the largest difference's 99th percentile) and ratios.json.

What to expect: Cycles' Principled BSDF is not glTF's metallic-roughness BRDF (its specular
layer, multiple scattering in rough metals, its sheen and clearcoat), so glossy and metallic
surfaces differ by a few percent to tens of percent by design; Lambertian walls lit by the same
lights agree to within the noise of both (docs/gltf.md "Beside Cycles").
"""

import argparse
import json
import os
import shutil
import subprocess

from . import exr, gltf_scene
from .common import REPO, ToolError, run_main, save_png, write_text


def view_of(meta, render):
    """The view, resolution and sky of a photonbound render from its metadata."""
    def triple(key):
        try:
            v = [float(x) for x in meta[key].split(",")]
        except (KeyError, ValueError):
            raise ToolError(f"{render}: no {key} in its metadata (not a photonbound render, or "
                            "one older than the view entries)")
        if len(v) != 3:
            raise ToolError(f"{render}: {key} is not three numbers")
        return v
    try:
        width, height = (int(x) for x in meta["photonbound:resolution"].split("x"))
        fov = float(meta["photonbound:view_fov"])
        scale = float(meta.get("photonbound:environment_scale", "1"))
    except (KeyError, ValueError):
        raise ToolError(f"{render}: no resolution or view_fov in its metadata")
    environment = meta.get("photonbound:environment", "")
    if not environment.startswith("none"):
        raise ToolError(f"{render}: rendered with --environment {environment}; environment maps "
                        "are not translated for Cycles")
    return {"from": triple("photonbound:view_from"), "at": triple("photonbound:view_at"),
            "up": triple("photonbound:view_up"), "fov": fov, "width": width, "height": height,
            "sky_scale": scale}


def has_light(scene):
    """photonbound's default sky is on when the scene has neither a light nor an emitter."""
    return bool(scene.lights) or any(
        p.material is not None and max(p.material.emission) > 0.0
        for m in scene.meshes for p in m.primitives)


def ratios(ours, cycles, alpha):
    """Per channel: the mean of ours over the mean of Cycles' over the pixels a surface covers
    at least half of (Cycles' alpha); `cycles` has the sky composited back where alpha < 1."""
    import numpy as np
    covered = alpha >= 0.5
    if not covered.any():
        raise ToolError("Cycles' image has no pixel a surface covers")
    out = {}
    for k, c in enumerate("RGB"):
        den = float(cycles[..., k][covered].mean())
        out[c] = float(ours[..., k][covered].mean()) / den if den > 0 else float("nan")
    out["pixels"] = int(covered.sum())
    out["mean_abs_difference"] = float(np.abs(ours - cycles)[covered].mean())
    return out


def blender_exe(name):
    exe = shutil.which(name)
    if exe:
        return exe
    if name == "blender" and os.geteuid() == 0:
        print("cycles_side_by_side: installing Blender (apt-get install blender)", flush=True)
        subprocess.run(["apt-get", "install", "-y", "-q", "blender"], check=True,
                       stdout=subprocess.DEVNULL)
        exe = shutil.which(name)
    if not exe:
        raise ToolError(f"{name}: Blender not found (Debian: sudo apt-get install blender)")
    return exe


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.cycles_side_by_side",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("render")
    ap.add_argument("--out")
    ap.add_argument("--samples", type=int, default=1024)
    ap.add_argument("--principled", action="store_true",
                    help="keep Blender's import of the materials as it is")
    ap.add_argument("--blender", default="blender")
    args = ap.parse_args()
    if args.samples < 1:
        raise ToolError("--samples must be at least 1")
    import numpy as np
    ours_exr = exr.read_exr(args.render)
    view = view_of(ours_exr.metadata, args.render)
    scene_path = ours_exr.metadata.get("photonbound:scene", "")
    if not os.path.isfile(scene_path):
        raise ToolError(f"{args.render}: its scene {scene_path} is not found from here (run from "
                        "the folder photonbound was run in)")
    scene = gltf_scene.load(scene_path)
    out = args.out or os.path.splitext(args.render)[0] + "_cycles"
    os.makedirs(out, exist_ok=True)
    cycles_path = os.path.abspath(os.path.join(out, "cycles.exr"))
    job = dict(view, scene=os.path.abspath(scene_path), output=cycles_path,
               samples=args.samples, sky=0.0 if has_light(scene) else view["sky_scale"],
               principled=args.principled,
               lambertian=sorted({m.name for m in scene.materials if m.model == "lambertian"}),
               specular={m.name: m.specular for m in scene.materials},
               one_sided=sorted({m.name for m in scene.materials
                                 if max(m.emission) > 0.0 and not m.json.get("doubleSided")}))
    p = subprocess.run([blender_exe(args.blender), "--background", "--factory-startup",
                        "--python", os.path.join(REPO, "tools", "cycles_peer.py"), "--",
                        json.dumps(job)], capture_output=True, text=True, errors="replace")
    if p.returncode != 0 or not os.path.isfile(cycles_path):
        tail = (p.stderr.strip() or p.stdout.strip())[-400:]
        raise ToolError(f"Blender failed on {scene_path}: {tail}")
    theirs = exr.read_exr(cycles_path)
    cy = np.stack([theirs.planes[c] for c in "RGB"], axis=-1).astype(np.float64)
    alpha = theirs.planes["A"].astype(np.float64)
    ours = np.stack([ours_exr.planes[c] for c in "RGB"], axis=-1).astype(np.float64)
    if ours.shape != cy.shape:
        raise ToolError(f"the images differ in size: {ours.shape} and {cy.shape}")
    # Cycles' transparent film leaves the sky out of its colour (its alpha says how much of a
    # pixel a surface covers: MASK and BLEND materials, edges); put the uniform sky back.
    sky = job["sky"]
    cy_shown = cy + (1.0 - alpha[..., None]) * sky
    r = ratios(ours, cy_shown, alpha)
    scale = max(float(np.percentile(np.concatenate([ours, cy_shown]), 99)), 1e-12)
    save_png(os.path.join(out, "side_by_side.png"),
             np.clip(np.concatenate([ours, cy_shown], axis=1) / scale, 0, 1) ** (1 / 2.2))
    diff = (ours - cy_shown).mean(axis=2) * (alpha >= 0.5)
    top = max(float(np.percentile(np.abs(diff), 99)), 1e-12)
    d = np.clip(diff / top, -1, 1)
    save_png(os.path.join(out, "difference.png"),
             np.stack([np.clip(d, 0, 1), np.zeros_like(d), np.clip(-d, 0, 1)], axis=-1))
    write_text(os.path.join(out, "ratios.json"), json.dumps(r, indent=1) + "\n")
    print(f"photonbound / Cycles over {r['pixels']} covered pixels: R {r['R']:.3f}  "
          f"G {r['G']:.3f}  B {r['B']:.3f}; mean |difference| {r['mean_abs_difference']:.4g}; "
          f"wrote {out}/")


if __name__ == "__main__":
    run_main("cycles_side_by_side", main)
