"""Writes a corpus of glTF files laid out the way Blender's glTF exporter writes them, one per
material feature of docs/materials.md "Materials: glTF 2.0's metallic-roughness model":
python3 -m tools.make_corpus OUTDIR.

Needs numpy and OpenImageIO (tools/install-deps.sh), which write the textures (PNG and JPEG);
the files are written by tools/gltf_writer.py, the tools' one glTF writer. Deterministic. Like
Blender's exporter: y up; one buffer; FLOAT attributes NORMAL, TEXCOORD_0 (and TANGENT where
"export tangents" is on); UNSIGNED_SHORT indices; a material per object with
pbrMetallicRoughness (Principled BSDF defaults where unset: roughness 0.5, metallic 0) or none
at all; samplers with LINEAR / LINEAR_MIPMAP_LINEAR filters; KHR_texture_transform from a
Mapping node; KHR_materials_emissive_strength above strength 1; .glb files embed their images in
bufferViews, the .gltf file references external .png / .jpg files.

CORPUS lists every file with the warnings photonbound must print for it (exactly these) and
the range its mean radiance (at 48x48, tests/tools_test.py corpus) must fall into. Files:

  default_material.glb  Suzanne's case: a material without pbrMetallicRoughness is glTF's
                        default, a rough white metal (metallic 1, roughness 1), not a mirror.
  rough_metals.glb      Gold, copper and steel spheres at roughness 0.2, 0.5, 0.9 on a
                        Principled-default floor (a glossy dielectric), under a ceiling light.
  textured.glb          Embedded PNG textures with KHR_texture_transform: an sRGB base colour
                        checker, metallic-roughness (B metal stripes, G roughness ramp) and a
                        normal map, on a sphere with TANGENT and a floor without (computed).
  textured_external.gltf  External checker.jpg (base colour, MIRRORED_REPEAT, TEXCOORD_1) and
                        bumps.png (normal map, NEAREST magFilter).
  emissive_texture.glb  The only light is a "screen" whose emissiveFactor is [1, 1, 1] with an
                        emissive texture as the mask (strength 5).
  glass.glb             A thin-walled pane (KHR_materials_transmission alone) and a volumetric
                        sphere (with KHR_materials_volume: ior 1.45, attenuation) on a floor.
  double_sided_light.glb  A doubleSided emissive quad whose front faces away from the scene.
  alpha_mask.glb        A leaf-like cut-out (alphaMode MASK, an RGBA base colour) between the
                        light and the floor: light passes through its holes; and a veil in
                        alphaMode BLEND (alpha 0.4: it stops 40% of the rays).
"""

import argparse
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from . import gltf_writer
from .common import ToolError, run_main
from .exr import need_oiio
from .gltf_scene import FLOAT
from .gltf_scene import UNSIGNED_SHORT as USHORT
from .gltf_writer import ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, look_rotation, quaternion

REPEAT, CLAMP, MIRRORED = 10497, 33071, 33648
LINEAR, NEAREST, LINEAR_MIPMAP_LINEAR = 9729, 9728, 9987
GENERATOR = "Khronos glTF Blender I/O v3.6.27 (photonbound tools/make_corpus.py)"

# file -> (warnings photonbound prints for it, (lowest, highest) mean radiance at 48x48 after
# 6 passes of 20,000 photons: the measured mean (both methods agree to 9%) -35% / +40%)
CORPUS = {
    "default_material.glb": ([], (0.074, 0.16)),
    "rough_metals.glb": ([], (0.085, 0.19)),
    "textured.glb": ([], (0.071, 0.15)),
    "textured_external.gltf": ([], (0.075, 0.16)),
    "emissive_texture.glb": ([], (0.15, 0.33)),
    "glass.glb": ([], (0.097, 0.21)),
    "double_sided_light.glb": ([], (0.087, 0.19)),
    "alpha_mask.glb": ([], (0.064, 0.14)),
}


# ----------------------------------------------------------------------------- images

def encode(pixels, ext, quality=92):
    """The bytes of an image file (PNG or JPEG) of an (h, w, c) uint8 array."""
    oiio = need_oiio()
    h, w, c = pixels.shape
    with tempfile.TemporaryDirectory() as tmp:
        name = os.path.join(tmp, "image" + ext)
        out = oiio.ImageOutput.create(name)
        spec = oiio.ImageSpec(w, h, c, "uint8")
        if ext == ".jpg":
            spec.attribute("Compression", f"jpeg:{quality}")
        if not (out.open(name, spec) and out.write_image(np.ascontiguousarray(pixels))):
            raise ToolError(f"cannot write {ext}: {oiio.geterror()}")
        out.close()
        return Path(name).read_bytes()


def checker(n=64, cells=8, a=(200, 60, 40), b=(235, 225, 200)):
    y, x = np.mgrid[0:n, 0:n]
    odd = ((x * cells // n + y * cells // n) % 2)[..., None]
    return np.where(odd == 1, np.array(a, np.uint8), np.array(b, np.uint8)).astype(np.uint8)


def metal_rough(n=64):
    """R occlusion (unread), G roughness ramp 0.15..1 across, B metal in stripes."""
    y, x = np.mgrid[0:n, 0:n]
    img = np.zeros((n, n, 3), np.uint8)
    img[..., 0] = 255
    img[..., 1] = (40 + 215 * x / (n - 1)).astype(np.uint8)
    img[..., 2] = np.where((y // 8) % 2 == 0, 255, 0)
    return img


def bumps(n=64, k=4):
    """A tangent-space normal map of a bump field h = sin sin (+X right, +Y up the image)."""
    y, x = np.mgrid[0:n, 0:n] / n
    s = 2 * math.pi * k
    dhdx = 0.3 * s * np.cos(s * x) * np.sin(s * y) / n
    dhdy_down = 0.3 * s * np.sin(s * x) * np.cos(s * y) / n
    nrm = np.stack([-dhdx, dhdy_down, np.ones_like(x)], -1)  # +Y up: the slope is negated twice
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    return ((nrm * 0.5 + 0.5) * 255 + 0.5).astype(np.uint8)


def screen(w=32, h=16):
    """A mask of bright bars and dark gaps: where the emissive texture is black nothing emits."""
    y, x = np.mgrid[0:h, 0:w]
    on = ((x // 4) % 2 == 0) & (y > 2) & (y < h - 3)
    img = np.zeros((h, w, 3), np.uint8)
    img[on] = (255, 240, 200)
    img[~on] = (10, 10, 10)
    return img


def leaf(n=64):
    """RGBA: green, alpha 0 in a ring of holes and outside a disc."""
    y, x = np.mgrid[0:n, 0:n] / (n - 1) * 2 - 1
    r = np.hypot(x, y)
    holes = np.zeros_like(r, bool)
    for k in range(6):
        a = 2 * math.pi * k / 6
        holes |= np.hypot(x - 0.5 * math.cos(a), y - 0.5 * math.sin(a)) < 0.17
    alpha = np.where((r < 0.95) & ~holes, 255, 0)
    img = np.zeros((n, n, 4), np.uint8)
    img[..., 0], img[..., 1], img[..., 2], img[..., 3] = 60, 150, 50, alpha
    return img


# ----------------------------------------------------------------------------- geometry

def quad(center, u, v, uv_scale=1.0):
    """Two triangles, front u x v; TEXCOORD_0 (0, 0) at the corner center - u + v (the image's
    top-left at the top-left of the quad seen from the front)."""
    c, u, v = (np.array(a, float) for a in (center, u, v))
    pos = np.array([c - u - v, c + u - v, c + u + v, c - u + v])
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], float) * uv_scale
    tan = np.tile(np.append(u / np.linalg.norm(u), 1.0), (4, 1))
    return {"pos": pos, "nrm": np.tile(n, (4, 1)), "uv": uv, "tan": tan,
            "idx": np.array([0, 1, 2, 0, 2, 3])}


def sphere(center, radius, slices=48, stacks=24):
    """UV sphere with a seam (Blender's layout): u around, v from the north pole down."""
    pos, nrm, uv, tan = [], [], [], []
    for i in range(stacks + 1):
        th = math.pi * i / stacks
        for j in range(slices + 1):
            ph = 2 * math.pi * j / slices
            d = np.array([math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)])
            pos.append(np.array(center) + radius * d)
            nrm.append(d)
            uv.append((j / slices, i / stacks))
            t = np.array([-math.sin(ph), 0.0, -math.cos(ph)])  # dP/du: around, eastward
            # w: cross(n, t) w points up the image, toward the north pole (decreasing v).
            north = np.array([math.cos(th) * math.cos(ph), -math.sin(th),
                              -math.cos(th) * math.sin(ph)]) * -1.0
            w = 1.0 if np.dot(np.cross(d, t), north) >= 0 else -1.0
            tan.append(np.append(t, w))
    idx = []
    row = slices + 1
    for i in range(stacks):
        for j in range(slices):
            a, b, c, e = i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1
            if i > 0:
                idx += [a, c, b]
            if i < stacks - 1:
                idx += [b, c, e]
    return {"pos": np.array(pos), "nrm": np.array(nrm), "uv": np.array(uv, float),
            "tan": np.array(tan), "idx": np.array(idx)}


# ----------------------------------------------------------------------------- document

class Doc:
    """One glTF document with a single buffer, built as Blender's exporter lays it out."""

    def __init__(self, glb):
        self.glb, self.buffer, self.files = glb, gltf_writer.Buffer(), {}
        self.j = {"asset": {"generator": GENERATOR, "version": "2.0"}, "scene": 0,
                  "scenes": [{"name": "Scene", "nodes": []}], "nodes": [], "meshes": [],
                  "materials": [], "accessors": self.buffer.accessors,
                  "bufferViews": self.buffer.views}
        self.used = set()

    def add(self, kind, item):
        self.j.setdefault(kind, []).append(item)
        return len(self.j[kind]) - 1

    def accessor(self, array, kind, bounds=False):
        comp = USHORT if kind == "SCALAR" else FLOAT
        data = array.astype(np.uint16 if comp == USHORT else np.float32)
        return self.buffer.accessor(
            data.tobytes(), comp, len(data), kind,
            ELEMENT_ARRAY_BUFFER if comp == USHORT else ARRAY_BUFFER,
            (data.min(0).tolist(), data.max(0).tolist()) if bounds else None)

    def image(self, name, pixels, ext=".png"):
        data = encode(pixels, ext)
        mime = "image/png" if ext == ".png" else "image/jpeg"
        if self.glb:
            return self.add("images", {"bufferView": self.buffer.view(data), "mimeType": mime,
                                       "name": name})
        self.files[name + ext] = data
        return self.add("images", {"mimeType": mime, "name": name, "uri": name + ext})

    def texture(self, image, wrap=REPEAT, mag=LINEAR):
        sampler = self.add("samplers", {"magFilter": mag, "minFilter": LINEAR_MIPMAP_LINEAR,
                                        "wrapS": wrap, "wrapT": wrap})
        return self.add("textures", {"sampler": sampler, "source": image})

    def info(self, texture, tex_coord=0, transform=None, **extra):
        t = {"index": texture, **extra}
        if tex_coord:
            t["texCoord"] = tex_coord
        if transform:
            t["extensions"] = {"KHR_texture_transform": transform}
            self.used.add("KHR_texture_transform")
        return t

    def material(self, name, pbr=None, **rest):
        m = {"name": name, "doubleSided": True}
        if pbr is not None:
            m["pbrMetallicRoughness"] = pbr
        m.update(rest)
        self.used.update(rest.get("extensions", {}))
        return self.add("materials", m)

    def mesh(self, name, geo, material, uv1=False, tangents=False):
        attrs = {"POSITION": self.accessor(geo["pos"], "VEC3", bounds=True),
                 "NORMAL": self.accessor(geo["nrm"], "VEC3"),
                 "TEXCOORD_0": self.accessor(geo["uv"], "VEC2")}
        if uv1:
            attrs["TEXCOORD_1"] = self.accessor(geo["uv"] * 2.0 - 0.5, "VEC2")
        if tangents:
            attrs["TANGENT"] = self.accessor(geo["tan"], "VEC4")
        prim = {"attributes": attrs, "indices": self.accessor(geo["idx"], "SCALAR"),
                "material": material}
        return self.add("meshes", {"name": name, "primitives": [prim]})

    def node(self, name, **fields):
        n = {"name": name, **fields}
        index = self.add("nodes", n)
        self.j["scenes"][0]["nodes"].append(index)
        return index

    def object(self, name, geo, material, **kw):
        return self.node(name, mesh=self.mesh(name, geo, material, **kw))

    def camera(self, eye, target, yfov=0.69):
        cam = self.add("cameras", {"name": "Camera", "type": "perspective", "perspective": {
            "aspectRatio": 1.0, "yfov": yfov, "zfar": 100.0, "znear": 0.1}})
        rot = quaternion(look_rotation(eye, target))
        self.node("Camera", camera=cam, translation=list(eye), rotation=rot)

    def point_light(self, position, intensity, color=(1.0, 1.0, 1.0)):
        ext = self.j.setdefault("extensions", {}).setdefault("KHR_lights_punctual",
                                                             {"lights": []})
        ext["lights"].append({"color": list(color), "intensity": intensity, "name": "Light",
                              "type": "point"})
        self.used.add("KHR_lights_punctual")
        self.node("Light", translation=list(position),
                  extensions={"KHR_lights_punctual": {"light": len(ext["lights"]) - 1}})

    def write(self, path):
        self.j["extensionsUsed"] = sorted(self.used)
        if not self.j["extensionsUsed"]:
            del self.j["extensionsUsed"]
        for k in [k for k, v in self.j.items() if v == []]:
            del self.j[k]
        if self.glb:
            gltf_writer.write_glb(path, self.j, self.buffer.data)
        else:
            for name, data in self.files.items():
                (path.parent / name).write_bytes(data)
            gltf_writer.write_gltf_external(path, self.j, self.buffer.data, indent=2)


# ----------------------------------------------------------------------------- scenes

def principled(color, metallic=0.0, roughness=0.5):
    return {"baseColorFactor": list(color) + [1.0], "metallicFactor": metallic,
            "roughnessFactor": roughness}


def room(d, light=True):
    """Floor and back wall with Principled defaults, a ceiling light (an emissive quad facing
    down, strength 8) and a camera."""
    d.object("Floor", quad((0, 0, 0), (2, 0, 0), (0, 0, -2)),
             d.material("Floor", principled((0.8, 0.8, 0.8))))
    d.object("Wall", quad((0, 1.5, -2), (2, 0, 0), (0, 1.5, 0)),
             d.material("Wall", principled((0.6, 0.65, 0.8))))
    if light:
        d.used.add("KHR_materials_emissive_strength")
        lamp = d.material("Lamp", principled((0, 0, 0)), emissiveFactor=[1.0, 1.0, 1.0],
                          extensions={"KHR_materials_emissive_strength":
                                      {"emissiveStrength": 8.0}})
        d.object("Lamp", quad((0, 2.9, -0.5), (0.5, 0, 0), (0, 0, 0.5)), lamp)
    d.camera((0.0, 1.2, 3.2), (0.0, 0.7, 0.0))


def default_material(d):
    room(d)
    d.object("Suzanne", sphere((0, 0.6, 0), 0.6), d.material("Suzanne"))


def rough_metals(d):
    room(d)
    for x, color, rough in ((-1.1, (1.0, 0.77, 0.34), 0.2), (0.0, (0.95, 0.64, 0.54), 0.5),
                            (1.1, (0.56, 0.57, 0.58), 0.9)):
        d.object(f"Metal {rough}", sphere((x, 0.5, 0), 0.5),
                 d.material(f"Metal {rough}", principled(color, 1.0, rough)))


def textured(d):
    room(d)
    base = d.texture(d.image("checker", checker()))
    mr = d.texture(d.image("metal_rough", metal_rough()))
    nrm = d.texture(d.image("bumps", bumps()))
    xf = {"offset": [0.1, 0.0], "rotation": 0.3, "scale": [3.0, 3.0]}
    pbr = principled((1, 1, 1), 1.0, 1.0)
    pbr["baseColorTexture"] = d.info(base, transform=xf)
    pbr["metallicRoughnessTexture"] = d.info(mr)
    mat = d.material("Textured", pbr, normalTexture=d.info(nrm, transform=xf, scale=1.0))
    d.object("Ball", sphere((0, 0.6, 0), 0.6), mat, tangents=True)
    pbr2 = principled((1, 1, 1), 0.0, 0.6)
    pbr2["baseColorTexture"] = d.info(base, transform={"scale": [4.0, 4.0]})
    d.object("Rug", quad((0, 0.01, 1.0), (1.0, 0, 0), (0, 0, -0.6)),
             d.material("Rug", pbr2, normalTexture=d.info(nrm)))


def textured_external(d):
    room(d)
    base = d.texture(d.image("checker", checker(a=(40, 90, 200)), ".jpg"), wrap=MIRRORED)
    nrm = d.texture(d.image("bumps", bumps(32, 2)), mag=NEAREST)
    pbr = principled((1, 1, 1), 0.0, 0.4)
    pbr["baseColorTexture"] = d.info(base, tex_coord=1)
    d.object("Ball", sphere((0, 0.6, 0), 0.6), d.material("Tiles", pbr, normalTexture=d.info(nrm)),
             uv1=True)


def emissive_texture(d):
    room(d, light=False)
    tex = d.texture(d.image("screen", screen()), wrap=CLAMP)
    d.used.add("KHR_materials_emissive_strength")
    mat = d.material("Screen", principled((0.05, 0.05, 0.05), 0.0, 0.3),
                     emissiveFactor=[1.0, 1.0, 1.0], emissiveTexture=d.info(tex),
                     extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 5.0}})
    d.object("Screen", quad((0, 1.2, -1.9), (1.0, 0, 0), (0, 0.5, 0)), mat)


def glass(d):
    room(d)
    thin = d.material("Pane", principled((0.9, 1.0, 0.9), 0.0, 0.0),
                      extensions={"KHR_materials_transmission": {"transmissionFactor": 1.0}})
    d.object("Pane", quad((-0.7, 0.7, 0.3), (0.5, 0, 0.2), (0, 0.7, 0)), thin)
    vol = d.material("Glass", principled((1, 1, 1), 0.0, 0.0), extensions={
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_ior": {"ior": 1.45},
        "KHR_materials_volume": {"thicknessFactor": 1.0, "attenuationDistance": 0.5,
                                 "attenuationColor": [0.6, 0.9, 0.7]}})
    d.object("Ball", sphere((0.6, 0.5, 0), 0.5), vol)


def double_sided_light(d):
    room(d, light=False)
    d.used.add("KHR_materials_emissive_strength")
    # Front (u x v) faces up, toward the ceiling: only its back lights the room.
    mat = d.material("Panel", principled((0, 0, 0)), emissiveFactor=[1.0, 0.9, 0.8],
                     extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 6.0}})
    d.object("Panel", quad((0, 2.5, -0.5), (0.5, 0, 0), (0, 0, -0.5)), mat)


def alpha_mask(d):
    room(d)
    pbr = principled((1, 1, 1), 0.0, 0.7)
    pbr["baseColorTexture"] = d.info(d.texture(d.image("leaf", leaf()), wrap=CLAMP))
    mat = d.material("Leaf", pbr, alphaMode="MASK", alphaCutoff=0.5)
    d.object("Leaf", quad((0, 1.6, -0.3), (0.9, 0, 0), (0, 0, -0.9)), mat)
    # Blender's "Alpha Blend" mode: coverage 0.4.
    veil = d.material("Veil", {**principled((0.8, 0.3, 0.3)),
                               "baseColorFactor": [0.8, 0.3, 0.3, 0.4]},
                      alphaMode="BLEND")
    d.object("Veil", quad((1.4, 0.5, -1.0), (0.3, 0, 0), (0, 0.5, 0)), veil)


BUILDERS = {"default_material.glb": default_material, "rough_metals.glb": rough_metals,
            "textured.glb": textured, "textured_external.gltf": textured_external,
            "emissive_texture.glb": emissive_texture, "glass.glb": glass,
            "double_sided_light.glb": double_sided_light, "alpha_mask.glb": alpha_mask}


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.make_corpus",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", help="folder for the files (created)")
    out = Path(ap.parse_args().outdir)
    out.mkdir(parents=True, exist_ok=True)
    for name in CORPUS:
        d = Doc(glb=name.endswith(".glb"))
        BUILDERS[name](d)
        d.write(out / name)
        print(f"{name}: {len(d.j.get('materials', []))} materials, "
              f"{len(d.j.get('images', []))} images")


if __name__ == "__main__":
    run_main("make_corpus", main)
