#!/usr/bin/python3
"""ctest entries for the Python tools in tools/ (registered in tests/CMakeLists.txt).

  tools_test.py smoke --photonbound EXE       a tiny study (plane, 16x16, two targets, both
                                             confidences): the table and plots are written and
                                             the table agrees with `photonbound compare --json`;
                                             then the Cornell sweep, whose shipped reference
                                             must be 10x below its smallest actual error
  tools_test.py bad-input --photonbound EXE  missing files, wrong channels and bad options end
                                             with one line on stderr and a non-zero exit
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

TOOLS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools")
sys.path.insert(0, TOOLS)
import pbtools  # noqa: E402

PYTHON = sys.executable
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message, file=sys.stderr)


def run_tool(tool, *args):
    return subprocess.run([PYTHON, os.path.join(TOOLS, tool), *args], capture_output=True,
                          text=True)


def table_rows(path):
    lines = [l for l in open(path, encoding="utf-8") if l.startswith("|")]
    header = [c.strip() for c in lines[0].strip().strip("|").split("|")]
    return header, [dict(zip(header, (c.strip() for c in l.strip().strip("|").split("|"))))
                    for l in lines[2:]]


def check_png(path):
    if not os.path.isfile(path):
        check(False, f"{path} was not written")
        return
    with open(path, "rb") as f:
        check(f.read(8) == PNG_MAGIC, f"{path} is not a PNG")
    spec = pbtools.oiio.ImageInput.open(path)
    check(spec is not None and spec.spec().width >= 64 and spec.spec().height >= 64,
          f"{path}: unreadable or tiny")
    if spec is not None:
        spec.close()


def smoke(exe, tmp):
    out = os.path.join(tmp, "study")
    targets = [0.03, 0.015]
    p = run_tool("study.py", out, "--scenes", "plane", "--targets", ",".join(map(str, targets)),
                 "--resolution", "16x16", "--photonbound", exe)
    if p.returncode != 0:
        check(False, f"study.py failed ({p.returncode}): {p.stderr.strip()}")
        return
    header, rows = table_rows(os.path.join(out, "table.md"))
    check(header == ["scene", "confidence", "target", "actual mean error", "specified / actual",
                     "passes", "photons", "seconds", "coverage", "stop"],
          f"table header is {header}")
    check(len(rows) == 4, f"expected 4 rows (2 confidences x 2 targets), got {len(rows)}")
    with open(os.path.join(out, "results.json"), encoding="utf-8") as f:
        results = json.load(f)
    check(len(results) == len(rows), "results.json and table.md differ in rows")
    ref = os.path.join(out, "references", "plane_16x16_exact.exr")
    for row in rows:
        conf = int(row["confidence"].rstrip("%"))
        target = float(row["target"])
        exr = os.path.join(out, "runs", f"plane_c{conf}_t{target:g}.exr")
        check(os.path.isfile(exr), f"{exr} missing")
        # Measured again here, independently of the study.
        c = json.loads(subprocess.run([exe, "compare", exr, ref, "--json"], capture_output=True,
                                      text=True, check=True).stdout)
        actual = float(row["actual mean error"])
        check(abs(actual - c["mean_abs_error"]) <= 5e-4 * c["mean_abs_error"],
              f"{exr}: table says actual {actual}, compare says {c['mean_abs_error']}")
        check(abs(float(row["coverage"]) - c["coverage"]) <= 5e-4,
              f"{exr}: table says coverage {row['coverage']}, compare says {c['coverage']}")
        check(abs(float(row["specified / actual"]) - target / c["mean_abs_error"]) <=
              0.005 + 1e-3 * target / c["mean_abs_error"], f"{exr}: specified / actual is off")
        meta = pbtools.read_exr(exr).metadata
        passes = int(meta["photonbound:passes_done"])
        check(int(row["passes"]) == passes, f"{exr}: passes {row['passes']} vs {passes}")
        check(float(row["photons"]) == float(f"{int(meta['photonbound:photons_emitted']):.3g}"),
              f"{exr}: photons {row['photons']}")
        log = pbtools.read_log(exr[:-4] + ".jsonl")
        check(log[-1]["pass"] == passes, f"{exr}: the log ends at pass {log[-1]['pass']}")
        check(abs(log[-1]["mae"] - c["mean_abs_error"]) <= 1e-6 * max(1.0, c["mean_abs_error"]),
              f"{exr}: the log's last mae differs from compare")
        # A stop at the target means the render's own mean bound met it.
        if row["stop"] == "target-error":
            check(float(meta["photonbound:mean_error_bound"]) <= target,
                  f"{exr}: stopped for the target with a mean bound above it")
    for name in ("convergence_time.png", "convergence_passes.png", "convergence_sweep.png"):
        check_png(os.path.join(out, name))
    for conf in (50, 90):
        for kind in ("radiance", "bound", "noise_bias", "bounded"):
            check_png(os.path.join(out, "views", f"plane_c{conf}_t{min(targets):g}_{kind}.png"))
    leftovers = [f for _, _, fs in os.walk(out) for f in fs if f.startswith(".")]
    check(not leftovers, f"temporary files left behind: {leftovers}")
    cornell_reference_margin(exe, tmp)


def cornell_reference_margin(exe, tmp):
    """The shipped Cornell reference judges the study's own Cornell sweep with the 10x margin
    the issue asks for (its bound against the smallest actual error). Seed 1 and the fixed pass
    counts make this deterministic: 13.5x when the reference was made."""
    import study  # noqa: E402  (tools/ is on sys.path)
    out = os.path.join(tmp, "cornell")
    p = run_tool("study.py", out, "--scenes", "cornell", "--photonbound", exe)
    if p.returncode != 0:
        check(False, f"Cornell study failed ({p.returncode}): {p.stderr.strip()}")
        return
    check("warning" not in p.stderr, f"Cornell study warned: {p.stderr.strip()}")
    rows = json.load(open(os.path.join(out, "results.json")))
    bound = study.reference_quality(study.CORNELL_REFERENCE)[0]
    smallest = min(r["actual"] for r in rows)
    check(len(rows) == 8 and bound > 0 and smallest >= study.REFERENCE_MARGIN * bound,
          f"Cornell reference bound {bound:.3g} is not 10x below the smallest error {smallest:.3g}")
    # The warning itself: given for a loose reference, not for a tight or an exact one.
    check(study.reference_warning("x", 0.002, 0.01) is not None, "no warning at 5x")
    check(study.reference_warning("x", 0.0005, 0.01) is None, "warning at 20x")
    check(study.reference_warning("x", 0.0, 0.01) is None, "warning for an exact reference")


def expect_failure(what, p, needle):
    lines = p.stderr.strip().splitlines()
    check(p.returncode != 0, f"{what}: exit code 0")
    check(len(lines) == 1 and needle in p.stderr,
          f"{what}: expected one line mentioning '{needle}', got: {p.stderr.strip()!r}")


def bad_input(exe, tmp):
    missing = os.path.join(tmp, "missing.exr")
    expect_failure("views of a missing file", run_tool("views.py", missing, "-o", tmp), missing)
    rgb_only = os.path.join(tmp, "rgb_only.exr")
    z = np.zeros((4, 4), np.float32)
    pbtools.write_exr(rgb_only, {"R": z, "G": z, "B": z}, {})
    expect_failure("views of an EXR without bounds", run_tool("views.py", rgb_only, "-o", tmp),
                   "has no channel ErrorBound.R")
    check(not any(f.endswith(".png") for f in os.listdir(tmp)), "views wrote PNGs for bad input")
    text = os.path.join(tmp, "not_a_log.jsonl")
    with open(text, "w") as f:
        f.write("hello\n")
    expect_failure("plot of a non-log", run_tool("plot_logs.py", "-o", tmp, text),
                   "not a JSON line")
    expect_failure("plot of a missing log", run_tool("plot_logs.py", "-o", tmp, missing),
                   "no such file")
    expect_failure("study of an unknown scene",
                   run_tool("study.py", os.path.join(tmp, "s"), "--scenes", "teapot",
                            "--photonbound", exe), "--scenes teapot")
    expect_failure("study with a missing photonbound",
                   run_tool("study.py", os.path.join(tmp, "s"), "--photonbound", missing),
                   "no photonbound executable")
    expect_failure("study at a size the Cornell reference lacks",
                   run_tool("study.py", os.path.join(tmp, "s"), "--scenes", "cornell",
                            "--resolution", "8x8", "--photonbound", exe), "not 8x8")
    expect_failure("exact reference of a scene that is not a plane",
                   run_tool("reference.py", "exact", "plane", "-o", rgb_only, "--resolution",
                            "8x8", "--scene",
                            os.path.join(pbtools.REPO, "scenes", "closed_box.gltf")),
                   "is not a horizontal plane")
    expect_failure("bad resolution", run_tool("reference.py", "exact", "box", "-o", rgb_only,
                                              "--resolution", "8by8"), "expected WxH")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["smoke", "bad-input"])
    ap.add_argument("--photonbound", required=True)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix=f"pb_tools_{args.mode}_")
    try:
        (smoke if args.mode == "smoke" else bad_input)(args.photonbound, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print(f"{len(failures)} check(s) failed", file=sys.stderr)
        return 1
    print(f"{args.mode}: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
