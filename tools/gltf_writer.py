"""The one glTF 2.0 writer of the tools: a document's binary buffer, and its .gltf or .glb file.

Standard library only, like tools/gltf_scene.py (the reader): tools/make_scenes.py writes the
shipped scenes with it, tools/make_corpus.py its exporter-style files, tests/tools_test.py its
test files. Callers build the document's JSON themselves (each lays it out its own way); this
module owns what every glTF file needs the same:

  Buffer          the single binary buffer: bufferViews on 4-byte boundaries, accessors
  write_gltf      a .gltf with the buffer embedded as a base64 data URI
  write_gltf_external  a .gltf with the buffer in NAME.bin beside it
  write_glb       a binary .glb (JSON chunk padded with spaces, BIN chunk with zeros)
  look_rotation, quaternion, matrix_columns   node transforms that aim cameras and lights

The writers set the document's "buffers" to the one buffer, where the document has that key
(else at its end); the buffer is padded to 4 bytes and byteLength is its padded length. Output
is deterministic: the same document gives the same bytes.
"""

import base64
import json
import math
import os
import struct

from .gltf_scene import GLB_BIN, GLB_JSON, GLB_MAGIC, cross, dot

ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963  # bufferView targets

# ---------------------------------------------------------------------------------------------
# vectors (tuples) and node transforms


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def length(a):
    return math.sqrt(dot(a, a))


def normalize(a):
    return scale(a, 1.0 / length(a))


def look_rotation(eye, target, up_hint=(0.0, 1.0, 0.0)):
    """3x3 rotation (rows) whose local -Z looks from eye to target with local +Y up."""
    forward = normalize(sub(target, eye))
    right = normalize(cross(forward, up_hint))
    up = cross(right, forward)
    back = scale(forward, -1.0)
    return [[right[i], up[i], back[i]] for i in range(3)]


def quaternion(m):
    """Unit quaternion [x, y, z, w] (w >= 0) of the 3x3 rotation matrix m (rows)."""
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = 2.0 * math.sqrt(t + 1.0)
        q = [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4]
    elif m[0][0] >= m[1][1] and m[0][0] >= m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        q = [s / 4, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
    elif m[1][1] >= m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        q = [(m[0][1] + m[1][0]) / s, s / 4, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        q = [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, s / 4, (m[1][0] - m[0][1]) / s]
    q = [x if abs(x) > 1e-15 else 0.0 for x in q]  # no -0.0 / 1e-17 noise in the files
    return q if q[3] >= 0 else [-x for x in q]


def matrix_columns(rotation_rows, translation):
    """glTF node "matrix": column-major 4x4 from a 3x3 rotation (rows) and a translation."""
    cols = []
    for c in range(3):
        cols += [rotation_rows[r][c] for r in range(3)] + [0.0]
    return [x if abs(x) > 1e-15 else 0.0 for x in cols] + list(translation) + [1.0]


# ---------------------------------------------------------------------------------------------
# the binary buffer


class Buffer:
    """The one binary buffer of a document being written (.data), with the document's
    bufferViews (.views) and accessors (.accessors): lists to put into its JSON."""

    def __init__(self):
        self.data = bytearray()
        self.views, self.accessors = [], []

    def view(self, data, target=None):
        """Appends data at the next 4-byte boundary as a bufferView; returns its index."""
        while len(self.data) % 4:
            self.data.append(0)
        v = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(data)}
        if target is not None:
            v["target"] = target
        self.data += data
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, data, component, count, kind, target=None, bounds=None):
        """Appends data (packed little-endian) in a bufferView of its own and an accessor of
        `count` elements of glTF type `kind` (e.g. "VEC3") and componentType `component`;
        bounds = (min, max) lists when given. Returns the accessor's index."""
        acc = {"bufferView": self.view(data, target), "componentType": component,
               "count": count, "type": kind}
        if bounds is not None:
            acc["min"], acc["max"] = bounds
        self.accessors.append(acc)
        return len(self.accessors) - 1


# ---------------------------------------------------------------------------------------------
# files


def _with_buffer(doc, data, uri=None):
    """(a copy of doc whose "buffers" is the one buffer, the buffer padded to 4 bytes)."""
    data = bytes(data) + b"\0" * (-len(data) % 4)
    buf = {"byteLength": len(data)}
    if uri is not None:
        buf["uri"] = uri(data) if callable(uri) else uri
    out = dict(doc)
    out["buffers"] = [buf]
    return out, data


def _write_json(path, doc, indent):
    with open(path, "w", encoding="utf-8") as f:
        f.write(json.dumps(doc, indent=indent) + "\n")


def write_gltf(path, doc, data, indent=1):
    """A .gltf file with the buffer embedded as a base64 data URI."""
    doc, _ = _with_buffer(doc, data, lambda padded: "data:application/octet-stream;base64,"
                          + base64.b64encode(padded).decode())
    _write_json(path, doc, indent)


def write_gltf_external(path, doc, data, indent=1):
    """A .gltf file whose buffer is the file NAME.bin beside it (NAME: the .gltf's stem)."""
    bin_path = os.path.splitext(path)[0] + ".bin"
    doc, data = _with_buffer(doc, data, os.path.basename(bin_path))
    with open(bin_path, "wb") as f:
        f.write(data)
    _write_json(path, doc, indent)


def write_glb(path, doc, data):
    """A binary .glb file: the 12-byte header, the compact JSON chunk, the BIN chunk."""
    doc, data = _with_buffer(doc, data)
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", GLB_MAGIC, 2, 12 + 8 + len(js) + 8 + len(data))
                + struct.pack("<II", len(js), GLB_JSON) + js
                + struct.pack("<II", len(data), GLB_BIN) + data)
