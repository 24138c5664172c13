"""Shared helpers of the Python tools in tools/ (views, plots, references, the study).

EXR channel names come from include/photonbound/channels.def (channel(), rgb_prefix(),
channel_names()); glTF scenes are read by tools/gltf_scene.py (Gltf wraps it in numpy).

Runs with /usr/bin/python3 and the Debian packages python3-numpy, python3-matplotlib and
python3-openimageio (tools/install-deps.sh installs them). Every failure a user can cause
(missing file, wrong channels, bad glTF) raises ToolError with a one-line message; each tool's
main() turns it into that line on stderr and a non-zero exit.
"""

import functools
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

try:
    import OpenImageIO as oiio
except ImportError:  # the tools are meant for /usr/bin/python3 with the Debian package
    oiio = None

TOOLS = os.path.dirname(os.path.abspath(__file__))
if TOOLS not in sys.path:
    sys.path.insert(0, TOOLS)
import gltf_scene  # noqa: E402  (tools/gltf_scene.py: the glTF reader, standard library only)
from gltf_scene import ToolError  # noqa: E402,F401  (a user-facing failure: one line)

REPO = os.path.dirname(TOOLS)
RGB = ("R", "G", "B")  # the components of an RGB channel group (channels.def)
CHANNELS_DEF = os.path.join(REPO, "include", "photonbound", "channels.def")


def run_main(tool, main):
    """Runs main(); ToolError and OS errors become one line on stderr and exit code 1."""
    try:
        sys.exit(main() or 0)
    except ToolError as e:
        print(f"{tool}: {e}", file=sys.stderr)
        sys.exit(1)
    except OSError as e:
        print(f"{tool}: {e.filename}: {e.strerror}" if e.filename else f"{tool}: {e}",
              file=sys.stderr)
        sys.exit(1)
    except KeyboardInterrupt:
        print(f"{tool}: interrupted", file=sys.stderr)
        sys.exit(130)


def _need_oiio():
    if oiio is None:
        raise ToolError("needs the OpenImageIO Python module: run tools/install-deps.sh and use "
                        "/usr/bin/python3")


# ---------------------------------------------------------------------------------------------
# The EXR channel layout: include/photonbound/channels.def, the table the C++ writer reads too

_CHANNEL_LINE = re.compile(r'PB_CHANNEL\(\s*(\w+)\s*,\s*"([^"]*)"\s*,\s*(RGB|SCALAR)\s*,\s*'
                           r'"((?:[^"\\]|\\.)*)"\s*\)\s*$')


@functools.lru_cache(maxsize=None)
def channel_groups():
    """The channel groups in file order: (id, name, kind "RGB" or "SCALAR", meaning) each."""
    try:
        with open(CHANNELS_DEF, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise ToolError(f"{CHANNELS_DEF}: cannot read the channel table ({e.strerror})") from None
    groups = []
    for n, line in enumerate(lines, 1):
        text = line.strip()
        if not text or text.startswith("//"):
            continue
        m = _CHANNEL_LINE.match(text)
        if m is None:
            raise ToolError(f"{CHANNELS_DEF}:{n}: not a PB_CHANNEL(id, \"name\", RGB|SCALAR, "
                            "\"meaning\") line")
        groups.append(m.groups())
    if not groups:
        raise ToolError(f"{CHANNELS_DEF}: no PB_CHANNEL lines")
    return tuple(groups)


def _group(group_id):
    for g in channel_groups():
        if g[0] == group_id:
            return g
    raise ToolError(f"{CHANNELS_DEF}: no channel group {group_id}")


def rgb_prefix(group_id):
    """The prefix of an RGB group's channel names: "" for Radiance, "ErrorBound." ..."""
    _, name, kind, _ = _group(group_id)
    if kind != "RGB":
        raise ToolError(f"{CHANNELS_DEF}: channel {group_id} is {kind}, not RGB")
    return name + "." if name else ""


def channel(group_id, component=None):
    """The EXR channel name of a group, as src/channels.cpp makes it: channel("ErrorBound", "R")
    or channel("ErrorBound", 0) is "ErrorBound.R", channel("Radiance", "G") is "G"; a SCALAR
    group takes no component: channel("Photons") is "Photons"."""
    _, name, kind, _ = _group(group_id)
    if kind == "SCALAR":
        if component is not None:
            raise ToolError(f"{CHANNELS_DEF}: channel {group_id} is SCALAR; it has no "
                            f"component {component}")
        return name
    if component not in RGB and component not in range(3):
        raise ToolError(f"{CHANNELS_DEF}: channel {group_id} is RGB: give R, G, B or 0 .. 2")
    return rgb_prefix(group_id) + (RGB[component] if isinstance(component, int) else component)


def channel_names():
    """Every channel name in file order (the layout photonbound writes)."""
    return [channel(g[0], c) for g in channel_groups() for c in (RGB if g[2] == "RGB" else (None,))]


# ---------------------------------------------------------------------------------------------
# EXR images


class Exr:
    """An EXR as named float32 planes (height x width) plus its string metadata."""

    def __init__(self, path, planes, metadata):
        self.path = path
        self.planes = planes
        self.metadata = metadata

    @property
    def shape(self):
        return next(iter(self.planes.values())).shape

    def channel(self, name):
        if name not in self.planes:
            raise ToolError(f"{self.path}: has no channel {name}")
        return self.planes[name]

    def rgb(self, group="Radiance"):
        """(height, width, 3) array of an RGB channel group of channels.def, by its id."""
        return np.stack([self.channel(channel(group, c)) for c in RGB], axis=-1)

    def meta(self, key, default=None):
        return self.metadata.get(key, default)


def read_exr(path):
    _need_oiio()
    if os.path.isdir(path):
        raise ToolError(f"{path}: is a folder, not an image")
    if not os.path.isfile(path):
        raise ToolError(f"{path}: no such file")
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise ToolError(f"{path}: cannot read as an image ({oiio.geterror().strip()})")
    try:
        spec = inp.spec()
        pixels = inp.read_image(oiio.FLOAT)
        if pixels is None:
            raise ToolError(f"{path}: cannot read pixels ({inp.geterror().strip()})")
        pixels = np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width,
                                                              spec.nchannels)
        planes = {name: pixels[:, :, k].copy() for k, name in enumerate(spec.channelnames)}
        metadata = {a.name: str(a.value) for a in spec.extra_attribs}
    finally:
        inp.close()
    return Exr(path, planes, metadata)


def temp_beside(path, suffix):
    """A fresh temporary file name in path's folder (so a rename over path is atomic), with
    the permissions a newly created file gets (mkstemp's are owner-only)."""
    folder = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=suffix,
                                   dir=folder)
    except OSError as e:
        raise ToolError(f"{path}: cannot write ({e.strerror})") from None
    os.close(fd)
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(tmp, 0o666 & ~mask)
    return tmp


def write_exr(path, planes, metadata):
    """Writes float32 planes (dict name -> height x width) as a zip EXR, atomically."""
    _need_oiio()
    names = list(planes)
    h, w = planes[names[0]].shape
    spec = oiio.ImageSpec(w, h, len(names), oiio.FLOAT)
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    for k, v in metadata.items():
        spec.attribute(k, str(v))
    data = np.stack([np.asarray(planes[n], dtype=np.float32) for n in names], axis=-1)
    tmp = temp_beside(path, ".exr")
    try:
        out = oiio.ImageOutput.create(tmp)
        if out is None or not out.open(tmp, spec):
            raise ToolError(f"{path}: cannot write ({oiio.geterror().strip()})")
        ok = out.write_image(np.ascontiguousarray(data))
        out.close()
        if not ok:
            raise ToolError(f"{path}: cannot write ({oiio.geterror().strip()})")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def write_text(path, text):
    """Writes text to a temporary name beside path, then renames it over path."""
    tmp = temp_beside(path, ".tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def save_figure(fig, path, dpi=100):
    """Saves a matplotlib figure as PNG, atomically, and closes it."""
    import matplotlib.pyplot as plt
    tmp = temp_beside(path, ".png")
    try:
        fig.savefig(tmp, format="png", dpi=dpi)
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.remove(tmp)


def use_agg():
    """Selects matplotlib's file-only backend (no display needed) and returns pyplot."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


# ---------------------------------------------------------------------------------------------
# photonbound itself


def default_photonbound():
    return os.path.join(REPO, "build", "photonbound")


def check_photonbound(exe):
    if not (os.path.isfile(exe) and os.access(exe, os.X_OK)):
        raise ToolError(f"{exe}: no photonbound executable (build it with tools/build.sh, or "
                        "pass --photonbound PATH)")
    return exe


def compare_json(exe, render, reference):
    """`photonbound compare RENDER REFERENCE --json` as a dict."""
    p = subprocess.run([exe, "compare", render, reference, "--json"], capture_output=True,
                       text=True)
    if p.returncode != 0:
        raise ToolError(f"photonbound compare failed: {p.stderr.strip()}")
    return json.loads(p.stdout)


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


def parse_resolution(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise ToolError(f"--resolution {text}: expected WxH, e.g. 64x64") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ToolError(f"--resolution {text}: each side must be 1 .. 16384")
    return w, h


# ---------------------------------------------------------------------------------------------
# glTF: tools/gltf_scene.py reads it; these are its camera, lights and meshes as numpy arrays


class Gltf:
    """A .gltf or .glb scene in world space (read by gltf_scene.load; .scene is that Scene)."""

    def __init__(self, path):
        self.path = path
        self.scene = gltf_scene.load(path)

    def camera(self):
        """The first perspective camera: position, forward, right, up (unit), yfov, aspect
        (None when the file gives none)."""
        cam = self.scene.perspective_camera()
        if cam is None:
            raise ToolError(f"{self.path}: has no perspective camera")
        return {"position": np.array(cam.position), "forward": np.array(cam.forward),
                "right": np.array(cam.right), "up": np.array(cam.up), "yfov": cam.yfov,
                "aspect": cam.aspect}

    def point_lights(self):
        """(position, radiant intensity per channel) of every KHR_lights_punctual point light."""
        out = []
        for light in self.scene.lights:
            if light.type != "point":
                raise ToolError(f"{self.path}: light {light.json.get('name', light.index)} is "
                                "not a point light")
            out.append((np.array(light.position), np.array(light.intensity)))
        return out

    def mesh_instances(self):
        """(world bounds min, max, list of gltf_scene.Material or None) per mesh node."""
        out = []
        for inst in self.scene.meshes:
            points = [p for prim in inst.primitives for p in prim.positions]
            if not points:
                raise ToolError(f"{self.path}: mesh {inst.mesh} has no vertices")
            points = np.array(points, float)
            out.append((points.min(axis=0), points.max(axis=0),
                        [prim.material for prim in inst.primitives]))
        return out


def camera_rays(camera, width, height):
    """Unit directions through the pixel centres, (height, width, 3), as src/camera.cpp makes
    them: pixel (0, 0) is the top-left corner and pixels are square."""
    tan_half = math.tan(0.5 * camera["yfov"])
    aspect = width / height
    x = (np.arange(width) + 0.5) / width
    y = (np.arange(height) + 0.5) / height
    sx = (2.0 * x - 1.0) * tan_half * aspect
    sy = (1.0 - 2.0 * y) * tan_half
    d = (camera["forward"][None, None, :] + sx[None, :, None] * camera["right"][None, None, :] +
         sy[:, None, None] * camera["up"][None, None, :])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)
