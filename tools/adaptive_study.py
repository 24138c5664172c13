"""Adaptive against uniform: passes and seconds to a target error, per --adaptive mode.

  python3 -m tools.adaptive_study OUTDIR [--scenes caustic,indirect,cornell,plane,box,door]
                                  [--modes none,radius,photons,paths,radius+paths]
                                  [--targets T1,T2,...] [--resolution WxH]
                                  [--time-limit S] [--reference-passes N] [--photonbound EXE]

For each scene, target and mode, `photonbound render --target-error T` runs with the default
stop rule (mean-error, 90%) and seed 1, and its image is measured with `photonbound compare`
against the scene's reference. The table gives each mode's passes, seconds and actual mean
error, and the passes and seconds of each mode over the first mode's (issue 39's "time to a
target against --adaptive none"). A mode joins --adaptive parts with + (radius+photons is
--adaptive radius,photons). Passes are the machine-independent figure; seconds on a
shared machine are noisy.

References: the exact pixel-area answers for the plane and the closed box (tools/analytic.py),
the shipped 64x64 SPPM render for the Cornell box, and for the caustic and the indirect room a
long render (--adaptive none, 1M photons per pass, --reference-passes passes, seed 99), whose
own mean 90% bound the table prints: the actual errors include the reference's.
OUTDIR gets table.md, results.json and runs/.
"""

import argparse
import json
import os
import sys
import time

from . import analytic, cli, exr
from .common import REPO, ToolError, parse_resolution, run_main, write_text

SEED = 1
SCENES = {
    "caustic": {"file": "caustic.gltf", "resolution": "128x96", "reference": "render",
                "targets": [0.004, 0.003, 0.0024]},
    "indirect": {"file": "indirect_room.gltf", "resolution": "128x96", "reference": "render",
                 "targets": [0.006, 0.0045, 0.0035]},
    "cornell": {"file": "cornell.gltf", "resolution": "64x64",
                "reference": os.path.join(REPO, "tools", "study",
                                          "cornell_64x64_sppm_reference.exr"),
                "targets": [0.02, 0.012, 0.008]},
    "plane": {"file": "plane_point.gltf", "resolution": "64x64", "reference": "exact plane",
              "options": ["--direct", "photons"], "targets": [0.02, 0.01]},
    "box": {"file": "closed_box.gltf", "resolution": "64x64", "reference": "exact box",
            "targets": [0.08, 0.04]},
    "door": {"file": "door_room.gltf", "resolution": "128x96", "reference": "render",
             "targets": [0.002, 0.0014, 0.001]},
}


def reference(exe, name, cfg, resolution, folder, passes):
    kind = cfg["reference"]
    if kind.startswith("exact"):  # the pixel-area average, as tools.study makes it for SPPM
        path = os.path.join(folder, f"{name}_{resolution}_exact_area.exr")
        w, h = parse_resolution(resolution)
        gltf = analytic.Gltf(os.path.join(REPO, "scenes", cfg["file"]))
        exr.write_reference(path, analytic.exact_image(name, gltf, w, h, 16),
                            {"photonbound:reference": f"exact {name}"})
        return path, float("nan")
    if kind == "render":
        path = os.path.join(folder, f"{name}_{resolution}_reference.exr")
        if not os.path.isfile(path):
            cli.render(exe, os.path.join(REPO, "scenes", cfg["file"]), path,
                       ["--resolution", resolution, "--photons-per-pass", "1000000", "--passes",
                        str(passes), "--seed", "99", "--quiet"] + cfg.get("options", []))
        meta = exr.read_exr(path).metadata
        return path, float(meta["photonbound:mean_error_bound"])
    if resolution != "64x64":
        raise ToolError(f"{name}: the shipped reference is 64x64, not {resolution}")
    return kind, float("nan")


def scene_section(name, resolution, ref_error, rows, modes):
    head = f"### {name} ({resolution}"
    head += f"; the reference's own mean 90% bound {ref_error:.3g})" if ref_error == ref_error \
        else ")"
    lines = [head, "", "| target | " + " | ".join(
        f"{m}: passes | {m}: seconds | {m}: actual | {m}: stop" for m in modes) +
        " | passes / " + modes[0] + " | seconds / " + modes[0] + " |",
        "|---|" + "---|---|---|---|" * len(modes) + "---|---|"]
    for target in dict.fromkeys(r["target"] for r in rows):
        by_mode = {r["mode"]: r for r in rows if r["target"] == target}
        cells = []
        for m in modes:
            r = by_mode[m]
            cells += [str(r["passes"]), f"{r['seconds']:.2f}", f"{r['actual']:.4g}", r["stop"]]
        base = by_mode[modes[0]]
        lines.append(f"| {target:g} | " + " | ".join(cells) + " | " +
                     " / ".join(f"{by_mode[m]['passes'] / base['passes']:.2f}" for m in modes) +
                     " | " + " / ".join(f"{by_mode[m]['seconds'] / base['seconds']:.2f}"
                                        for m in modes) + " |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.adaptive_study",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--modes", default="none,radius")
    ap.add_argument("--targets", help="comma-separated targets for every scene chosen")
    ap.add_argument("--resolution", help="WxH for every scene chosen")
    ap.add_argument("--time-limit", type=float, default=600.0, help="seconds per render")
    ap.add_argument("--reference-passes", type=int, default=400)
    ap.add_argument("--photonbound", default=cli.default_photonbound())
    args = ap.parse_args()
    exe = cli.check_photonbound(args.photonbound)
    names = [s.strip() for s in args.scenes.split(",") if s.strip()]
    unknown = [s for s in names if s not in SCENES]
    if unknown:
        raise ToolError(f"unknown scene {unknown[0]} (known: {', '.join(SCENES)})")
    modes = [m.strip() for m in args.modes.split(",") if m.strip()]
    if not modes:
        raise ToolError("--modes: need at least one mode")
    targets = None
    if args.targets:
        try:
            targets = [float(v) for v in args.targets.split(",") if v.strip()]
        except ValueError:
            raise ToolError(f"--targets: '{args.targets}' is not a comma list of numbers")
        if not targets or any(not (v > 0) for v in targets):
            raise ToolError("--targets: every target must be a number above 0")
    runs_dir = os.path.join(args.outdir, "runs")
    os.makedirs(runs_dir, exist_ok=True)
    start = time.monotonic()
    doc = ["# --adaptive study", "", f"`python3 -m tools.adaptive_study {' '.join(sys.argv[1:])}`,"
           f" {cli.version(exe)}, seed {SEED}, mean-error rule at 90%.", ""]
    results = []
    for name in names:
        cfg = SCENES[name]
        res = args.resolution or cfg["resolution"]
        ref, ref_error = reference(exe, name, cfg, res, runs_dir, args.reference_passes)
        rows = []
        for target in targets or cfg["targets"]:
            for mode in modes:
                path = os.path.join(runs_dir, f"{name}_t{target:g}_{mode}.exr")
                cli.render(exe, os.path.join(REPO, "scenes", cfg["file"]), path,
                           ["--resolution", res, "--target-error", f"{target:g}", "--time",
                            f"{args.time_limit:g}", "--seed", str(SEED), "--adaptive",
                            mode.replace("+", ","),
                            "--quiet"] + cfg.get("options", []))
                meta = exr.read_exr(path).metadata
                c = cli.compare_json(exe, path, ref)
                row = {"scene": name, "target": target, "mode": mode,
                       "passes": int(meta["photonbound:passes_done"]),
                       "seconds": float(meta["photonbound:seconds"]),
                       "stop": meta["photonbound:stop_reason"],
                       "actual": c["mean_abs_error"], "resolution": res, "reference": ref}
                rows.append(row)
                print(f"adaptive_study: {name} target {target:g} {mode}: {row['passes']} passes, "
                      f"{row['seconds']:.1f} s, actual {row['actual']:.4g}", flush=True)
        doc.append(scene_section(name, res, ref_error, rows, modes))
        results += rows
    write_text(os.path.join(args.outdir, "results.json"), json.dumps(results, indent=1) + "\n")
    write_text(os.path.join(args.outdir, "table.md"), "\n".join(doc))
    print(f"adaptive_study: wrote {args.outdir}/table.md in {time.monotonic() - start:.0f} s")


if __name__ == "__main__":
    run_main("adaptive_study", main)
