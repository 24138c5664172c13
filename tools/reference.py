"""Reference images to measure photonbound's actual error against.

  python3 -m tools.reference exact plane|box -o REF.exr --resolution WxH [--scene FILE.gltf]
                             [--pixel area|centre] [--sub N]
  python3 -m tools.reference render SCENE.gltf -o REF.exr --resolution WxH (--time S |
                             --passes N | --target-error E) [--seed S] [--photonbound EXE]
                             [-- MORE RENDER OPTIONS]

`exact` writes the analytic answer (tools/analytic.py) of scenes/plane_point.gltf ("plane") or
scenes/closed_box.gltf ("box"), with the camera, light, reflectance and emission read from the
glTF file (.gltf or .glb, through tools/gltf_scene.py): with `--pixel area` (the default) each
pixel's average over its area, from N x N stratified sub-pixel rays (`--sub`, default 16), what
`--method sppm` estimates; with `--pixel centre` the value at the pixel-centre measurement point
`--method ppm` uses (src/scene/camera.cpp). It has every channel of photonbound's layout
(src/estimator/channels.def); all but the radiance are 0.

`render` runs a long photonbound render (its own error bound channels included) and prints
its mean bound, so you can check that it is at least 10x below the errors you study. It uses
seed 1000003 unless told otherwise: a reference must not share its random numbers with the
renders it judges (the study uses seed 1). Options after `--` go to `photonbound render`
(e.g. --radius, --photons-per-pass, --alpha, --checkpoint-every).

For a long reference, start from a radius of a fraction of a pixel and keep alpha near 1
(docs/study.md "Making a reference converge"): the render is then noise-dominated and its bound
falls like passes^-0.5, where the default radius and alpha give about passes^-0.25 in the
Cornell box, because the bias at edges shrinks only as fast as the radius.
"""

import argparse
import os
import sys
import time

import numpy as np

from . import analytic, cli, exr
from .common import REPO, ToolError, parse_resolution, run_main

DEFAULT_SCENES = {"plane": "plane_point.gltf", "box": "closed_box.gltf"}
REFERENCE_SEED = 1000003


def cmd_exact(args):
    width, height = parse_resolution(args.resolution)
    scene = args.scene or os.path.join(REPO, "scenes", DEFAULT_SCENES[args.kind])
    gltf = analytic.Gltf(scene)
    if args.sub < 1 or args.sub > 64:
        raise ToolError(f"--sub {args.sub}: choose 1 to 64")
    sub = args.sub if args.pixel == "area" else 1
    radiance = analytic.exact_image(args.kind, gltf, width, height, sub)
    exr.write_reference(args.output, radiance, {
        "photonbound:reference": f"exact {args.kind}, pixel {args.pixel}"
                                 + (f" ({sub}x{sub} rays)" if args.pixel == "area" else ""),
        "photonbound:scene": scene,
        "photonbound:mean_error_bound": "0",
    })
    print(f"reference: wrote {args.output} (exact {args.kind}, pixel {args.pixel}, "
          f"{width}x{height}, mean radiance "
          f"{radiance.mean():.6g})")


def cmd_render(args, extra):
    exe = cli.check_photonbound(args.photonbound)
    if not os.path.isfile(args.scene):
        raise ToolError(f"{args.scene}: no such file")
    parse_resolution(args.resolution)
    stops = []
    if args.time is not None:
        stops += ["--time", str(args.time)]
    if args.passes is not None:
        stops += ["--passes", str(args.passes)]
    if args.target_error is not None:
        stops += ["--target-error", str(args.target_error)]
    if not stops:
        raise ToolError("render: give at least one of --time, --passes, --target-error")
    options = ["--resolution", args.resolution, "--seed", str(args.seed), *stops, *extra]
    print("reference: " + " ".join(cli.render_command(exe, args.scene, args.output, options)),
          flush=True)
    start = time.monotonic()
    cli.render(exe, args.scene, args.output, options, capture=False)
    ref = exr.read_exr(args.output)
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
    ap = argparse.ArgumentParser(prog="python3 -m tools.reference",
                                 description=__doc__.split("\n\n")[0])
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
    rd.add_argument("--photonbound", default=cli.default_photonbound())
    args = ap.parse_args(argv)
    if args.command == "exact":
        if extra:
            raise ToolError("exact: takes no render options after --")
        cmd_exact(args)
    else:
        cmd_render(args, extra)


if __name__ == "__main__":
    run_main("reference", main)
