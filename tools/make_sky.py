"""Writes a small equirectangular sky map (EXR) for docs/materials.md's pictures and tests by
hand: a blue gradient above the horizon, a dim ground below and a small sun of radiance 60.

  python3 -m tools.make_sky OUT.exr [--width 256]
"""

import argparse

import numpy as np

from .common import ToolError, run_main
from .exr import write_exr


def sky(width):
    height = width // 2
    theta = (np.arange(height) + 0.5) / height * np.pi  # 0 at the top row (+Y)
    phi = ((np.arange(width) + 0.5) / width - 0.5) * 2 * np.pi  # centre column -Z
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    y = np.cos(th)[..., None]
    above = np.array([0.35, 0.5, 0.9]) * (1 - 0.6 * y) + 0.2
    rgb = np.where(y > 0, above, np.array([0.15, 0.13, 0.1]))
    d = np.stack([np.sin(th) * np.sin(ph), np.cos(th), -np.sin(th) * np.cos(ph)], -1)
    sun = np.array([0.4, 0.7, 0.6]) / np.linalg.norm([0.4, 0.7, 0.6])
    rgb = rgb + np.where(d @ sun > 0.995, 60.0, 0.0)[..., None] * np.array([1.0, 0.95, 0.85])
    return {c: rgb[..., k].astype(np.float32) for k, c in enumerate("RGB")}


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.make_sky",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("output")
    ap.add_argument("--width", type=int, default=256)
    args = ap.parse_args()
    if args.width < 2:
        raise ToolError("--width must be at least 2")
    write_exr(args.output, sky(args.width), {})


if __name__ == "__main__":
    run_main("make_sky", main)
