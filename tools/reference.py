#!/usr/bin/python3
"""Reference images to measure photonbound's actual error against.

  tools/reference.py exact plane|box -o REF.exr --resolution WxH [--scene FILE.gltf]
                     [--pixel area|centre] [--sub N]
  tools/reference.py render SCENE.gltf -o REF.exr --resolution WxH (--time S | --passes N |
                     --target-error E) [--seed S] [--photonbound EXE] [-- MORE RENDER OPTIONS]

`exact` writes the analytic answer of scenes/plane_point.gltf ("plane") or scenes/closed_box.gltf
("box"), with the camera, light, reflectance and emission read from the glTF file (.gltf or
.glb, through tools/gltf_scene.py): with `--pixel area` (the default) each pixel's average over
its area, from N x N stratified sub-pixel rays (`--sub`, default 16), what `--method sppm`
estimates; with `--pixel centre` the value at the pixel-centre measurement point `--method ppm`
uses (src/camera.cpp). It has every channel of photonbound's layout
(include/photonbound/channels.def); all but the radiance are 0.

`render` runs a long photonbound render (its own error bound channels included) and prints
its mean bound, so you can check that it is at least 10x below the errors you study. It uses
seed 1000003 unless told otherwise: a reference must not share its random numbers with the
renders it judges (the study uses seed 1). Options after `--` go to `photonbound render`
(e.g. --radius, --photons-per-pass, --alpha, --checkpoint-every).

For a long reference, start from a radius of a fraction of a pixel and keep alpha near 1
(README "Pictures, plots and references"): the render is then noise-dominated and its bound
falls like passes^-0.5, where the default radius and alpha give about passes^-0.25 in the
Cornell box, because the bias at edges shrinks only as fast as the radius.
"""

import argparse
import math
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pbtools  # noqa: E402
from pbtools import ToolError  # noqa: E402

DEFAULT_SCENES = {"plane": "plane_point.gltf", "box": "closed_box.gltf"}
REFERENCE_SEED = 1000003


def _lambertian(gltf, material, what):
    if material is None:
        raise ToolError(f"{gltf.path}: the {what} has no material")
    if material.model != "lambertian":
        raise ToolError(f"{gltf.path}: the {what}'s material is not plain Lambertian")
    return np.array(material.base_color, float)


def exact_plane(gltf, width, height):
    """L = rho/pi I cos(theta) / d^2 on a horizontal plane under point lights (scenes/README)."""
    meshes = gltf.mesh_instances()
    if len(meshes) != 1 or len(meshes[0][2]) != 1:
        raise ToolError(f"{gltf.path}: expected a single one-primitive plane mesh")
    lo, hi, (material,) = meshes[0]
    if hi[1] - lo[1] > 1e-9 * max(1.0, float(np.max(hi - lo))):
        raise ToolError(f"{gltf.path}: the mesh is not a horizontal plane")
    rho = _lambertian(gltf, material, "plane")
    if any(material.emission):
        raise ToolError(f"{gltf.path}: the plane emits light")
    lights = gltf.point_lights()
    if not lights:
        raise ToolError(f"{gltf.path}: has no point light")
    cam = gltf.camera()
    o = cam["position"]
    d = pbtools.camera_rays(cam, width, height)
    y = lo[1]
    if not (o[1] > y and all(lp[1] > y for lp, _ in lights)):
        raise ToolError(f"{gltf.path}: camera and lights must be above the plane")
    t = (y - o[1]) / d[..., 1]  # camera ray hits the plane where the height is y
    p = o + t[..., None] * d
    on_plane = (t > 0) & np.all((p[..., [0, 2]] >= lo[[0, 2]]) & (p[..., [0, 2]] <= hi[[0, 2]]),
                                axis=-1)
    radiance = np.zeros((height, width, 3))
    for lp, intensity in lights:
        v = lp - p
        dist2 = np.sum(v * v, axis=-1)
        cos = v[..., 1] / np.sqrt(dist2)  # the plane's normal is +y (it faces the camera)
        radiance += (rho / math.pi)[None, None, :] * intensity[None, None, :] * (
            cos / dist2)[..., None]
    radiance[~on_plane] = 0.0  # rays that miss see the black background
    return radiance


def exact_box(gltf, width, height):
    """L = Le / (1 - rho) everywhere inside a closed box of emitting Lambertian walls."""
    meshes = gltf.mesh_instances()
    if len(meshes) != 1:
        raise ToolError(f"{gltf.path}: expected a single box mesh")
    lo, hi, materials = meshes[0]
    first = materials[0]
    if any(m is not first for m in materials):
        raise ToolError(f"{gltf.path}: the walls must share one material")
    rho = _lambertian(gltf, first, "box")
    emission = np.array(first.emission, float)
    o = gltf.camera()["position"]
    if not np.all((o > lo) & (o < hi)):
        raise ToolError(f"{gltf.path}: the camera is not inside the box")
    return np.broadcast_to(emission / (1.0 - rho), (height, width, 3)).copy()


def exact_image(kind, gltf, width, height, sub=1):
    """The exact answer per pixel: at the pixel centres (sub = 1), or averaged over sub x sub
    stratified positions in each pixel. The centres of a sub-times finer image are exactly those
    positions ((x + (i + 0.5) / sub) / width), so its blocks average to the pixel-area value."""
    exact = exact_plane if kind == "plane" else exact_box
    fine = exact(gltf, width * sub, height * sub)
    return fine.reshape(height, sub, width, sub, 3).mean(axis=(1, 3))


def write_reference(path, radiance, metadata):
    """The full channel layout of channels.def: the radiance, and 0 in every other channel
    (bound, bias, noise, variance, photons, radius)."""
    zero = np.zeros(radiance.shape[:2], np.float32)
    planes = {name: zero for name in pbtools.channel_names()}
    for k, c in enumerate(pbtools.RGB):
        planes[pbtools.channel("Radiance", c)] = radiance[..., k]
    pbtools.write_exr(path, planes, metadata)


def cmd_exact(args):
    width, height = pbtools.parse_resolution(args.resolution)
    scene = args.scene or os.path.join(pbtools.REPO, "scenes", DEFAULT_SCENES[args.kind])
    gltf = pbtools.Gltf(scene)
    if args.sub < 1 or args.sub > 64:
        raise ToolError(f"--sub {args.sub}: choose 1 to 64")
    sub = args.sub if args.pixel == "area" else 1
    radiance = exact_image(args.kind, gltf, width, height, sub)
    write_reference(args.output, radiance, {
        "photonbound:reference": f"exact {args.kind}, pixel {args.pixel}"
                                 + (f" ({sub}x{sub} rays)" if args.pixel == "area" else ""),
        "photonbound:scene": scene,
        "photonbound:mean_error_bound": "0",
    })
    print(f"reference: wrote {args.output} (exact {args.kind}, pixel {args.pixel}, "
          f"{width}x{height}, mean radiance "
          f"{radiance.mean():.6g})")


def cmd_render(args, extra):
    exe = pbtools.check_photonbound(args.photonbound)
    if not os.path.isfile(args.scene):
        raise ToolError(f"{args.scene}: no such file")
    pbtools.parse_resolution(args.resolution)
    stops = []
    if args.time is not None:
        stops += ["--time", str(args.time)]
    if args.passes is not None:
        stops += ["--passes", str(args.passes)]
    if args.target_error is not None:
        stops += ["--target-error", str(args.target_error)]
    if not stops:
        raise ToolError("render: give at least one of --time, --passes, --target-error")
    cmd = [exe, "render", args.scene, "-o", args.output, "--resolution", args.resolution,
           "--seed", str(args.seed), *stops, *extra]
    print("reference: " + " ".join(cmd), flush=True)
    start = time.monotonic()
    if subprocess.run(cmd).returncode != 0:
        raise ToolError("the reference render failed (see above)")
    ref = pbtools.read_exr(args.output)
    bound = ref.rgb("ErrorBound")
    finite = bound[np.isfinite(bound)]
    print(f"reference: wrote {args.output}: {ref.meta('photonbound:passes_done')} passes, "
          f"{time.monotonic() - start:.0f} s, mean bound {finite.mean():.6g} at confidence "
          f"{ref.meta('photonbound:confidence')}, {bound.size - finite.size} unknown "
          f"pixel-channels, {os.path.getsize(args.output)} bytes")


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        k = argv.index("--")
        argv, extra = argv[:k], argv[k + 1:]
    ap = argparse.ArgumentParser(prog="reference.py", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    ex = sub.add_parser("exact", help="the analytic answer of the plane or the closed box")
    ex.add_argument("kind", choices=sorted(DEFAULT_SCENES))
    ex.add_argument("-o", "--output", required=True)
    ex.add_argument("--resolution", required=True, help="WxH, as given to photonbound")
    ex.add_argument("--scene", help="the .gltf or .glb file (default: the shipped scene)")
    ex.add_argument("--pixel", choices=["area", "centre"], default="area",
                    help="each pixel's average over its area (--method sppm, the default) or "
                    "its centre's value (--method ppm)")
    ex.add_argument("--sub", type=int, default=16,
                    help="with --pixel area: N x N rays per pixel (default 16)")
    rd = sub.add_parser("render", help="a long photonbound render of any scene")
    rd.add_argument("scene")
    rd.add_argument("-o", "--output", required=True)
    rd.add_argument("--resolution", required=True)
    rd.add_argument("--time", type=float)
    rd.add_argument("--passes", type=int)
    rd.add_argument("--target-error", type=float)
    rd.add_argument("--seed", type=int, default=REFERENCE_SEED)
    rd.add_argument("--photonbound", default=pbtools.default_photonbound())
    args = ap.parse_args(argv)
    if args.command == "exact":
        if extra:
            raise ToolError("exact: takes no render options after --")
        cmd_exact(args)
    else:
        cmd_render(args, extra)


if __name__ == "__main__":
    pbtools.run_main("reference", main)
