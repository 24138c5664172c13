"""The one glTF 2.0 reader of the Python tools: a .gltf or .glb file in world space.

Standard library only: tools/make_scenes.py (standard-library Python) validates the scenes it
writes with it, and tools/analytic.py (Gltf) wraps it in numpy arrays for the other tools;
tools/gltf_writer.py is its counterpart that writes.

  scene = gltf_scene.load(path)     # reads and checks the whole file; GltfError when it cannot
  scene.cameras     [Camera]        every camera instance: position, forward, right, up, yfov,
                                    aspect (world space, unit vectors; perspective ones have yfov)
  scene.lights      [Light]         KHR_lights_punctual instances: type, position, direction,
                                    intensity = color x intensity, spot cone angles
  scene.materials   [Material]      every material with the glTF defaults applied
  scene.meshes      [MeshInstance]  mesh nodes, each with its primitives: world-space positions,
                                    normals, indices and triangles (the file's local data too)
  scene.nodes       [Node]          the nodes reached from the scene, parents first, with their
                                    world matrices (scene.world[node index])

It follows the renderer's reading (src/gltf/gltf_loader.cpp; docs/gltf.md "Files, meshes and
primitives"): the default scene (or scene 0, or every node that is nobody's child), depth first;
a node's "matrix" or T * R * S (the quaternion normalised); matrices are column-major lists of
16 numbers as in glTF; normals by the inverse transpose; a mirroring transform keeps the
counter-clockwise front, so world triangles are wound front-side counter-clockwise. It does not
judge materials or geometry (a reflectance above 1, a degenerate triangle): tools that care check
those themselves.

Whatever it cannot read (a missing buffer, a sparse or out-of-range accessor, a node reached
twice, a primitive that is not TRIANGLES) raises GltfError, a ToolError whose message is one
line "FILE: what"; .detail is the "what" alone.
"""

import base64
import json
import math
import os
import struct
import urllib.parse
from functools import cached_property

from .common import ToolError

# glTF constants
BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
TRIANGLES = 4
GLB_MAGIC, GLB_JSON, GLB_BIN = 0x46546C67, 0x4E4F534A, 0x004E4942

EXT_LIGHTS = "KHR_lights_punctual"
EXT_TRANSMISSION = "KHR_materials_transmission"
EXT_IOR = "KHR_materials_ior"
EXT_STRENGTH = "KHR_materials_emissive_strength"
EXT_SPECULAR = "KHR_materials_specular"
EXT_VOLUME = "KHR_materials_volume"

# componentType -> (struct format, bytes, name, divisor of a normalized integer)
COMPONENTS = {
    BYTE: ("b", 1, "BYTE", 127.0), UNSIGNED_BYTE: ("B", 1, "UNSIGNED_BYTE", 255.0),
    SHORT: ("h", 2, "SHORT", 32767.0), UNSIGNED_SHORT: ("H", 2, "UNSIGNED_SHORT", 65535.0),
    UNSIGNED_INT: ("I", 4, "UNSIGNED_INT", 4294967295.0), FLOAT: ("f", 4, "FLOAT", None),
}
TYPES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
INDEX_COMPONENTS = (UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT)
DATA_URI_PREFIXES = ("data:application/octet-stream;base64,",
                     "data:application/gltf-buffer;base64,")


class GltfError(ToolError):
    """A glTF file this module cannot read: str() is "FILE: detail"."""

    def __init__(self, path, detail):
        super().__init__(f"{path}: {detail}")
        self.path, self.detail = str(path), detail


# ---------------------------------------------------------------------------------------------
# 4x4 matrices: column-major lists of 16 numbers, as glTF stores them

IDENTITY = [1.0 if r == c else 0.0 for c in range(4) for r in range(4)]


def matmul(a, b):
    """Product a * b of two column-major 4x4 matrices."""
    return [sum(a[k * 4 + r] * b[c * 4 + k] for k in range(4)) for c in range(4) for r in range(4)]


def quaternion_columns(q):
    """The 3x3 rotation of the quaternion [x, y, z, w], normalised, as three columns; None when
    it is zero or not finite."""
    n = math.sqrt(sum(v * v for v in q))
    if not (n > 0.0 and math.isfinite(n)):
        return None
    x, y, z, w = (v / n for v in q)
    return [(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w)),
            (2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w)),
            (2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y))]


def transform_point(m, p):
    return tuple(m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] for r in range(3))


def transform_direction(m, d):
    return tuple(m[r] * d[0] + m[4 + r] * d[1] + m[8 + r] * d[2] for r in range(3))


def determinant(m):
    """Determinant of the 3x3 linear part."""
    (a, b, c), (d, e, f), (g, h, i) = m[0:3], m[4:7], m[8:11]  # columns
    return a * (e * i - f * h) - d * (b * i - c * h) + g * (b * f - c * e)


def normal_matrix(m):
    """Columns of the inverse transpose of the 3x3 linear part (for normals); None if singular."""
    c0, c1, c2 = m[0:3], m[4:7], m[8:11]
    det = determinant(m)
    if not (det != 0.0 and math.isfinite(det)):
        return None
    # inverse transpose = cofactor matrix / det; its columns are c1 x c2, c2 x c0, c0 x c1
    return [tuple(v / det for v in cross(c1, c2)), tuple(v / det for v in cross(c2, c0)),
            tuple(v / det for v in cross(c0, c1))]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def unit(v):
    """v / |v|, or None when v is zero or not finite."""
    n = math.sqrt(dot(v, v))
    if not (n > 0.0 and math.isfinite(n)):
        return None
    return tuple(x / n for x in v)


# ---------------------------------------------------------------------------------------------
# the file: JSON and buffers


_SINGULAR = {"accessors": "accessor", "bufferViews": "bufferView", "buffers": "buffer",
             "cameras": "camera", "meshes": "mesh", "nodes": "node", "scenes": "scene"}


class Document:
    """A glTF file's JSON (.json) and the bytes of its buffers (.buffers)."""

    def __init__(self, path, doc, buffers):
        self.path, self.json, self.buffers = str(path), doc, buffers

    def fail(self, detail):
        raise GltfError(self.path, detail)

    def item(self, kind, index, where):
        """doc[kind][index], or a GltfError naming `where` when there is none."""
        items = self.json.get(kind, [])
        if not (isinstance(index, int) and not isinstance(index, bool) and 0 <= index < len(items)):
            self.fail(f"{where} refers to {_SINGULAR.get(kind, kind)} {index}, which does not "
                      f"exist (the file has {len(items)})")
        return items[index]

    def read_accessor(self, index, where="", types=None, components=None):
        """(accessor JSON, values): a list of numbers (SCALAR) or of tuples (VECn), honouring
        byteOffset and byteStride; normalized integers become floats. `types` and `components`
        restrict what is accepted (None: anything readable)."""
        where = f"{where} accessor {index}".strip()
        acc = self.item("accessors", index, where)
        if "sparse" in acc:
            self.fail(f"{where} is sparse; sparse accessors are not read")
        kind, component = acc.get("type"), acc.get("componentType")
        if kind not in TYPES or (types is not None and kind not in types):
            self.fail(f"{where} has type {kind}; expected {' or '.join(types or TYPES)}")
        if component not in COMPONENTS or (components is not None and component not in components):
            want = " or ".join(COMPONENTS[c][2] for c in (components or COMPONENTS))
            self.fail(f"{where} has componentType {component}; expected {want}")
        if "bufferView" not in acc:
            self.fail(f"{where} has no bufferView; accessors without data are not read")
        view = self.item("bufferViews", acc["bufferView"], where)
        buffer = self.item("buffers", view.get("buffer"), f"bufferView {acc['bufferView']}")
        fmt, size, _, divisor = COMPONENTS[component]
        comps = TYPES[kind]
        element = size * comps
        stride = view.get("byteStride") or element
        if stride < element:
            self.fail(f"bufferView {acc['bufferView']} has byteStride {stride}, smaller than the "
                      f"{element}-byte elements of {where}")
        count, acc_offset = acc["count"], acc.get("byteOffset", 0)
        view_offset, view_length = view.get("byteOffset", 0), view["byteLength"]
        if count > 0 and acc_offset + stride * (count - 1) + element > view_length:
            self.fail(f"accessor {index} overflows")
        if view_offset + view_length > buffer["byteLength"]:
            self.fail(f"bufferView of accessor {index} overflows its buffer")
        data, start = self.buffers[view["buffer"]], view_offset + acc_offset
        if stride == element:
            flat = struct.unpack_from(f"<{comps * count}{fmt}", data, start)
        else:
            one = struct.Struct(f"<{comps}{fmt}")
            flat = [v for i in range(count) for v in one.unpack_from(data, start + i * stride)]
        if acc.get("normalized") and divisor is not None:
            flat = [max(v / divisor, -1.0) for v in flat]
        if comps == 1:
            return acc, list(flat)
        return acc, list(zip(*[iter(flat)] * comps))


def read_document(path):
    """The JSON and buffers of a .gltf (embedded or external buffers) or .glb file."""
    path = str(path)
    if not os.path.exists(path):
        raise GltfError(path, "no such file")
    if os.path.isdir(path):
        raise GltfError(path, "is a folder, not a glTF file")
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise GltfError(path, f"cannot read ({e.strerror})") from None
    def fail(detail):
        raise GltfError(path, detail)

    glb_bin = None
    if path.endswith(".glb") or raw[:4] == b"glTF":
        if len(raw) < 20:
            fail("bad GLB header")
        magic, version, total = struct.unpack_from("<III", raw, 0)
        if not (magic == GLB_MAGIC and version == 2):
            fail("bad GLB header")
        if total != len(raw):
            fail("GLB length field != file size")
        jlen, jtype = struct.unpack_from("<II", raw, 12)
        if not (jtype == GLB_JSON and jlen % 4 == 0 and 20 + jlen <= total):
            fail("bad GLB JSON chunk")
        text = raw[20:20 + jlen]
        off = 20 + jlen
        while off < total:  # a BIN chunk first; other chunk types are skipped (glTF 2.0 4.4.3)
            if off + 8 > total:
                fail("GLB chunks do not fill the file")
            blen, btype = struct.unpack_from("<II", raw, off)
            if blen % 4 != 0 or (btype == GLB_BIN and glb_bin is not None):
                fail("bad GLB BIN chunk")
            if off + 8 + blen > total:
                fail("GLB chunks do not fill the file")
            if btype == GLB_BIN:
                glb_bin = raw[off + 8:off + 8 + blen]
            off += 8 + blen
    else:
        text = raw
    try:
        doc = json.loads(text.decode("utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        fail(f"not a glTF JSON file ({e})")
    if not isinstance(doc, dict):
        fail("not a glTF JSON file (the top level is not an object)")
    version = str(doc.get("asset", {}).get("version", "")) if isinstance(doc.get("asset"),
                                                                          dict) else ""
    if not version.startswith("2."):
        fail(f"asset.version is {version or 'missing'}; only glTF 2.0 is read")
    buffers = []
    for i, buf in enumerate(doc.get("buffers", [])):
        uri = buf.get("uri")
        if uri is None:
            if not (i == 0 and glb_bin is not None):
                fail("buffer without uri outside a GLB")
            data = glb_bin
        elif uri.startswith("data:"):
            if not uri.startswith(DATA_URI_PREFIXES):
                fail("bad data URI")
            try:
                data = base64.b64decode(uri.split(",", 1)[1], validate=True)
            except ValueError:
                fail(f"buffer {i}: bad base64 in its data URI")
        else:
            name = os.path.join(os.path.dirname(path), urllib.parse.unquote(uri))
            try:
                with open(name, "rb") as f:
                    data = f.read()
            except OSError as e:
                fail(f"buffer {i}: cannot read {uri} ({e.strerror})")
        if not buf.get("byteLength", 0) <= len(data):
            fail(f"buffer {i} shorter than byteLength")
        buffers.append(data)
    return Document(path, doc, buffers)


# ---------------------------------------------------------------------------------------------
# the scene in world space


class Node:
    """A node reached from the scene: index, name, JSON, parent index (None at a root), world."""

    def __init__(self, index, json_, parent, world):
        self.index, self.json, self.parent, self.world = index, json_, parent, world
        self.name = json_.get("name", f"node {index}")


class Camera:
    """A camera instance. position, forward, right, up: world space, unit, right-handed (up made
    orthogonal to forward, right = forward x up, as the renderer does). yfov and aspect (None
    when the file gives none) for a perspective camera; type "orthographic" ones have yfov None.
    """

    def __init__(self, index, json_, node, position, forward, right, up):
        self.index, self.json, self.node = index, json_, node
        self.name = json_.get("name", f"camera {index}")
        self.type = json_.get("type")
        persp = json_.get("perspective", {}) if self.type == "perspective" else {}
        self.yfov = float(persp["yfov"]) if "yfov" in persp else None
        ratio = persp.get("aspectRatio")
        self.aspect = float(ratio) if ratio is not None and ratio > 0 else None
        self.position, self.forward, self.right, self.up = position, forward, right, up


class Light:
    """A KHR_lights_punctual instance. type "point", "spot" or "directional"; position, and
    direction (unit, the node's -Z; None when the transform has none); intensity = color x
    intensity per channel (radiant intensity for point and spot, irradiance for directional);
    inner_cone, outer_cone (radians, glTF defaults 0 and pi/4) for a spot; range or None."""

    def __init__(self, index, json_, node, position, direction):
        self.index, self.json, self.node = index, json_, node
        self.name = json_.get("name", f"light {index}")
        self.type = json_.get("type")
        self.color = tuple(float(c) for c in json_.get("color", (1.0, 1.0, 1.0)))
        strength = float(json_.get("intensity", 1.0))
        self.intensity = tuple(c * strength for c in self.color)
        spot = json_.get("spot", {})
        self.inner_cone = float(spot.get("innerConeAngle", 0.0))
        self.outer_cone = float(spot.get("outerConeAngle", math.pi / 4))
        self.range = json_.get("range")
        self.position, self.direction = position, direction


class Material:
    """A material with the glTF defaults: base_color (RGB of baseColorFactor, default 1), alpha,
    metallic and roughness (default 1 each), emission = emissiveFactor (default 0) x
    KHR_materials_emissive_strength (default 1), transmission (KHR_materials_transmission,
    default 0), ior (KHR_materials_ior, default 1.5), specular (KHR_materials_specular
    specularFactor, default 1) and thin (no KHR_materials_volume with a thicknessFactor above 0).
    .model is the renderer's reading of it (docs/materials.md "Materials: glTF 2.0's
    metallic-roughness model"): "lambertian" (metallic 0, no transmission, specular 0),
    "dielectric" (transmission bounding a volume), "thin" (transmission without a volume) or
    "glossy" (glTF's metallic-roughness BRDF)."""

    def __init__(self, index, json_):
        self.index, self.json = index, json_
        self.name = json_.get("name", f"material {index}")
        pbr = json_.get("pbrMetallicRoughness", {})
        factor = [float(v) for v in pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))]
        self.base_color, self.alpha = tuple(factor[:3]), (factor[3] if len(factor) > 3 else 1.0)
        self.metallic = float(pbr.get("metallicFactor", 1.0))
        self.roughness = float(pbr.get("roughnessFactor", 1.0))
        ext = json_.get("extensions", {})
        self.extensions = ext
        self.emissive_factor = tuple(float(v) for v in json_.get("emissiveFactor", (0.0, 0.0, 0.0)))
        self.emissive_strength = float(ext.get(EXT_STRENGTH, {}).get("emissiveStrength", 1.0))
        self.emission = tuple(c * self.emissive_strength for c in self.emissive_factor)
        self.transmission = float(ext.get(EXT_TRANSMISSION, {}).get("transmissionFactor", 0.0))
        self.ior = float(ext.get(EXT_IOR, {}).get("ior", 1.5))
        self.specular = float(ext.get(EXT_SPECULAR, {}).get("specularFactor", 1.0))
        self.thin = not float(ext.get(EXT_VOLUME, {}).get("thicknessFactor", 0.0)) > 0.0

    @property
    def model(self):
        if self.transmission > 0.0:
            return "thin" if self.thin else "dielectric"
        if self.metallic == 0.0 and self.specular == 0.0:
            return "lambertian"
        return "glossy"


class Primitive:
    """One primitive of a mesh instance. The file's data: local_positions, local_normals (None
    without NORMAL), local_indices (0 .. n-1 when the primitive has none) and the accessors'
    JSON (position_accessor, normal_accessor, index_accessor or None). World space (computed
    on first use): positions; normals (unit; None without NORMAL or when one is zero after the
    transform); indices, wound counter-clockwise front in world space (swapped under a
    mirroring transform); triangles (tuples of three points). material: a Material or None."""

    def __init__(self, instance, index, json_, material, position, normal, indices):
        self.instance, self.index, self.json, self.material = instance, index, json_, material
        self.position_accessor, self.local_positions = position
        self.normal_accessor, self.local_normals = normal
        self.index_accessor, self.local_indices = indices

    @cached_property
    def positions(self):
        m = self.instance.world
        return [transform_point(m, p) for p in self.local_positions]

    @cached_property
    def normals(self):
        if self.local_normals is None:
            return None
        n = self.instance.normal_matrix
        out = [unit(tuple(n[0][r] * v[0] + n[1][r] * v[1] + n[2][r] * v[2] for r in range(3)))
               for v in self.local_normals]
        return None if any(v is None for v in out) else out

    @cached_property
    def indices(self):
        idx = self.local_indices
        if not self.instance.mirrored:
            return list(idx)
        out = []
        for t in range(0, len(idx), 3):
            out += (idx[t], idx[t + 2], idx[t + 1])
        return out

    @cached_property
    def triangles(self):
        p, idx = self.positions, self.indices
        return [(p[idx[t]], p[idx[t + 1]], p[idx[t + 2]]) for t in range(0, len(idx), 3)]


class MeshInstance:
    """A node's mesh: node and mesh indices, name, world matrix, primitives."""

    def __init__(self, node, mesh, json_, world):
        self.node, self.mesh, self.json, self.world = node, mesh, json_, world
        self.name = json_.get("name", f"mesh {mesh}")
        self.mirrored = determinant(world) < 0.0
        self.primitives = []

    @cached_property
    def normal_matrix(self):
        return normal_matrix(self.world)


class Scene:
    """A glTF file in world space (see the module's docstring)."""

    def __init__(self, document):
        self.document, self.path, self.json = document, document.path, document.json
        self.materials = [Material(i, m) for i, m in enumerate(self.json.get("materials", []))]
        self.nodes, self.world, self._seen = [], {}, set()
        self.cameras, self.lights, self.meshes = [], [], []
        self._lights = self.json.get("extensions", {}).get(EXT_LIGHTS, {}).get("lights", [])
        for root, where in self._roots():
            self._walk(root, where)

    def fail(self, detail):
        self.document.fail(detail)

    def _roots(self):
        """(node index, referrer) of the scene's roots: the default scene, scene 0, or every
        node that is nobody's child when there are no scenes."""
        scenes = self.json.get("scenes", [])
        if "scene" in self.json or scenes:
            s = self.json.get("scene", 0)
            scene = self.document.item("scenes", s, '"scene"')
            return [(r, f"scene {s}") for r in scene.get("nodes", [])]
        children = {c for n in self.json.get("nodes", []) for c in n.get("children", [])}
        return [(i, "the file") for i in range(len(self.json.get("nodes", [])))
                if i not in children]

    def _walk(self, root, where):
        stack, seen = [(root, None, IDENTITY, where)], self._seen
        while stack:
            i, parent, parent_world, where = stack.pop()
            node = self.document.item("nodes", i, where)
            if i in seen:
                self.fail(f"node {i} reached twice")
            seen.add(i)
            world = matmul(parent_world, self._local_matrix(i, node))
            if not all(math.isfinite(v) for v in world):
                self.fail(f"node {i} has a non-finite transform")
            self.nodes.append(Node(i, node, parent, world))
            self.world[i] = world
            if "mesh" in node:
                self._add_mesh(i, node["mesh"], world)
            if "camera" in node:
                self._add_camera(i, node["camera"], world)
            if EXT_LIGHTS in node.get("extensions", {}):
                self._add_light(i, node["extensions"][EXT_LIGHTS], world)
            for c in reversed(node.get("children", [])):
                stack.append((c, i, world, f"node {i}"))

    def _local_matrix(self, i, node):
        """The node's "matrix" (column-major), or T * R * S."""
        for key, want in (("matrix", 16), ("translation", 3), ("rotation", 4), ("scale", 3)):
            if key in node and len(node[key]) != want:
                self.fail(f"node {i} has a {key} of {len(node[key])} numbers; expected {want}")
        if "matrix" in node:
            return [float(v) for v in node["matrix"]]
        r = quaternion_columns(node.get("rotation", (0.0, 0.0, 0.0, 1.0)))
        if r is None:
            self.fail(f"node {i} has a zero or non-finite rotation quaternion")
        s = node.get("scale", (1.0, 1.0, 1.0))
        t = node.get("translation", (0.0, 0.0, 0.0))
        cols = [v for c in range(3) for v in (r[c][0] * s[c], r[c][1] * s[c], r[c][2] * s[c], 0.0)]
        return cols + [float(t[0]), float(t[1]), float(t[2]), 1.0]

    def _add_mesh(self, i, m, world):
        mesh = self.document.item("meshes", m, f"node {i}")
        inst = MeshInstance(i, m, mesh, world)
        if inst.normal_matrix is None:
            self.fail(f"node {i} has a singular transform (determinant {determinant(world):g}); "
                      f"cannot place mesh {m}")
        for p, prim in enumerate(mesh.get("primitives", [])):
            inst.primitives.append(self._read_primitive(inst, p, prim))
        self.meshes.append(inst)

    def _read_primitive(self, inst, p, prim):
        where = f"mesh {inst.mesh} prim {p}"
        doc = self.document
        if prim.get("mode", TRIANGLES) != TRIANGLES:
            self.fail(f"{where}: not TRIANGLES")
        material = None
        if "material" in prim:
            k = prim["material"]
            if not (isinstance(k, int) and 0 <= k < len(self.materials)):
                self.fail(f"{where}: bad material")
            material = self.materials[k]
        attrs = prim.get("attributes", {})
        if "POSITION" not in attrs:
            self.fail(f"{where} has no POSITION attribute")
        position = doc.read_accessor(attrs["POSITION"], f"{where} POSITION", ("VEC3",), (FLOAT,))
        count = len(position[1])
        normal = (None, None)
        if "NORMAL" in attrs:
            normal = doc.read_accessor(attrs["NORMAL"], f"{where} NORMAL", ("VEC3",), (FLOAT,))
            if len(normal[1]) != count:
                self.fail(f"{where}: NORMAL count != POSITION count")
        if "indices" in prim:
            indices = doc.read_accessor(prim["indices"], f"{where} indices", ("SCALAR",),
                                        INDEX_COMPONENTS)
            if indices[1] and max(indices[1]) >= count:
                self.fail(f"{where}: index out of range")
            if len(indices[1]) % 3:
                self.fail(f"{where}: index count not a multiple of 3")
        else:
            if count % 3:
                self.fail(f"{where} has {count} vertices, not a multiple of 3, and no indices")
            indices = (None, list(range(count)))
        return Primitive(inst, p, prim, material, position, normal, indices)

    def _add_camera(self, i, c, world):
        cam = self.document.item("cameras", c, f"node {i}")
        forward = unit(transform_direction(world, (0.0, 0.0, -1.0)))
        up = transform_direction(world, (0.0, 1.0, 0.0))
        if forward is not None:  # up made orthogonal to forward (Gram-Schmidt)
            up = unit(tuple(u - dot(up, forward) * f for u, f in zip(up, forward)))
        if forward is None or up is None:
            self.fail(f"camera {c}: node {i} has a degenerate transform (no forward or up "
                      "direction)")
        camera = Camera(c, cam, i, transform_point(world, (0.0, 0.0, 0.0)), forward,
                        unit(cross(forward, up)), up)
        if camera.type == "perspective" and camera.yfov is None:
            self.fail(f"camera {c} has no yfov")
        self.cameras.append(camera)

    def _add_light(self, i, ref, world):
        if not isinstance(ref, dict) or "light" not in ref:
            self.fail(f"node {i}: {EXT_LIGHTS} has no light index")
        k = ref["light"]
        if not (isinstance(k, int) and 0 <= k < len(self._lights)):
            self.fail(f"node {i} refers to light {k}, which does not exist (the file has "
                      f"{len(self._lights)})")
        direction = unit(transform_direction(world, (0.0, 0.0, -1.0)))
        light = Light(k, self._lights[k], i, transform_point(world, (0.0, 0.0, 0.0)), direction)
        if light.type in ("spot", "directional") and direction is None:
            self.fail(f"light {k}: node {i} has a degenerate transform (no direction)")
        self.lights.append(light)

    def perspective_camera(self):
        """The first perspective camera (the renderer's default), or None."""
        return next((c for c in self.cameras if c.type == "perspective"), None)


# What a malformed file makes the reading code raise, turned into one line.
_MALFORMED = (KeyError, IndexError, TypeError, ValueError, AttributeError, struct.error)


def load(path):
    """The scene of a .gltf or .glb file, in world space; GltfError when it cannot be read."""
    try:
        return Scene(read_document(path))
    except GltfError:
        raise
    except _MALFORMED as e:
        raise GltfError(path, f"cannot read it as glTF 2.0 ({type(e).__name__}: {e})") from None
