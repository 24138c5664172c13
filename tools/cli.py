"""How the tools run photonbound (build/photonbound by default) and read its JSONL logs.

Every tool that renders, compares or asks for the version goes through here, so the command
lines they build and the failures they report are the same: a missing executable or a failed
run is a ToolError of one line.
"""

import json
import os
import subprocess

from .common import REPO, ToolError


def default_photonbound():
    return os.path.join(REPO, "build", "photonbound")


def check_photonbound(exe):
    if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        raise ToolError(f"{exe}: no photonbound executable (build it with tools/build.sh, or "
                        "pass --photonbound PATH)")
    return exe


def render_command(exe, scene, output, options):
    """`photonbound render SCENE -o OUTPUT OPTIONS...` as an argument list."""
    return [exe, "render", scene, "-o", output, *options]


def render(exe, scene, output, options, capture=True):
    """Runs `photonbound render SCENE -o OUTPUT OPTIONS...`: with capture quietly (its stderr
    is in the ToolError when it fails), else printing as it goes. Returns the finished
    subprocess.CompletedProcess."""
    p = subprocess.run(render_command(exe, scene, output, options), capture_output=capture,
                       text=True)
    if p.returncode != 0:
        raise ToolError(f"photonbound render {output} failed"
                        + (f": {p.stderr.strip()}" if capture else " (see above)"))
    return p


def compare_json(exe, render_exr, reference):
    """`photonbound compare RENDER REFERENCE --json` as a dict."""
    p = subprocess.run([exe, "compare", render_exr, reference, "--json"], capture_output=True,
                       text=True)
    if p.returncode != 0:
        raise ToolError(f"photonbound compare failed: {p.stderr.strip()}")
    return json.loads(p.stdout)


def version(exe):
    """What `photonbound --version` prints."""
    return subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip()


def read_log(path):
    """The records of a `--log` JSONL file, in order."""
    if not os.path.isfile(path):
        raise ToolError(f"{path}: no such file")
    records = []
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
            except json.JSONDecodeError as e:
                raise ToolError(f"{path}:{n}: not a JSON line ({e.msg})") from None
            if not isinstance(rec, dict) or "pass" not in rec or "mean_bound" not in rec:
                raise ToolError(f"{path}:{n}: not a photonbound --log record")
            records.append(rec)
    if not records:
        raise ToolError(f"{path}: empty log")
    return records
