"""photonbound against Mitsuba 3 on one scene: relative error against seconds (issue 39).

  python3 -m tools.mitsuba_side_by_side OUTDIR [--scene scenes/caustic.gltf] [--resolution WxH]
        [--integrators ptracer,path] [--spp 4,16,64,256,1024] [--passes 16,64,256,1024,4096]
        [--adaptive none,radius] [--runs 3] [--reference-spp 65536] [--target 0.01]
        [--photonbound EXE]

The peer comes from the registries when the script runs, never in CI: Mitsuba 3.5.2 from PyPI
into a venv of its own (~/.cache/photonbound/mitsuba-3.5.2), and Debian's libllvm19, which its
LLVM backend loads (installed with apt-get when missing and the script runs as root; otherwise
it says what to install). tools/mitsuba_peer.py runs inside that venv.

The glTF file is translated for Mitsuba (PLY meshes with the file's normals, Lambertian,
dielectric and one-sided area emitters, point and directional lights, the camera; anything
else is refused by name) and both render it with a box pixel filter at the same resolution.
The reference is Mitsuba's light tracer (`ptracer`) at --reference-spp, independent seeds:
unbiased wherever a light tracer sees, which is every pixel whose 4 x 4 camera rays all first
meet a non-delta surface (the mask; a light tracer cannot connect a delta surface to the
camera, so a glass ball seen directly is black in its image). Errors are over the mask: the
mean over pixels and channels of |image - reference| over the reference's mean ("relative
error"). The reference's own error is estimated from its two halves and printed.

Seconds are each renderer's own render time on this machine: photonbound's
photonbound:seconds (its pass loop, without loading), Mitsuba's timed renders (without loading
the scene and without the warm-up render that compiles its kernels). Each row is the median of
--runs seeds. The table gives, per renderer, the slope of log error against log seconds over
its rows and the seconds it needs for --target by log-log interpolation (blank when its rows
do not reach it). OUTDIR gets table.md, results.json and runs/.
"""

import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import time

from . import cli, exr, gltf_scene
from .common import REPO, ToolError, parse_resolution, run_main, write_text

MITSUBA = "3.5.2"


def peer_python():
    """The venv's Python with Mitsuba, made on first use; libllvm19 installed when missing."""
    if not any(os.path.exists(os.path.join(d, "libLLVM-19.so.1"))
               for d in ("/usr/lib/x86_64-linux-gnu", "/usr/lib/llvm-19/lib")):
        if os.geteuid() != 0:
            raise ToolError("Mitsuba's LLVM backend needs Debian's libllvm19: "
                            "sudo apt-get install libllvm19")
        subprocess.run(["apt-get", "install", "-y", "-q", "libllvm19"], check=True,
                       stdout=subprocess.DEVNULL)
    cache = os.path.join(os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")),
                         "photonbound", f"mitsuba-{MITSUBA}")
    python = os.path.join(cache, "bin", "python")
    if subprocess.run([python, "-c", "import mitsuba, numpy"], capture_output=True).returncode \
            if os.path.exists(python) else True:
        print(f"mitsuba_side_by_side: installing Mitsuba {MITSUBA} into {cache}", flush=True)
        subprocess.run([sys.executable, "-m", "venv", "--clear", cache], check=True)
        p = subprocess.run([python, "-m", "pip", "install", "-q", f"mitsuba=={MITSUBA}", "numpy"],
                           capture_output=True, text=True, errors="replace")
        if p.returncode != 0:
            raise ToolError(f"pip install mitsuba=={MITSUBA} failed: {p.stderr.strip()[-300:]}")
    return python


def write_ply(path, positions, normals, indices):
    with open(path, "wb") as f:
        head = ["ply", "format binary_little_endian 1.0", f"element vertex {len(positions)}",
                "property float x", "property float y", "property float z"]
        if normals:
            head += ["property float nx", "property float ny", "property float nz"]
        head += [f"element face {len(indices) // 3}",
                 "property list uchar int vertex_indices", "end_header"]
        f.write(("\n".join(head) + "\n").encode("ascii"))
        for k, p in enumerate(positions):
            f.write(struct.pack("<3f", *p))
            if normals:
                f.write(struct.pack("<3f", *normals[k]))
        for t in range(0, len(indices), 3):
            f.write(struct.pack("<B3i", 3, *indices[t:t + 3]))


def translate(gltf_path, folder, width, height):
    """scene.json and PLY files for tools.mitsuba_peer; ToolError for what has no translation."""
    scene = gltf_scene.load(gltf_path)
    if not scene.cameras or scene.cameras[0].yfov is None:
        raise ToolError(f"{gltf_path}: needs a perspective camera (the first is used)")
    cam = scene.cameras[0]
    desc = {"width": width, "height": height, "meshes": [], "lights": [],
            "camera": {"position": cam.position, "forward": cam.forward, "up": cam.up,
                       "yfov": cam.yfov}}
    for m in scene.meshes:
        for p in m.primitives:
            mat = p.material
            name = mat.name if mat else "default"
            if mat is None:
                kind = {"kind": "diffuse", "reflectance": [1.0, 1.0, 1.0]}
            elif mat.model == "lambertian":
                kind = {"kind": "diffuse", "reflectance": list(mat.base_color)}
            elif mat.model == "dielectric":
                kind = {"kind": "dielectric", "ior": mat.ior}
            else:
                raise ToolError(f"{gltf_path}: material {name} is {mat.model}; only Lambertian "
                                "and dielectric materials are translated")
            if mat is not None and any(k in mat.json.get("pbrMetallicRoughness", {})
                                       for k in ("baseColorTexture",)) or \
                    (mat is not None and "emissiveTexture" in mat.json):
                raise ToolError(f"{gltf_path}: material {name} has a texture; not translated")
            if mat is not None and mat.json.get("doubleSided") and max(mat.emission) > 0.0:
                raise ToolError(f"{gltf_path}: material {name} is a double-sided emitter")
            kind["emission"] = list(mat.emission) if mat else [0.0, 0.0, 0.0]
            ply = os.path.join(folder, f"mesh_{len(desc['meshes'])}.ply")
            write_ply(ply, p.positions, p.normals, p.indices)
            desc["meshes"].append({"ply": ply, "material": kind, "smooth": p.normals is not None})
    for light in scene.lights:
        if light.type == "point":
            desc["lights"].append({"type": "point", "position": light.position,
                                   "intensity": list(light.intensity)})
        elif light.type == "directional":
            desc["lights"].append({"type": "directional", "direction": light.direction,
                                   "intensity": list(light.intensity)})
        else:
            raise ToolError(f"{gltf_path}: light {light.name} is a {light.type}; not translated")
    path = os.path.join(folder, "scene.json")
    write_text(path, json.dumps(desc, indent=1) + "\n")
    return path


def peer(python, *args):
    p = subprocess.run([python, "-m", "tools.mitsuba_peer", *args], cwd=REPO,
                       capture_output=True, text=True, errors="replace")
    if p.returncode != 0:
        raise ToolError(f"mitsuba_peer {' '.join(args[:3])} failed: {p.stderr.strip()[-400:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def read_rgb(path):
    import numpy as np
    img = exr.read_exr(path)
    return np.stack([img.planes[c] for c in ("R", "G", "B")], axis=-1).astype(np.float64)


def relative_error(image, reference, mask):
    import numpy as np
    diff = np.abs(image - reference)[mask]
    return float(diff.mean() / reference[mask].mean())


def fit(rows):
    """Slope of log error on log seconds, and seconds at `target` by log-log interpolation."""
    pts = [(math.log(r["seconds"]), math.log(r["error"])) for r in rows
           if r["seconds"] > 0 and r["error"] > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    sxx = sum((x - mx) ** 2 for x, _ in pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sxx if sxx > 0 else float("nan")


def seconds_at(rows, target):
    rows = sorted(rows, key=lambda r: r["seconds"])
    for a, b in zip(rows, rows[1:]):
        if a["error"] >= target >= b["error"] and a["error"] > b["error"]:
            t = (math.log(target) - math.log(a["error"])) / (math.log(b["error"]) -
                                                             math.log(a["error"]))
            return math.exp(math.log(a["seconds"]) + t * (math.log(b["seconds"]) -
                                                          math.log(a["seconds"])))
    return float("nan")


def median(values):
    v = sorted(values)
    return v[len(v) // 2] if len(v) % 2 else 0.5 * (v[len(v) // 2 - 1] + v[len(v) // 2])


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.mitsuba_side_by_side",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--scene", default=os.path.join(REPO, "scenes", "caustic.gltf"))
    ap.add_argument("--resolution", default="128x96")
    ap.add_argument("--integrators", default="ptracer,path")
    ap.add_argument("--spp", default="4,16,64,256,1024")
    ap.add_argument("--passes", default="16,64,256,1024,4096")
    ap.add_argument("--adaptive", default="none,radius")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--reference-spp", type=int, default=65536)
    ap.add_argument("--target", type=float, default=0.01)
    ap.add_argument("--photonbound", default=cli.default_photonbound())
    args = ap.parse_args()
    exe = cli.check_photonbound(args.photonbound)
    width, height = parse_resolution(args.resolution)
    try:
        spps = [int(v) for v in args.spp.split(",") if v.strip()]
        passes = [int(v) for v in args.passes.split(",") if v.strip()]
    except ValueError:
        raise ToolError("--spp and --passes are comma lists of whole numbers")
    if args.runs < 1 or args.reference_spp < 2 or not (args.target > 0):
        raise ToolError("--runs at least 1, --reference-spp at least 2, --target above 0")
    runs = os.path.join(args.outdir, "runs")
    os.makedirs(runs, exist_ok=True)
    start = time.monotonic()
    python = peer_python()
    desc = translate(args.scene, runs, width, height)
    import numpy as np

    mask_path = os.path.join(runs, "mask.exr")
    peer(python, "mask", desc, mask_path)
    mask = read_rgb(mask_path)[..., 0] > 0.5
    halves = []
    for h in range(2):
        path = os.path.join(runs, f"reference_{h}.exr")
        if not os.path.isfile(path):
            peer(python, "render", desc, path, "--integrator", "ptracer", "--spp",
                 str(args.reference_spp // 2), "--seed", str(10**5 * (h + 1)))
        halves.append(read_rgb(path))
    reference = 0.5 * (halves[0] + halves[1])
    # The halves differ by twice the reference's noise in variance: its own error is about
    # half their mean absolute difference (for normal noise, E|a - b| / 2 = E|a - ref| / sqrt 2
    # ... to within the shape of the noise).
    ref_error = relative_error(halves[0], halves[1], mask) / 2.0
    print(f"mitsuba_side_by_side: reference {args.reference_spp} spp, its own relative error "
          f"about {ref_error:.4f}; mask {int(mask.sum())} of {mask.size} pixels", flush=True)

    rows = []
    integrators = [v for v in args.integrators.split(",") if v.strip()]
    for integ in integrators:
        for spp in spps:
            errs, secs = [], []
            for run in range(args.runs):
                path = os.path.join(runs, f"mitsuba_{integ}_{spp}_{run}.exr")
                r = peer(python, "render", desc, path, "--integrator", integ, "--spp", str(spp),
                         "--seed", str(1000 * (run + 1)))
                errs.append(relative_error(read_rgb(path), reference, mask))
                secs.append(r["seconds"])
            rows.append({"renderer": f"mitsuba {integ}", "work": f"{spp} spp",
                         "seconds": median(secs), "error": median(errs)})
            print(f"mitsuba_side_by_side: {rows[-1]}", flush=True)
    for mode in [v for v in args.adaptive.split(",") if v.strip()]:
        for p in passes:
            errs, secs = [], []
            for run in range(args.runs):
                path = os.path.join(runs, f"photonbound_{mode.replace('+', '_')}_{p}_{run}.exr")
                cli.render(exe, args.scene, path,
                           ["--resolution", args.resolution, "--passes", str(p), "--seed",
                            str(run + 1), "--adaptive", mode.replace("+", ","), "--quiet"])
                img = exr.read_exr(path)
                errs.append(relative_error(read_rgb(path), reference, mask))
                secs.append(float(img.metadata["photonbound:seconds"]))
            rows.append({"renderer": f"photonbound {mode}", "work": f"{p} passes",
                         "seconds": median(secs), "error": median(errs)})
            print(f"mitsuba_side_by_side: {rows[-1]}", flush=True)

    doc = ["# photonbound against Mitsuba 3", "",
           f"`python3 -m tools.mitsuba_side_by_side {' '.join(sys.argv[1:])}`; "
           f"{cli.version(exe)}; Mitsuba {MITSUBA} (llvm_ad_rgb). Reference: ptracer at "
           f"{args.reference_spp} spp, its own relative error about {ref_error:.4f}; "
           f"{int(mask.sum())} of {mask.size} pixels in the mask.", "",
           "| renderer | work | seconds (median) | relative error (median) |", "|---|---|---|---|"]
    for r in rows:
        doc.append(f"| {r['renderer']} | {r['work']} | {r['seconds']:.3f} | {r['error']:.5f} |")
    doc += ["", f"| renderer | slope of log error on log seconds | seconds to {args.target:g} |",
            "|---|---|---|"]
    summary = {}
    for name in dict.fromkeys(r["renderer"] for r in rows):
        mine = [r for r in rows if r["renderer"] == name]
        summary[name] = {"slope": fit(mine), "seconds_at_target": seconds_at(mine, args.target)}
        s = summary[name]
        doc.append(f"| {name} | {s['slope']:.3f} | " +
                   (f"{s['seconds_at_target']:.2f}" if s["seconds_at_target"] ==
                    s["seconds_at_target"] else "") + " |")
    write_text(os.path.join(args.outdir, "table.md"), "\n".join(doc) + "\n")
    write_text(os.path.join(args.outdir, "results.json"),
               json.dumps({"rows": rows, "summary": summary, "reference_error": ref_error,
                           "mask_pixels": int(mask.sum())}, indent=1) + "\n")
    print(f"mitsuba_side_by_side: wrote {args.outdir}/table.md in "
          f"{time.monotonic() - start:.0f} s")


if __name__ == "__main__":
    run_main("mitsuba_side_by_side", main)
