"""Shared helpers of the Python tools in tools/ (views, plots, references, the study).

Runs with /usr/bin/python3 and the Debian packages python3-numpy, python3-matplotlib and
python3-openimageio (tools/install-deps.sh installs them). Every failure a user can cause
(missing file, wrong channels, bad glTF) raises ToolError with a one-line message; each tool's
main() turns it into that line on stderr and a non-zero exit.
"""

import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

try:
    import OpenImageIO as oiio
except ImportError:  # the tools are meant for /usr/bin/python3 with the Debian package
    oiio = None

RGB = ("R", "G", "B")
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class ToolError(Exception):
    """A user-facing failure: one line, no traceback."""


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

    def rgb(self, prefix=""):
        """(height, width, 3) array of the channels PREFIX R, G, B."""
        return np.stack([self.channel(prefix + c) for c in RGB], axis=-1)

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
# glTF: just enough to find the camera, lights and mesh bounds in world space


def _quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _local_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=float).reshape(4, 4).T  # glTF is column-major
    m = np.eye(4)
    s = np.diag(node.get("scale", [1.0, 1.0, 1.0]))
    m[:3, :3] = _quat_matrix(node.get("rotation", [0.0, 0.0, 0.0, 1.0])) @ s
    m[:3, 3] = node.get("translation", [0.0, 0.0, 0.0])
    return m


class Gltf:
    """World transforms of a .gltf file's nodes (JSON only: .glb is not read here)."""

    def __init__(self, path):
        if not os.path.isfile(path):
            raise ToolError(f"{path}: no such file")
        if not path.endswith(".gltf"):
            raise ToolError(f"{path}: only .gltf (JSON) scenes are read by this tool")
        try:
            with open(path, encoding="utf-8") as f:
                self.doc = json.load(f)
        except (json.JSONDecodeError, UnicodeDecodeError) as e:
            raise ToolError(f"{path}: not a glTF JSON file ({e})") from None
        self.path = path
        nodes = self.doc.get("nodes", [])
        parent = {}
        for i, n in enumerate(nodes):
            for c in n.get("children", []):
                parent[c] = i
        self.world = []
        for i in range(len(nodes)):
            m, k = np.eye(4), i
            while k is not None:
                m = _local_matrix(nodes[k]) @ m
                k = parent.get(k)
            self.world.append(m)

    def nodes_with(self, key):
        return [(i, n) for i, n in enumerate(self.doc.get("nodes", [])) if key in n]

    def camera(self):
        """The first perspective camera: position, forward, right, up (unit), yfov."""
        for i, n in self.nodes_with("camera"):
            cam = self.doc["cameras"][n["camera"]]
            if cam.get("type") != "perspective":
                continue
            m = self.world[i]
            unit = lambda v: v / np.linalg.norm(v)  # noqa: E731
            return {
                "position": m[:3, 3].copy(),
                "right": unit(m[:3, 0]),
                "up": unit(m[:3, 1]),
                "forward": unit(-m[:3, 2]),
                "yfov": float(cam["perspective"]["yfov"]),
            }
        raise ToolError(f"{self.path}: has no perspective camera")

    def point_lights(self):
        """(position, radiant intensity per channel) of every KHR_lights_punctual point light."""
        lights = self.doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
        out = []
        for i, n in self.nodes_with("extensions"):
            ref = n["extensions"].get("KHR_lights_punctual")
            if ref is None:
                continue
            light = lights[ref["light"]]
            if light.get("type") != "point":
                raise ToolError(f"{self.path}: light {light.get('name', ref['light'])} is not "
                                "a point light")
            intensity = np.array(light.get("color", [1, 1, 1]), float) * light.get("intensity", 1)
            out.append((self.world[i][:3, 3].copy(), intensity))
        return out

    def mesh_instances(self):
        """(world bounds min, max, list of materials) per mesh node, from POSITION min/max."""
        out = []
        for i, n in self.nodes_with("mesh"):
            lo, hi, mats = np.full(3, np.inf), np.full(3, -np.inf), []
            for prim in self.doc["meshes"][n["mesh"]]["primitives"]:
                acc = self.doc["accessors"][prim["attributes"]["POSITION"]]
                a, b = np.array(acc["min"], float), np.array(acc["max"], float)
                for corner in range(8):
                    p = np.array([(b if corner >> k & 1 else a)[k] for k in range(3)] + [1.0])
                    q = (self.world[i] @ p)[:3]
                    lo, hi = np.minimum(lo, q), np.maximum(hi, q)
                mats.append(self.doc["materials"][prim["material"]] if "material" in prim
                            else None)
            out.append((lo, hi, mats))
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
