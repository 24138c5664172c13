"""The one EXR reader and writer of the tools, and photonbound's channel layout.

EXR channel names come from src/estimator/channels.def, the table the C++ writer reads
too (channel(), rgb_prefix(), channel_names()), so a channel renamed there is renamed here.
Images are read as named float32 planes (Exr) through OpenImageIO's Python module (the Debian
package python3-openimageio; tools/install-deps.sh installs it).
"""

import functools
import os
import re

import numpy as np

from .common import REPO, ToolError, replace_atomically

try:
    import OpenImageIO as oiio
except ImportError:  # the tools are meant for /usr/bin/python3 with the Debian package
    oiio = None

RGB = ("R", "G", "B")  # the components of an RGB channel group (src/estimator/channels.def)
CHANNELS_DEF = os.path.join(REPO, "src", "estimator", "channels.def")


def need_oiio():
    """The OpenImageIO module, or a ToolError saying how to get it."""
    if oiio is None:
        raise ToolError("needs the OpenImageIO Python module: run tools/install-deps.sh and use "
                        "/usr/bin/python3")
    return oiio


# ---------------------------------------------------------------------------------------------
# The EXR channel layout: src/estimator/channels.def

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
    """The EXR channel name of a group, as src/estimator/channels.cpp makes it:
    channel("ErrorBound", "R") or channel("ErrorBound", 0) is "ErrorBound.R", channel("Radiance",
    "G") is "G"; a SCALAR group takes no component: channel("Photons") is "Photons"."""
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
        """(height, width, 3) array of an RGB channel group of src/estimator/channels.def, by id."""
        return np.stack([self.channel(channel(group, c)) for c in RGB], axis=-1)

    def meta(self, key, default=None):
        return self.metadata.get(key, default)


def read_exr(path):
    need_oiio()
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


def write_exr(path, planes, metadata):
    """Writes float32 planes (dict name -> height x width) as a zip EXR, atomically."""
    need_oiio()
    names = list(planes)
    h, w = planes[names[0]].shape
    spec = oiio.ImageSpec(w, h, len(names), oiio.FLOAT)
    spec.channelnames = tuple(names)
    spec.attribute("compression", "zip")
    for k, v in metadata.items():
        spec.attribute(k, str(v))
    data = np.stack([np.asarray(planes[n], dtype=np.float32) for n in names], axis=-1)

    def write(tmp):
        out = oiio.ImageOutput.create(tmp)
        if out is None or not out.open(tmp, spec):
            raise ToolError(f"{path}: cannot write ({oiio.geterror().strip()})")
        ok = out.write_image(np.ascontiguousarray(data))
        out.close()
        if not ok:
            raise ToolError(f"{path}: cannot write ({oiio.geterror().strip()})")
    replace_atomically(path, ".exr", write)


def write_reference(path, radiance, metadata):
    """An EXR with the full channel layout of src/estimator/channels.def: the radiance ((h, w, 3)),
    and 0 in every other channel (bound, bias, noise, variance, photons, radius): an exact
    reference."""
    zero = np.zeros(radiance.shape[:2], np.float32)
    planes = {name: zero for name in channel_names()}
    for k, c in enumerate(RGB):
        planes[channel("Radiance", c)] = radiance[..., k]
    write_exr(path, planes, metadata)
