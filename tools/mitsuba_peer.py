"""The Mitsuba 3 side of tools.mitsuba_side_by_side, run by the Python of the peer's own venv.

  VENV/bin/python -m tools.mitsuba_peer render SCENE.json OUT.exr --integrator ptracer --spp N
                                               [--seed S] [--chunk C]
  VENV/bin/python -m tools.mitsuba_peer mask SCENE.json OUT.exr

SCENE.json is what tools.mitsuba_side_by_side writes from a glTF file: PLY meshes with their
material (diffuse, dielectric, area emitter), punctual lights and the camera. `render` renders
N samples per pixel with the LLVM backend and a box pixel filter, in chunks of C samples per
pixel with seeds S, S + 1, ... (one wavefront of N samples for every pixel would not fit in
memory), averaged; it prints one JSON line: the seconds of the timed chunks and of the
untimed warm-up render (one chunk) that compiles their kernels. `mask` writes 1 where every one
of 4 x 4 rays through a pixel first meets a surface a light tracer can connect to the camera
(not a delta BSDF), else 0.

Imports Mitsuba, Dr.Jit and numpy only (and the standard library): not OpenImageIO.
"""

import argparse
import json
import math
import sys
import time


def load_scene(mi, desc, integrator, spp):
    scene = {"type": "scene",
             "integrator": {"type": integrator, "max_depth": -1, "rr_depth": 5}}
    cam = desc["camera"]
    pos, fwd, up = cam["position"], cam["forward"], cam["up"]
    target = [p + f for p, f in zip(pos, fwd)]
    scene["sensor"] = {
        "type": "perspective", "fov": math.degrees(cam["yfov"]), "fov_axis": "y",
        "to_world": mi.ScalarTransform4f.look_at(origin=pos, target=target, up=up),
        "film": {"type": "hdrfilm", "width": desc["width"], "height": desc["height"],
                 "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": spp}}
    for k, m in enumerate(desc["meshes"]):
        mat = m["material"]
        if mat["kind"] == "dielectric":
            bsdf = {"type": "dielectric", "int_ior": mat["ior"], "ext_ior": 1.0}
        else:
            bsdf = {"type": "diffuse",
                    "reflectance": {"type": "rgb", "value": mat["reflectance"]}}
        shape = {"type": "ply", "filename": m["ply"], "bsdf": bsdf,
                 "face_normals": not m["smooth"]}
        if mat.get("emission") and max(mat["emission"]) > 0.0:
            shape["emitter"] = {"type": "area",
                                "radiance": {"type": "rgb", "value": mat["emission"]}}
        scene[f"mesh_{k}"] = shape
    for k, light in enumerate(desc["lights"]):
        if light["type"] == "point":
            scene[f"light_{k}"] = {"type": "point", "position": light["position"],
                                   "intensity": {"type": "rgb", "value": light["intensity"]}}
        else:
            scene[f"light_{k}"] = {"type": "directional", "direction": light["direction"],
                                   "irradiance": {"type": "rgb", "value": light["intensity"]}}
    return mi.load_dict(scene)


def render(args, mi, np, desc):
    scene = load_scene(mi, desc, args.integrator, 1)
    # The warm-up renders a chunk of the size the timed renders use, so that they find its
    # kernels compiled (Dr.Jit compiles per wavefront shape; a compile takes ~0.3 s here).
    t0 = time.perf_counter()
    np.array(mi.render(scene, spp=min(args.chunk, args.spp), seed=10**6 + args.seed))
    warm = time.perf_counter() - t0
    total = np.zeros((desc["height"], desc["width"], 3))
    done, seed, seconds = 0, args.seed, 0.0
    while done < args.spp:
        n = min(args.chunk, args.spp - done)
        t0 = time.perf_counter()
        img = np.array(mi.render(scene, spp=n, seed=seed))
        seconds += time.perf_counter() - t0
        total += img[..., :3] * n
        done += n
        seed += 1
    mi.Bitmap((total / args.spp).astype(np.float32)).write(args.output)
    print(json.dumps({"spp": args.spp, "seconds": seconds, "warmup_seconds": warm}))


def mask(args, mi, np, desc):
    import drjit as dr
    scene = load_scene(mi, desc, "path", 1)
    sensor = scene.sensors()[0]
    w, h, sub = desc["width"], desc["height"], 4
    ys, xs, sy, sx = np.meshgrid(np.arange(h), np.arange(w), np.arange(sub), np.arange(sub),
                                 indexing="ij")
    u = (xs + (sx + 0.5) / sub) / w
    v = (ys + (sy + 0.5) / sub) / h
    pos = mi.Point2f(u.ravel().astype(np.float32), v.ravel().astype(np.float32))
    rays, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(rays)
    delta = mi.has_flag(si.bsdf().flags(), mi.BSDFFlags.Delta) & si.is_valid()
    dr.eval(delta)
    bad = np.array(delta).reshape(h, w, sub * sub).any(axis=2)
    out = np.repeat((~bad).astype(np.float32)[..., None], 3, axis=2)
    mi.Bitmap(out).write(args.output)
    print(json.dumps({"pixels": int((~bad).sum()), "of": w * h}))


def main():
    ap = argparse.ArgumentParser(prog="python -m tools.mitsuba_peer")
    ap.add_argument("command", choices=("render", "mask"))
    ap.add_argument("scene")
    ap.add_argument("output")
    ap.add_argument("--integrator", default="ptracer")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--chunk", type=int, default=256)
    args = ap.parse_args()
    import mitsuba as mi
    import numpy as np
    mi.set_variant("llvm_ad_rgb")
    with open(args.scene, encoding="utf-8") as f:
        desc = json.load(f)
    (render if args.command == "render" else mask)(args, mi, np, desc)


if __name__ == "__main__":
    try:
        main()
    except Exception as e:  # one line for the driver, which names the run
        print(f"mitsuba_peer: {type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
