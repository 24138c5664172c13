"""PNG views of a photonbound EXR.

  python3 -m tools.views IN.exr -o OUTDIR [--reference REF.exr] [--name PREFIX]
                         [--exposure STOPS]

writes into OUTDIR (PREFIX defaults to IN's file name without .exr):

  PREFIX_radiance.png   the radiance, exposure-scaled, clipped and sRGB-encoded (as
                        `photonbound preview`), enlarged with square pixels to >= 256 pixels
  PREFIX_bound.png      the relative error bound per pixel, max over R, G, B of
                        ErrorBound / max(L, 0.01 x image mean L) (what --error-metric relative
                        measures), false colour on a log scale, with a colour bar
  PREFIX_noise_bias.png |Bias| / noise half-width per pixel (sums over R, G, B, as
                        `photonbound compare` counts bias-dominated pixels): blue pixels are
                        noise-dominated, red ones bias-dominated
  PREFIX_target_ratio.png  TargetRatio (bound over the target, 1 = at the target) on a
                        diverging scale: blue within the target, red beyond
  PREFIX_bounded.png    with --reference: whether |L - L_ref| <= ErrorBound, per pixel
                        (HJJ10 figure 1): how many of its bounded channels are covered

Pixels with bound 0 (background, exact emission) are grey and pixels with an unknown bound
(too few photons yet) black in every map.
"""

import argparse
import math
import os

import numpy as np

from . import exr as exr_io
from .common import ToolError, run_main, save_figure, save_png, use_agg

EXACT_COLOUR = (0.62, 0.62, 0.62, 1.0)
UNKNOWN_COLOUR = (0.0, 0.0, 0.0, 1.0)
RELATIVE_FLOOR = 0.01  # src/estimator/film.h kRelativeFloor


def srgb(linear):
    v = np.clip(np.nan_to_num(linear, nan=0.0), 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1.0 / 2.4) - 0.055)


def enlarge(image, minimum=256):
    k = max(1, math.ceil(minimum / max(image.shape[:2])))
    return np.repeat(np.repeat(image, k, axis=0), k, axis=1)


def pixel_classes(bound):
    """Per pixel: exact (every channel bound 0), unknown (any channel infinite)."""
    unknown = np.any(~np.isfinite(bound), axis=-1)
    exact = np.all(bound == 0.0, axis=-1) & ~unknown
    return exact, unknown


def map_figure(plt, shape, title):
    h, w = shape
    fig_w = 6.0
    fig_h = max(3.0, fig_w * 0.82 * h / w + 0.9)
    fig, ax = plt.subplots(figsize=(fig_w, fig_h), layout="constrained")
    ax.set_title(title, fontsize=10)
    ax.set_xticks([])
    ax.set_yticks([])
    return fig, ax


def add_class_legend(ax, exact, unknown, extra=()):
    from matplotlib.patches import Patch
    handles = list(extra)
    if exact.any():
        handles.append(Patch(color=EXACT_COLOUR, label="bound 0 (exact)"))
    if unknown.any():
        handles.append(Patch(color=UNKNOWN_COLOUR, label="bound unknown"))
    if handles:
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.01),
                  ncol=min(len(handles), 3), fontsize=8, frameon=False)


def paint(colours, exact, unknown):
    colours[exact] = EXACT_COLOUR
    colours[unknown] = UNKNOWN_COLOUR
    return colours


def radiance_view(plt, exr, path, exposure):
    save_png(path, enlarge(srgb(exr.rgb() * 2.0**exposure)))


def finish_map(plt, fig, ax, image, norm, cmap, bar_label, exact, unknown, path):
    """The end every colour-bar view shares: the image, its colour bar, the legend of exact and
    unknown pixels, and the PNG."""
    ax.imshow(image, interpolation="nearest")
    bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, extend="both",
                       shrink=0.9)
    bar.set_label(bar_label)
    add_class_legend(ax, exact, unknown)
    save_figure(fig, path)


def bound_view(plt, exr, path, label):
    import matplotlib.colors as mcolors
    radiance, bound = exr.rgb(), exr.rgb("ErrorBound")
    exact, unknown = pixel_classes(bound)
    floor = RELATIVE_FLOOR * float(np.mean(radiance))
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.max(bound / np.maximum(radiance, max(floor, 1e-300)), axis=-1)
    known = ~exact & ~unknown & np.isfinite(rel) & (rel > 0)
    cmap = plt.get_cmap("viridis")
    if known.any():
        lo, hi = np.percentile(rel[known], [1, 99])
        lo, hi = max(lo, 1e-12), max(hi, lo * 1.0001)
    else:
        lo, hi = 1e-3, 1.0
    norm = mcolors.LogNorm(vmin=lo, vmax=hi)
    colours = cmap(norm(np.where(known, rel, lo)))
    colours[~known & ~exact & ~unknown] = EXACT_COLOUR  # rel == 0: bound 0 in some channel
    mean_rel = float(np.mean(rel[known])) if known.any() else float("nan")
    fig, ax = map_figure(plt, rel.shape, f"{label}\nrelative error bound at "
                         f"{confidence_text(exr)} confidence (pixel mean {mean_rel:.3g})")
    finish_map(plt, fig, ax, paint(colours, exact, unknown), norm, cmap,
               "ErrorBound / max(L, 0.01 mean L), max over R, G, B", exact, unknown, path)


def target_ratio_view(plt, exr, path, label):
    """The TargetRatio channel (bound over --target-error in the render's metric, max over R, G,
    B) on a diverging log scale centred at 1: blue within the target, red beyond it."""
    import matplotlib.colors as mcolors
    ratio = np.max(exr.rgb("TargetRatio"), axis=-1)
    bound = exr.rgb("ErrorBound")
    exact, unknown = pixel_classes(bound)
    known = ~exact & ~unknown & np.isfinite(ratio) & (ratio > 0)
    cmap = plt.get_cmap("coolwarm")
    norm = mcolors.LogNorm(vmin=0.1, vmax=10.0)
    colours = cmap(norm(np.clip(np.where(known, ratio, 1.0), 0.1, 10.0)))
    colours[~known & ~exact & ~unknown] = EXACT_COLOUR
    within = float(np.mean(ratio[known] <= 1.0)) if known.any() else float("nan")
    target = exr.meta("photonbound:target_error", "none")
    fig, ax = map_figure(plt, ratio.shape, f"{label}\nbound / target ({target}) at "
                         f"{confidence_text(exr)} confidence ({100 * within:.1f}% within)")
    finish_map(plt, fig, ax, paint(colours, exact, unknown), norm, cmap,
               "TargetRatio, max over R, G, B (1 = at the target)", exact, unknown, path)


def noise_bias_view(plt, exr, path, label):
    import matplotlib.colors as mcolors
    bound = exr.rgb("ErrorBound")
    exact, unknown = pixel_classes(bound)
    bias = np.sum(np.abs(exr.rgb("Bias")), axis=-1)
    noise = np.sum(exr.rgb("Noise"), axis=-1)
    known = ~exact & ~unknown
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(known, bias / noise, 1.0)
    ratio = np.clip(np.nan_to_num(ratio, nan=1.0, posinf=1e6), 1e-6, 1e6)
    span = 100.0  # ratios beyond 1:100 either way are shown at the ends of the bar
    norm = mcolors.LogNorm(vmin=1.0 / span, vmax=span)
    cmap = plt.get_cmap("RdBu_r")
    colours = paint(cmap(norm(ratio)), exact, unknown)
    dominated = float(np.mean(bias[known] > noise[known])) if known.any() else 0.0
    fig, ax = map_figure(plt, ratio.shape, f"{label}\n|bias| / noise half-width "
                         f"({100 * dominated:.1f}% of bounded pixels bias-dominated)")
    finish_map(plt, fig, ax, colours, norm, cmap,
               "|bias| / noise  (< 1 noise-dominated, > 1 bias-dominated)", exact, unknown, path)


def bounded_view(plt, exr, ref, path, label):
    from matplotlib.patches import Patch
    if ref.shape != exr.shape:
        raise ToolError(f"{exr.path} is {exr.shape[1]}x{exr.shape[0]} but {ref.path} is "
                        f"{ref.shape[1]}x{ref.shape[0]}")
    bound = exr.rgb("ErrorBound")
    err = np.abs(exr.rgb() - ref.rgb())
    exact, unknown = pixel_classes(bound)
    bounded = np.isfinite(bound) & (bound > 0)
    covered = bounded & (err <= bound)
    n_bounded = bounded.sum(axis=-1)
    n_covered = covered.sum(axis=-1)
    levels = [((1.0, 1.0, 1.0, 1.0), "all channels bounded"),
              ((1.0, 0.75, 0.3, 1.0), "some channels bounded"),
              ((0.85, 0.1, 0.1, 1.0), "no channel bounded")]
    colours = np.zeros(n_bounded.shape + (4,))
    has = n_bounded > 0
    colours[has & (n_covered == n_bounded)] = levels[0][0]
    colours[has & (n_covered > 0) & (n_covered < n_bounded)] = levels[1][0]
    colours[has & (n_covered == 0)] = levels[2][0]
    colours[~has & ~unknown] = EXACT_COLOUR
    colours[unknown & ~has] = UNKNOWN_COLOUR
    coverage = covered.sum() / max(1, bounded.sum())
    fig, ax = map_figure(plt, n_bounded.shape, f"{label}\n|L - L_ref| <= bound at "
                         f"{confidence_text(exr)} confidence: coverage {coverage:.3f} of "
                         f"{bounded.sum()} pixel-channels")
    ax.imshow(colours, interpolation="nearest")
    ax.set_facecolor((0.3, 0.3, 0.3))
    extra = [Patch(facecolor=c, edgecolor="0.3", label=t) for c, t in levels]
    add_class_legend(ax, ~has & ~unknown, unknown & ~has, extra)
    save_figure(fig, path)


def confidence_text(exr):
    try:
        return f"{100 * float(exr.meta('photonbound:confidence')):g}%"
    except (TypeError, ValueError):
        return "its"


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.views",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("input", help="a photonbound EXR")
    ap.add_argument("-o", "--output", required=True, help="folder for the PNGs (created)")
    ap.add_argument("--reference", help="reference EXR of the same size: adds PREFIX_bounded.png")
    ap.add_argument("--name", help="file name prefix (default: the input's name)")
    ap.add_argument("--exposure", type=float, default=0.0, help="radiance scale in stops")
    ap.add_argument("--label", help="title of the maps (default: the prefix)")
    args = ap.parse_args()
    exr = exr_io.read_exr(args.input)
    for group in ("Radiance", "ErrorBound", "Bias", "Noise"):
        exr.rgb(group)  # fails, naming the channel, before anything is written
    ref = exr_io.read_exr(args.reference) if args.reference else None
    if ref is not None:
        ref.rgb()
    name = args.name or os.path.splitext(os.path.basename(args.input))[0]
    label = args.label or name
    os.makedirs(args.output, exist_ok=True)
    plt = use_agg()
    out = lambda kind: os.path.join(args.output, f"{name}_{kind}.png")  # noqa: E731
    radiance_view(plt, exr, out("radiance"), args.exposure)
    bound_view(plt, exr, out("bound"), label)
    noise_bias_view(plt, exr, out("noise_bias"), label)
    if "TargetRatio.R" in exr.planes:  # images before the channel existed lack it
        target_ratio_view(plt, exr, out("target_ratio"), label)
    if ref is not None:
        bounded_view(plt, exr, ref, out("bounded"), label)
    print(f"views: wrote {name}_*.png in {args.output}")


if __name__ == "__main__":
    run_main("views", main)
