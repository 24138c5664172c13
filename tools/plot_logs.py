"""Plots of photonbound's convergence logs and of a sweep of target errors.

  python3 -m tools.plot_logs -o OUTDIR [--name PREFIX] LOG.jsonl[=LABEL] ...
  python3 -m tools.plot_logs -o OUTDIR [--name PREFIX] --sweep RESULTS.json
                             [LOG.jsonl[=LABEL] ...]

From `photonbound render --log LOG.jsonl [--reference REF.exr]` logs it writes
PREFIX_time.png and PREFIX_passes.png: the image mean error bound (dashed) and, when the log
was made with a reference, the actual mean absolute error (solid) against seconds and against
passes, log-log. A LABEL of the form PANEL:SERIES puts the log in the panel PANEL (e.g.
"cornell:90%"); logs without a panel share one.

With --sweep it also writes PREFIX_sweep.png: specified target against actual mean error,
log-log, from a JSON list of objects with the keys scene, confidence, target and actual (as
python3 -m tools.study writes in results.json). PREFIX defaults to "convergence".
"""

import argparse
import json
import os

from .cli import read_log
from .common import ToolError, run_main, save_figure, use_agg

SERIES_COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown"]


def parse_log_args(items):
    logs = []
    for item in items:
        path, _, label = item.partition("=")
        label = label or os.path.splitext(os.path.basename(path))[0]
        panel, _, series = label.rpartition(":")
        logs.append((panel, series, read_log(path)))
    return logs


def convergence_plot(plt, logs, x_key, x_label, path):
    panels = list(dict.fromkeys(p for p, _, _ in logs))
    series = list(dict.fromkeys(s for _, s, _ in logs))
    colour = {s: SERIES_COLOURS[k % len(SERIES_COLOURS)] for k, s in enumerate(series)}
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels) + 0.6, 4.0),
                             layout="constrained", squeeze=False)
    for ax, panel in zip(axes[0], panels):
        for p, s, records in logs:
            if p != panel:
                continue
            bound = [(r[x_key], r["mean_bound"]) for r in records
                     if r["mean_bound"] > 0 and r[x_key] > 0]
            if bound:
                ax.plot(*zip(*bound), "--", color=colour[s], lw=1.4, label=f"mean bound, {s}")
            actual = [(r[x_key], r["mae"]) for r in records if "mae" in r and r[x_key] > 0]
            if actual:
                ax.plot(*zip(*actual), "-", color=colour[s], lw=1.0, alpha=0.8,
                        label=f"actual error, {s} run")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlabel(x_label)
        ax.set_title(panel or "convergence", fontsize=10)
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("mean over pixels and RGB")
    save_figure(fig, path)


def read_sweep(path):
    if not os.path.isfile(path):
        raise ToolError(f"{path}: no such file")
    try:
        with open(path, encoding="utf-8") as f:
            rows = json.load(f)
    except json.JSONDecodeError as e:
        raise ToolError(f"{path}: not JSON ({e.msg})") from None
    if not isinstance(rows, list) or not rows:
        raise ToolError(f"{path}: expected a non-empty JSON list of rows")
    for k, row in enumerate(rows):
        missing = [key for key in ("scene", "confidence", "target", "actual")
                   if not isinstance(row, dict) or key not in row]
        if missing:
            raise ToolError(f"{path}: row {k} lacks {', '.join(missing)}")
    return rows


def sweep_plot(plt, rows, path):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    confidences = sorted({r["confidence"] for r in rows})
    markers = "osD^vP*X"
    colour = {c: SERIES_COLOURS[k % len(SERIES_COLOURS)] for k, c in enumerate(confidences)}
    fig, ax = plt.subplots(figsize=(5.6, 4.6), layout="constrained")
    for si, scene in enumerate(scenes):
        for c in confidences:
            pts = sorted((r["target"], r["actual"]) for r in rows
                         if r["scene"] == scene and r["confidence"] == c)
            if pts:
                ax.plot(*zip(*pts), marker=markers[si % len(markers)], color=colour[c],
                        lw=0.8, ms=5, label=f"{scene}, {100 * c:g}%")
    lo = min(min(r["target"], r["actual"]) for r in rows) * 0.7
    hi = max(max(r["target"], r["actual"]) for r in rows) * 1.4
    ax.plot([lo, hi], [lo, hi], "k-", lw=0.6, label="actual = specified")
    ax.plot([lo, hi], [lo / 2, hi / 2], "k:", lw=0.6, label="actual = specified / 2")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ax.grid(True, which="both", alpha=0.25)
    ax.set_xlabel("specified target error (--target-error)")
    ax.set_ylabel("actual mean absolute error")
    ax.legend(fontsize=7, ncol=2)
    save_figure(fig, path)


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.plot_logs",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("logs", nargs="*", metavar="LOG.jsonl[=LABEL]")
    ap.add_argument("-o", "--output", required=True, help="folder for the PNGs (created)")
    ap.add_argument("--name", default="convergence", help="file name prefix")
    ap.add_argument("--sweep", help="results JSON of a sweep of targets (python3 -m tools.study)")
    args = ap.parse_args()
    if not args.logs and not args.sweep:
        raise ToolError("nothing to plot: give logs, --sweep, or both")
    logs = parse_log_args(args.logs)
    rows = read_sweep(args.sweep) if args.sweep else None
    os.makedirs(args.output, exist_ok=True)
    plt = use_agg()
    written = []
    if logs:
        for key, label, kind in (("seconds", "seconds", "time"), ("pass", "passes", "passes")):
            name = f"{args.name}_{kind}.png"
            convergence_plot(plt, logs, key, label, os.path.join(args.output, name))
            written.append(name)
    if rows:
        name = f"{args.name}_sweep.png"
        sweep_plot(plt, rows, os.path.join(args.output, name))
        written.append(name)
    print(f"plot_logs: wrote {', '.join(written)} in {args.output}")


if __name__ == "__main__":
    run_main("plot_logs", main)
