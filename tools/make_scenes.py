"""Generates the glTF 2.0 scenes in scenes/ (python3 -m tools.make_scenes from the repo root).

Standard library only, deterministic (identical bytes on every run); the files are written by
tools/gltf_writer.py, the tools' one glTF writer. After writing, every file is read back with
tools/gltf_scene.py (the tools' one glTF reader, also standard library only) and validated (JSON or
GLB container, accessors, min/max, index ranges, winding against normals, closed glass meshes,
extensions), and one summary line per scene is printed. Conventions: y up, metres,
counter-clockwise winding = front face. Diffuse surfaces are pure Lambertian: metallicFactor 0
and KHR_materials_specular specularFactor 0 (glTF's way to say "no specular layer"), which the
analytic answers below assume and validate() checks.

Scenes (analytic answers are radiances in the renderer's units):

  cornell.gltf       Default scene. 2 m Cornell box (x,z in [-1,1], y in [0,2]) open
                     towards +z, white/red/green walls, 0.3 m ceiling light (radiance 40),
                     glass sphere (ior 1.5, KHR_materials_volume) throwing a caustic on the
                     floor, mirror sphere (a smooth metal).
                     No analytic answer; the visual reference.
  plane_point.gltf   Grey Lambertian plane (rho 0.5, 20 x 20 m at y=0, facing +y), point
                     light I = 10 at (0,1,0), camera 3 m above looking down (yfov 0.6).
                     Only direct light exists, so exactly
                       L(x,0,z) = (0.5/pi) * 10 * cos(theta) / d^2 = 5 / (pi d^3),
                       d^2 = x^2 + 1 + z^2;  L(0,0,0) = 5/pi = 1.591549.
                     The camera sees |x|,|z| <= 3 tan(0.3) = 0.928 m (corner L = 0.3543).
  plane_point.glb, plane_point_external.gltf (+ .bin), nested.gltf
                     The same scene as binary GLB, with an external buffer, and through a
                     node hierarchy (TRS parent/child whose product is the identity; light
                     and camera placed with "matrix"). Must render identically.
  glossy_plane.gltf  plane_point with glTF's metallic-roughness BRDF on the plane (base colour
                     0.6, metallic 0.5, roughness 0.4). Only direct light exists, so exactly
                       L(x) = f(wo, wi) * 10 * cos(theta) / d^2,  d^2 = x^2 + 1 + z^2,
                     f glTF's appendix B at wo (toward the camera) and wi (toward the light);
                     L = 10.86 at the image centre (the highlight), 0.220 at its corners.
  closed_box.gltf    Closed cube [-1,1]^3, walls facing inward, one material: Lambertian
                     rho 0.5 emitting Le 1.0. Camera inside at (0,0,0.9) looking -z.
                     Exactly L = Le / (1 - rho) = 2.0 everywhere, in every direction
                     (irradiance 2 pi on every wall; emitted power pi * 1 * 24 m^2 = 24 pi).
  closed_block.gltf  The closed box with a block floating inside, faces outward, of the same
                     material: still a closed furnace, L = 2.0 everywhere; the block adds
                     edges, creases and silhouettes.
  spot.gltf          4 x 4 m floor (rho 0.7) at y=0, spot light I = 20 at (0,2,0) pointing
                     down, inner cone 0.3 rad, outer 0.5 rad. Only direct light; inside the
                     inner cone (r <= 2 tan 0.3 = 0.619 m) exactly
                       L = (0.7/pi) * 20 * 2 / d^3,  d^2 = r^2 + 4;  L(0) = 3.5/pi = 1.114085.
                     Zero beyond r = 2 tan 0.5 = 1.093 m; the falloff between is the
                     renderer's spot profile.
  glass_slab.gltf    4 x 4 m floor (rho 0.8), closed glass box 1 x 0.2 x 1 m (ior 1.5) at
                     y in [0.8,1.0], 0.2 m light (radiance 50) facing down at y = 1.9.
                     Tests Fresnel splitting and caustics. Approximate check: irradiance
                     reaching the floor centre through the slab (all internal bounces)
                     = 0.547, i.e. 0.99 x the 0.552 of the bare light (Fresnel loss
                     T = (1-R)/(1+R) = 0.923, offset by the slab pulling the light's image
                     0.067 m closer); floor radiance there ~ 0.8/pi * 0.547 = 0.139, plus
                     ~2% from floor <-> slab-underside interreflection.

  caustic.gltf       4 x 4 m floor (rho 0.8), glass ball (radius 0.4, ior 1.5) resting on it,
                     0.1 m lamp (radiance 400) facing down at y = 2, off to the side: the
                     caustic of issue 39's convergence figures. No analytic answer.
  indirect_room.gltf 4 x 3 x 4 m white room with a red wall and a block; a 0.4 m lamp
                     faces the back wall from 0.4 m and the camera looks the other way, so
                     all light it sees has bounced at least once. No analytic answer.

  door_room.gltf     Two 4 x 3 x 4 m white rooms joined by a 1 x 2 m door; a 0.5 m lamp on
                     the far room's ceiling, the camera in the other room looking at the
                     door: the light it sees came through the door. No analytic answer.

  unlit.gltf         A model as exporters write one with neither camera nor light: a 4 x 4
                     grey ground (rho 0.8), a red box, a blue sphere and a mirror sphere.
                     Rendered as shipped it gets the default view (framing the bounds) and the
                     default sky (uniform radiance 1): docs/gltf.md "A scene
                     with no camera and no light".
  furnace.gltf       Flat-shaded unit sphere (a convex polyhedron, rho 0.5), camera at
                     (0, 0, 4), no light: under the default sky (Le = 1) exactly L = rho Le =
                     0.5 wherever the sphere is seen, 1 elsewhere.
  sun.gltf           10 x 10 plane (rho 0.5) under a directional light of irradiance 2
                     travelling 30 degrees from straight down, camera 3 above looking down:
                     exactly L = (0.5/pi) * 2 * cos(30 deg) = 0.275664.

--corpus DIR writes files the way exporters do (tests/gltf/test_corpus.cpp renders them, with
build/tools/make_gltf_corpus's Draco, meshopt, quantised and sparse files):

  exported.glb       no camera, no light; an animation, a morph target and an extension
                     photonbound does not implement (KHR_materials_specular).
  sun_spot.gltf      a camera, a directional light and a spot light with a range.
  huge_ground.gltf   a 1-unit box and sphere on a 2e5 x 2e5 ground under a sun, a close camera.

Not in scenes/ (25 MB; generated on demand, by the benchmark on first use, or with
python3 -m tools.make_scenes --heavy DIR):

  cornell_heavy.glb  The default scene with the mirror sphere replaced by a displaced
                     clay-coloured Lambertian sphere of 1,046,528 triangles (1024 x 512 UV
                     grid, radius 0.33 (1 + 0.06 sin 9 theta sin 9 phi), analytic normals).
                     Benchmark scene (at least 1 M triangles); no analytic answer.

Not in scenes/ either (python3 -m tools.make_scenes --smallvcm DIR; the benchmark writes it):

  smallvcm_twin.gltf SmallVCM's default scene (github.com/SmallVCM/SmallVCM, `smallvcm -s 0`):
                     its Cornell box open at the front, a mirror and a glass ball (IOR 1.6) of
                     radius 0.5, the unlit light box and the sun, SmallVCM's camera; the floor
                     Lambertian. For issue 40's per-pass comparison with `smallvcm -a ppm`.
"""

import argparse
import math
import os
import struct
import sys
from pathlib import Path

from . import gltf_scene, gltf_writer
from .common import REPO  # noqa: E402
from .gltf_scene import (EXT_IOR, EXT_LIGHTS, EXT_SPECULAR, EXT_STRENGTH,  # noqa: E402
                         EXT_TRANSMISSION, EXT_VOLUME, FLOAT, TRIANGLES, cross, dot)
from .gltf_scene import UNSIGNED_INT as UINT  # noqa: E402
from .gltf_writer import (ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, add, length,  # noqa: E402
                          look_rotation, matrix_columns, normalize, quaternion, scale, sub)

# ----------------------------------------------------------------------------- geometry


class Geometry:
    """Indexed triangles with per-vertex normals (outward = counter-clockwise front side)."""

    def __init__(self, positions, normals, indices):
        self.positions, self.normals, self.indices = list(positions), list(normals), list(indices)

    def __add__(self, other):
        base = len(self.positions)
        return Geometry(self.positions + other.positions, self.normals + other.normals,
                        self.indices + [i + base for i in other.indices])

    @property
    def triangles(self):
        return len(self.indices) // 3


def merge(geometries):
    geometries = list(geometries)
    out = geometries[0]
    for g in geometries[1:]:
        out = out + g
    return out


def quad(center, u, v):
    """Parallelogram center +- u +- v, two triangles, front side (and flat normal) u x v."""
    n = normalize(cross(u, v))
    corners = [add(center, add(scale(u, su), scale(v, sv)))
               for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return Geometry(corners, [n] * 4, [0, 1, 2, 0, 2, 3])


def horizontal_quad(center, half_x, half_z, facing_up=True):
    """Axis-aligned quad in the plane y = center.y, facing +y (or -y)."""
    return quad(center, (half_x, 0.0, 0.0), (0.0, 0.0, -half_z if facing_up else half_z))


def box_faces(lo, hi, inward=False):
    """The six faces of an axis-aligned box as {"+x": Geometry, "-x": ..., ...}.

    Faces face outward (a closed solid) or inward (an enclosure seen from inside)."""
    mid = scale(add(lo, hi), 0.5)
    half = scale(sub(hi, lo), 0.5)
    faces = {}
    for i, axis in enumerate("xyz"):
        j, k = (i + 1) % 3, (i + 2) % 3
        u = tuple(half[j] if a == j else 0.0 for a in range(3))  # e_j x e_k = e_i
        v = tuple(half[k] if a == k else 0.0 for a in range(3))
        for sign in (1, -1):
            center = tuple((hi if sign > 0 else lo)[a] if a == i else mid[a] for a in range(3))
            outward = sign > 0
            faces[("+" if sign > 0 else "-") + axis] = (
                quad(center, u, v) if outward != inward else quad(center, v, u))
    return faces


def box(lo, hi, inward=False):
    faces = box_faces(lo, hi, inward)
    return merge(faces[name] for name in ("+x", "-x", "+y", "-y", "+z", "-z"))


def uv_sphere(center, radius, slices=64, stacks=32):
    """Closed UV sphere, outward winding, smooth normals; single pole vertices (no slivers)."""
    dirs = [(0.0, 1.0, 0.0)]
    for i in range(1, stacks):
        theta = math.pi * i / stacks
        for j in range(slices):
            phi = 2.0 * math.pi * j / slices
            dirs.append((math.sin(theta) * math.cos(phi), math.cos(theta),
                         math.sin(theta) * math.sin(phi)))
    dirs.append((0.0, -1.0, 0.0))
    north, south = 0, len(dirs) - 1

    def ring(i, j):  # vertex j of latitude ring i (1 .. stacks-1)
        return 1 + (i - 1) * slices + j % slices

    idx = []
    for j in range(slices):
        idx += [north, ring(1, j + 1), ring(1, j)]
        for i in range(1, stacks - 1):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            idx += [a, b, c, b, d, c]
        idx += [ring(stacks - 1, j), ring(stacks - 1, j + 1), south]
    return Geometry([add(center, scale(d, radius)) for d in dirs], dirs, idx)


def displaced_sphere(center, radius, slices, stacks, amplitude, frequency):
    """UV sphere with radius r = radius (1 + amplitude sin(f theta) sin(f phi)), outward winding.

    Same topology as uv_sphere; normals are the analytic normals of the displaced surface
    (dp/dtheta x dp/dphi), radial at the poles. Written with flat loops: ~1 M triangles."""
    a, f = amplitude, frequency
    positions, normals = [], []

    def vertex(theta, phi):
        st, ct, sp, cp = math.sin(theta), math.cos(theta), math.sin(phi), math.cos(phi)
        d = (st * cp, ct, st * sp)
        r = radius * (1.0 + a * math.sin(f * theta) * math.sin(f * phi))
        r_t = radius * a * f * math.cos(f * theta) * math.sin(f * phi)
        # dp/dphi / sin(theta) = (r_phi / sin theta) d + r (-sin phi, 0, cos phi)
        r_p = radius * a * f * math.sin(f * theta) * math.cos(f * phi) / st
        dt = (ct * cp, -st, ct * sp)
        p_t = (r_t * d[0] + r * dt[0], r_t * d[1] + r * dt[1], r_t * d[2] + r * dt[2])
        p_p = (r_p * d[0] - r * sp, r_p * d[1], r_p * d[2] + r * cp)
        n = normalize(cross(p_p, p_t))
        positions.append((center[0] + r * d[0], center[1] + r * d[1], center[2] + r * d[2]))
        normals.append(n)

    positions.append(add(center, (0.0, radius, 0.0)))
    normals.append((0.0, 1.0, 0.0))
    for i in range(1, stacks):
        for j in range(slices):
            vertex(math.pi * i / stacks, 2.0 * math.pi * j / slices)
    positions.append(add(center, (0.0, -radius, 0.0)))
    normals.append((0.0, -1.0, 0.0))
    south = len(positions) - 1
    idx = []
    for j in range(slices):
        j1 = (j + 1) % slices
        idx += [0, 1 + j1, 1 + j]
        for i in range(1, stacks - 1):
            r0, r1 = 1 + (i - 1) * slices, 1 + i * slices
            idx += [r0 + j, r0 + j1, r1 + j, r0 + j1, r1 + j1, r1 + j]
        last = 1 + (stacks - 2) * slices
        idx += [last + j, last + j1, south]
    return Geometry(positions, normals, idx)


# ----------------------------------------------------------------------------- glTF builder


class GltfBuilder:
    """Accumulates one glTF document: a single binary buffer plus the JSON objects."""

    def __init__(self):
        self.buffer = gltf_writer.Buffer()
        self.materials, self.meshes, self.nodes = [], [], []
        self.cameras, self.lights, self.roots = [], [], []
        self.extensions = set()
        self.animations = []

    # -- buffers
    def _accessor(self, fmt, values, count, component, kind, target, bounds=False):
        data = struct.pack("<" + fmt * len(values), *values)
        minmax = None
        if bounds:  # min/max of the float32 values actually stored
            stored = struct.unpack("<" + fmt * len(values), data)
            minmax = [min(stored[c::3]) for c in range(3)], [max(stored[c::3]) for c in range(3)]
        return self.buffer.accessor(data, component, count, kind, target, minmax)

    def _vec3(self, vectors, bounds=False):
        flat = [x for v in vectors for x in v]
        return self._accessor("f", flat, len(vectors), FLOAT, "VEC3", ARRAY_BUFFER, bounds)

    # -- materials
    def material(self, name, base_color, metallic=0.0, roughness=1.0, emission=None,
                 strength=1.0, transmission=None, ior=None, specular=None, thickness=None):
        m = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(base_color) + [1.0],
            "metallicFactor": metallic, "roughnessFactor": roughness}}
        ext = {}
        if specular is not None:
            ext[EXT_SPECULAR] = {"specularFactor": specular}
        if thickness is not None:
            ext[EXT_VOLUME] = {"thicknessFactor": thickness}
        if emission is not None:
            m["emissiveFactor"] = list(emission)
            if strength != 1.0:
                ext[EXT_STRENGTH] = {"emissiveStrength": strength}
        if transmission is not None:
            ext[EXT_TRANSMISSION] = {"transmissionFactor": transmission}
        if ior is not None:
            ext[EXT_IOR] = {"ior": ior}
        if ext:
            m["extensions"] = ext
            self.extensions.update(ext)
        self.materials.append(m)
        return len(self.materials) - 1

    def lambertian(self, name, reflectance, radiance=None):
        """Diffuse (metallic 0, KHR_materials_specular specularFactor 0: glTF's way to say "no
        specular layer"); radiance (a number) makes it a white one-sided area light as well."""
        if radiance is None:
            return self.material(name, reflectance, specular=0.0)
        return self.material(name, reflectance, emission=(1.0, 1.0, 1.0), strength=radiance,
                             specular=0.0)

    def mirror(self, name, tint):
        return self.material(name, tint, metallic=1.0, roughness=0.0)

    def glass(self, name, ior=1.5, thickness=1.0):
        """Smooth glass bounding a volume (KHR_materials_volume: a thicknessFactor above 0; the
        renderer traces the real thickness)."""
        return self.material(name, (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=ior,
                             thickness=thickness)

    # -- meshes, cameras, lights, nodes
    def mesh(self, name, parts, flat=False, targets=None):
        """parts: [(Geometry, material index)], one primitive each; flat: no NORMAL (faceted);
        targets: per-vertex POSITION offsets of one morph target for every primitive."""
        prims = []
        for geo, mat in parts:
            attrs = {"POSITION": self._vec3(geo.positions, bounds=True)}
            if not flat:
                attrs["NORMAL"] = self._vec3(geo.normals)
            ind = self._accessor("I", geo.indices, len(geo.indices), UINT, "SCALAR",
                                 ELEMENT_ARRAY_BUFFER)
            prims.append({"attributes": attrs, "indices": ind, "material": mat,
                          "mode": TRIANGLES})
            if targets is not None:
                prims[-1]["targets"] = [{"POSITION": self._vec3(targets(geo), bounds=True)}]
        self.meshes.append({"name": name, "primitives": prims})
        if targets is not None:
            self.meshes[-1]["weights"] = [0.5]
        return len(self.meshes) - 1

    def scalars(self, values):
        """A FLOAT SCALAR accessor with min/max (animation times)."""
        data = struct.pack(f"<{len(values)}f", *values)
        return self.buffer.accessor(data, FLOAT, len(values), "SCALAR", ARRAY_BUFFER,
                                    ([min(values)], [max(values)]))

    def animate_translation(self, node, times, translations):
        """One LINEAR translation channel on a node (as exporters write object motion)."""
        inp, out = self.scalars(times), self._vec3(translations)
        self.animations.append({"name": "motion", "samplers": [{"input": inp, "output": out}],
                                "channels": [{"sampler": 0,
                                              "target": {"node": node, "path": "translation"}}]})

    def camera(self, name, yfov, aspect=1.0):
        self.cameras.append({"name": name, "type": "perspective", "perspective": {
            "yfov": yfov, "aspectRatio": aspect, "znear": 0.01, "zfar": 1000.0}})
        return len(self.cameras) - 1

    def point_light(self, name, intensity, color=(1.0, 1.0, 1.0)):
        return self._light({"name": name, "type": "point", "color": list(color),
                            "intensity": intensity})

    def spot_light(self, name, intensity, inner, outer, color=(1.0, 1.0, 1.0)):
        return self._light({"name": name, "type": "spot", "color": list(color),
                            "intensity": intensity,
                            "spot": {"innerConeAngle": inner, "outerConeAngle": outer}})

    def directional_light(self, name, intensity, color=(1.0, 1.0, 1.0)):
        """Irradiance color x intensity on a surface facing it; travels along the node's -Z."""
        return self._light({"name": name, "type": "directional", "color": list(color),
                            "intensity": intensity})

    def light_node(self, name, light, travel, position=(0.0, 0.0, 0.0)):
        """A node whose -Z points along `travel` (directional and spot lights)."""
        up = (0.0, 0.0, -1.0) if abs(normalize(travel)[1]) > 0.99 else (0.0, 1.0, 0.0)
        rot = look_rotation((0.0, 0.0, 0.0), travel, up)
        return self.node(name, light=light, translation=position, rotation=quaternion(rot))

    def _light(self, light):
        self.extensions.add(EXT_LIGHTS)
        self.lights.append(light)
        return len(self.lights) - 1

    def node(self, name, mesh=None, camera=None, light=None, children=(), root=True, **xform):
        """xform: translation / rotation / scale, or matrix (glTF node properties)."""
        n = {"name": name}
        if mesh is not None:
            n["mesh"] = mesh
        if camera is not None:
            n["camera"] = camera
        if light is not None:
            n["extensions"] = {EXT_LIGHTS: {"light": light}}
        if children:
            n["children"] = list(children)
        n.update({k: list(v) for k, v in xform.items()})
        self.nodes.append(n)
        if root:
            self.roots.append(len(self.nodes) - 1)
        return len(self.nodes) - 1

    def mesh_node(self, name, parts, flat=False, targets=None, **xform):
        return self.node(name, mesh=self.mesh(name, parts, flat, targets), **xform)

    def camera_node(self, name, eye, target, yfov, aspect=1.0, up=(0.0, 1.0, 0.0),
                    use_matrix=False):
        rot = look_rotation(eye, target, up)
        xform = ({"matrix": matrix_columns(rot, eye)} if use_matrix else
                 {"translation": eye, "rotation": quaternion(rot)})
        return self.node(name, camera=self.camera(name, yfov, aspect), **xform)

    # -- output
    def document(self):
        """The JSON; gltf_writer fills in "buffers" (the buffer's length and where it is)."""
        doc = {"asset": {"version": "2.0", "generator": "photonbound tools/make_scenes.py"}}
        if self.extensions:
            doc["extensionsUsed"] = sorted(self.extensions)
        doc.update({"scene": 0, "scenes": [{"nodes": self.roots}], "nodes": self.nodes,
                    "meshes": self.meshes, "materials": self.materials})
        if self.cameras:
            doc["cameras"] = self.cameras
        if self.lights:
            doc["extensions"] = {EXT_LIGHTS: {"lights": self.lights}}
        if self.animations:
            doc["animations"] = self.animations
        doc.update({"buffers": [], "bufferViews": self.buffer.views,
                    "accessors": self.buffer.accessors})
        return doc

    def write_gltf(self, path):
        gltf_writer.write_gltf(path, self.document(), self.buffer.data)

    def write_gltf_external(self, path):
        gltf_writer.write_gltf_external(path, self.document(), self.buffer.data)

    def write_glb(self, path):
        gltf_writer.write_glb(path, self.document(), self.buffer.data)


# ----------------------------------------------------------------------------- scenes

def build_cornell():
    b = GltfBuilder()
    white = b.lambertian("white", (0.75, 0.75, 0.75))
    red = b.lambertian("red", (0.63, 0.065, 0.05))
    green = b.lambertian("green", (0.14, 0.45, 0.09))
    lamp = b.lambertian("light", (0.0, 0.0, 0.0), radiance=40.0)
    glass = b.glass("glass", 1.5, thickness=0.7)
    mirror = b.mirror("mirror", (0.95, 0.95, 0.95))

    walls = box_faces((-1.0, 0.0, -1.0), (1.0, 2.0, 1.0), inward=True)  # +z left open
    b.mesh_node("walls", [(merge([walls["-y"], walls["+y"], walls["-z"]]), white),
                          (walls["-x"], red), (walls["+x"], green)])
    b.mesh_node("light", [(horizontal_quad((0.0, 1.98, 0.0), 0.15, 0.15, facing_up=False),
                           lamp)])
    sphere = uv_sphere((0.0, 0.0, 0.0), 0.35)  # placed by node translations
    b.mesh_node("glass_sphere", [(sphere, glass)], translation=(0.45, 0.35, 0.4))
    b.mesh_node("mirror_sphere", [(sphere, mirror)], translation=(-0.45, 0.35, -0.35))
    b.camera_node("camera", eye=(0.0, 1.0, 3.4), target=(0.0, 1.0, 0.0), yfov=0.78)
    return b


def build_cornell_heavy():
    """The default scene with the mirror sphere replaced by a ~1 M-triangle displaced sphere."""
    b = GltfBuilder()
    white = b.lambertian("white", (0.75, 0.75, 0.75))
    red = b.lambertian("red", (0.63, 0.065, 0.05))
    green = b.lambertian("green", (0.14, 0.45, 0.09))
    lamp = b.lambertian("light", (0.0, 0.0, 0.0), radiance=40.0)
    glass = b.glass("glass", 1.5, thickness=0.7)
    clay = b.lambertian("clay", (0.7, 0.6, 0.5))

    walls = box_faces((-1.0, 0.0, -1.0), (1.0, 2.0, 1.0), inward=True)
    b.mesh_node("walls", [(merge([walls["-y"], walls["+y"], walls["-z"]]), white),
                          (walls["-x"], red), (walls["+x"], green)])
    b.mesh_node("light", [(horizontal_quad((0.0, 1.98, 0.0), 0.15, 0.15, facing_up=False),
                           lamp)])
    b.mesh_node("glass_sphere", [(uv_sphere((0.0, 0.0, 0.0), 0.35), glass)],
                translation=(0.45, 0.35, 0.4))
    bumpy = displaced_sphere((0.0, 0.0, 0.0), 0.33, 1024, 512, 0.06, 9.0)
    b.mesh_node("bumpy_sphere", [(bumpy, clay)], translation=(-0.45, 0.37, -0.35))
    b.camera_node("camera", eye=(0.0, 1.0, 3.4), target=(0.0, 1.0, 0.0), yfov=0.78)
    return b


def svcm(p):
    """SmallVCM's z-up coordinates (src/scene.hxx) to glTF's y-up: (x, y, z) -> (x, z, -y)."""
    return (p[0], p[2], -p[1])


def build_smallvcm_twin():
    """SmallVCM's default scene (`smallvcm -s 0`: its Cornell box, both small balls, the sun)
    as glTF, for the benchmark's per-pass comparison with `smallvcm -a ppm` (issue 40): the same
    box, balls, light box and camera, axes turned to glTF's y-up. The floor is Lambertian of
    SmallVCM's total albedo 0.8 (its Phong lobe has no glTF twin); the balls are UV spheres."""
    b = GltfBuilder()
    white = b.lambertian("white", (0.803922,) * 3)
    floor = b.lambertian("floor", (0.8, 0.8, 0.8))
    green = b.lambertian("green", (0.156863, 0.803922, 0.172549))
    red = b.lambertian("red", (0.803922, 0.152941, 0.152941))
    blue = b.lambertian("blue", (0.156863, 0.172549, 0.803922))
    mirror = b.mirror("mirror", (1.0, 1.0, 1.0))
    glass = b.glass("glass", 1.6, thickness=1.0)
    lo, hi = (-1.27029, -1.25549, -1.28002), (1.28975, 1.30455, 1.28002)  # SmallVCM's box
    box_lo, box_hi = svcm(lo), svcm(hi)
    walls = box_faces(tuple(map(min, box_lo, box_hi)), tuple(map(max, box_lo, box_hi)),
                      inward=True)  # the front (+z here) is open, as in SmallVCM
    b.mesh_node("walls", [(walls["-y"], floor), (walls["-z"], blue), (walls["+y"], white),
                          (walls["-x"], green), (walls["+x"], red)])
    lamp_box = box_faces((-0.25, 1.26002, -0.25), (0.25, 1.28002, 0.25))  # not emitting in -s 0
    b.mesh_node("light_box", [(merge([lamp_box[f] for f in ("-x", "+x", "-y", "-z", "+z")]),
                               white)])
    small = 0.5  # SmallVCM's small balls, 2/7 of the box's width in from its side walls
    inset = 2.0 * (hi[0] - lo[0]) / 7.0
    wall_y, wall_z = 0.5 * (lo[1] + hi[1]), lo[2] + small
    ball = uv_sphere((0.0, 0.0, 0.0), small)
    b.mesh_node("mirror_ball", [(ball, mirror)],
                translation=svcm((lo[0] + inset, wall_y, wall_z)))
    b.mesh_node("glass_ball", [(ball, glass)], translation=svcm((hi[0] - inset, wall_y, wall_z)))
    # SmallVCM's DirectionalLight(-1, 1.5, -1): the light travels along that direction, with
    # irradiance (0.5, 0.2, 0) x 20.
    b.light_node("sun", b.directional_light("sun", 10.0, (1.0, 0.4, 0.0)), svcm((-1.0, 1.5, -1.0)))
    eye = svcm((-0.0439815, -4.12529, 0.222539))
    forward = svcm((0.00688625, 0.998505, -0.0542161))
    b.camera_node("camera", eye=eye, target=add(eye, forward), yfov=math.radians(45.0),
                  up=svcm((3.73896e-4, 0.0542148, 0.998529)))
    return b


def plane_point_parts(b):
    """Shared content of the plane_point family: (plane parts, light index)."""
    grey = b.lambertian("grey", (0.5, 0.5, 0.5))
    plane = horizontal_quad((0.0, 0.0, 0.0), 10.0, 10.0)
    return [(plane, grey)], b.point_light("point", 10.0)


PLANE_CAMERA = {"eye": (0.0, 3.0, 0.0), "target": (0.0, 0.0, 0.0), "yfov": 0.6,
                "up": (0.0, 0.0, -1.0)}  # looking straight down, image up = -z


def build_plane_point():
    b = GltfBuilder()
    parts, light = plane_point_parts(b)
    b.mesh_node("plane", parts)
    b.node("point", light=light, translation=(0.0, 1.0, 0.0))
    b.camera_node("camera", **PLANE_CAMERA)
    return b


def build_glossy_plane():
    """plane_point with glTF's metallic-roughness BRDF on the plane instead of a Lambertian."""
    b = GltfBuilder()
    glossy = b.material("glossy", (0.6, 0.6, 0.6), metallic=0.5, roughness=0.4)
    b.mesh_node("plane", [(horizontal_quad((0.0, 0.0, 0.0), 10.0, 10.0), glossy)])
    b.node("point", light=b.point_light("point", 10.0), translation=(0.0, 1.0, 0.0))
    b.camera_node("camera", **PLANE_CAMERA)
    return b


def build_nested():
    b = GltfBuilder()
    parts, light = plane_point_parts(b)
    child = b.node("plane", mesh=b.mesh("plane", parts), root=False,
                   translation=(0.0, 0.5, 0.0), scale=(0.5, 0.5, 0.5))
    b.node("plane_parent", children=[child], translation=(0.0, -1.0, 0.0),
           scale=(2.0, 2.0, 2.0))
    identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    b.node("point", light=light, matrix=matrix_columns(identity, (0.0, 1.0, 0.0)))
    b.camera_node("camera", use_matrix=True, **PLANE_CAMERA)
    return b


def build_closed_box():
    b = GltfBuilder()
    wall = b.lambertian("emissive_wall", (0.5, 0.5, 0.5), radiance=1.0)
    b.mesh_node("box", [(box((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0), inward=True), wall)])
    b.camera_node("camera", eye=(0.0, 0.0, 0.9), target=(0.0, 0.0, 0.0), yfov=1.0)
    return b


def build_closed_block():
    """The closed box with a block floating inside: every surface emits 1 and reflects 0.5,
    so the enclosure is still a furnace (L = 2 everywhere), and the block adds edges, creases
    and the silhouettes of one surface in front of another."""
    b = GltfBuilder()
    wall = b.lambertian("emissive_wall", (0.5, 0.5, 0.5), radiance=1.0)
    b.mesh_node("box", [(box((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0), inward=True), wall)])
    b.mesh_node("block", [(box((-0.45, -0.8, -0.6), (0.25, -0.25, 0.0)), wall)])
    b.camera_node("camera", eye=(0.0, 0.0, 0.9), target=(0.0, -0.3, 0.0), yfov=1.0)
    return b


def build_spot():
    b = GltfBuilder()
    floor = b.lambertian("floor", (0.7, 0.7, 0.7))
    b.mesh_node("floor", [(horizontal_quad((0.0, 0.0, 0.0), 2.0, 2.0), floor)])
    spot = b.spot_light("spot", 20.0, inner=0.3, outer=0.5)
    down = look_rotation((0.0, 2.0, 0.0), (0.0, 0.0, 0.0), up_hint=(0.0, 0.0, -1.0))
    b.node("spot", light=spot, translation=(0.0, 2.0, 0.0), rotation=quaternion(down))
    b.camera_node("camera", eye=(0.0, 1.5, 3.0), target=(0.0, 0.0, 0.0), yfov=0.8)
    return b


def build_glass_slab():
    b = GltfBuilder()
    floor = b.lambertian("floor", (0.8, 0.8, 0.8))
    glass = b.glass("glass", 1.5, thickness=0.2)
    lamp = b.lambertian("light", (0.0, 0.0, 0.0), radiance=50.0)
    b.mesh_node("floor", [(horizontal_quad((0.0, 0.0, 0.0), 2.0, 2.0), floor)])
    b.mesh_node("slab", [(box((-0.5, 0.8, -0.5), (0.5, 1.0, 0.5)), glass)])
    b.mesh_node("light", [(horizontal_quad((0.0, 1.9, 0.0), 0.1, 0.1, facing_up=False),
                           lamp)])
    b.camera_node("camera", eye=(0.0, 1.2, 2.5), target=(0.0, 0.0, 0.0), yfov=0.8)
    return b


def build_caustic():
    """Issue 39's caustic: a glass ball on a diffuse floor under a small lamp."""
    b = GltfBuilder()
    floor = b.lambertian("floor", (0.8, 0.8, 0.8))
    glass = b.glass("glass", 1.5, thickness=0.8)
    lamp = b.lambertian("light", (0.0, 0.0, 0.0), radiance=400.0)
    b.mesh_node("floor", [(horizontal_quad((0.0, 0.0, 0.0), 2.0, 2.0), floor)])
    b.mesh_node("ball", [(uv_sphere((0.0, 0.0, 0.0), 0.4), glass)], translation=(0.0, 0.4, 0.0))
    b.mesh_node("light", [(horizontal_quad((0.5, 2.0, -0.3), 0.05, 0.05, facing_up=False),
                           lamp)])
    b.camera_node("camera", eye=(0.0, 1.6, 2.4), target=(0.0, 0.25, 0.0), yfov=0.7,
                  aspect=4.0 / 3.0)
    return b


def build_indirect():
    """Issue 39's indirectly lit room: a lamp facing the back wall, the camera looking away."""
    b = GltfBuilder()
    white = b.lambertian("white", (0.7, 0.7, 0.7))
    red = b.lambertian("red", (0.6, 0.1, 0.08))
    lamp = b.lambertian("light", (0.0, 0.0, 0.0), radiance=60.0)
    walls = box_faces((-2.0, 0.0, -2.0), (2.0, 3.0, 2.0), inward=True)
    b.mesh_node("room", [(merge([walls["-y"], walls["+y"], walls["-z"], walls["+z"],
                                 walls["+x"]]), white), (walls["-x"], red)])
    # Facing -z, toward the back wall 0.4 m away: no surface the camera sees is lit directly.
    b.mesh_node("light", [(quad((0.0, 1.5, -1.6), (0.2, 0.0, 0.0), (0.0, -0.2, 0.0)), lamp)])
    b.mesh_node("block", [(box((0.3, 0.0, 0.6), (1.1, 0.8, 1.4)), white)])
    b.camera_node("camera", eye=(0.0, 1.4, -1.2), target=(0.0, 0.8, 2.0), yfov=0.9,
                  aspect=4.0 / 3.0)
    return b


def build_door_room():
    """Issue 39's room lit through a door: the lamp is in the next room."""
    b = GltfBuilder()
    white = b.lambertian("white", (0.7, 0.7, 0.7))
    lamp = b.lambertian("light", (0.0, 0.0, 0.0), radiance=40.0)
    # Two 4 x 3 x 4 m rooms side by side (x < 0 and x > 0) in one enclosure, split by a
    # 0.1 m wall with a 1 x 2 m door; each wall piece a closed box facing both rooms.
    b.mesh_node("rooms", [(box((-4.0, 0.0, -2.0), (4.0, 3.0, 2.0), inward=True), white)])
    wall = merge([box((-0.05, 0.0, -2.0), (0.05, 3.0, -0.5)),
                  box((-0.05, 0.0, 0.5), (0.05, 3.0, 2.0)),
                  box((-0.05, 2.0, -0.5), (0.05, 3.0, 0.5))])
    b.mesh_node("wall", [(wall, white)])
    # On the far room's ceiling, facing down: its light reaches the camera's room only
    # through the door, directly (a patch of floor) or after bounces.
    b.mesh_node("light", [(quad((-2.5, 2.99, 0.0), (0.25, 0.0, 0.0), (0.0, 0.0, 0.25)), lamp)])
    b.camera_node("camera", eye=(3.6, 1.6, 1.6), target=(0.0, 0.6, -0.4), yfov=0.9,
                  aspect=4.0 / 3.0)
    return b


def unlit_parts(b):
    """The unlit model: ground, box, sphere, mirror sphere (docs/gltf.md's example)."""
    ground = b.lambertian("ground", (0.8, 0.8, 0.8))
    red = b.lambertian("red", (0.75, 0.2, 0.12))
    blue = b.lambertian("blue", (0.15, 0.3, 0.7))
    chrome = b.mirror("chrome", (0.9, 0.9, 0.9))
    b.mesh_node("ground", [(horizontal_quad((0.0, 0.0, 0.0), 2.0, 2.0), ground)])
    b.mesh_node("box", [(box((-1.2, 0.0, -0.7), (-0.3, 0.9, 0.2)), red)])
    b.mesh_node("sphere", [(uv_sphere((0.0, 0.0, 0.0), 0.45), blue)],
                translation=(0.5, 0.45, -0.3))
    b.mesh_node("mirror_ball", [(uv_sphere((0.0, 0.0, 0.0), 0.3, 48, 24), chrome)],
                translation=(-0.1, 0.3, 0.75))


def build_unlit():
    b = GltfBuilder()
    unlit_parts(b)
    return b


def build_furnace():
    b = GltfBuilder()
    grey = b.lambertian("grey", (0.5, 0.5, 0.5))
    b.mesh_node("sphere", [(uv_sphere((0.0, 0.0, 0.0), 1.0, 48, 24), grey)], flat=True)
    b.camera_node("camera", eye=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), yfov=0.7)
    return b


SUN_TRAVEL = (math.sin(math.pi / 6), -math.cos(math.pi / 6), 0.0)  # 30 degrees from straight down


def build_sun():
    b = GltfBuilder()
    grey = b.lambertian("grey", (0.5, 0.5, 0.5))
    b.mesh_node("plane", [(horizontal_quad((0.0, 0.0, 0.0), 5.0, 5.0), grey)])
    b.light_node("sun", b.directional_light("sun", 2.0), SUN_TRAVEL)
    b.camera_node("camera", **PLANE_CAMERA)
    return b


# --corpus: files as exporters write them.

def build_exported():
    """No camera, no light, an animation, a morph target, an unimplemented extension."""
    b = GltfBuilder()
    unlit_parts(b)
    b.materials[1]["extensions"] = {"KHR_materials_specular": {"specularFactor": 0.5}}
    b.extensions.add("KHR_materials_specular")
    bump = lambda geo: [scale(n, 0.05) for n in geo.normals]
    b.mesh_node("blob", [(uv_sphere((0.0, 0.0, 0.0), 0.2, 24, 12), 2)], targets=bump,
                translation=(1.2, 0.2, 0.9))
    b.animate_translation(1, [0.0, 1.0], [(0.0, 0.0, 0.0), (0.0, 0.5, 0.0)])
    return b


def build_sun_spot():
    b = GltfBuilder()
    unlit_parts(b)
    b.light_node("sun", b.directional_light("sun", 3.0, (1.0, 0.95, 0.85)),
                 (-0.3, -1.0, -0.4))
    spot = b.spot_light("spot", 30.0, inner=0.2, outer=0.5)
    b.lights[spot]["range"] = 20.0
    b.light_node("spot", spot, (0.0, -1.0, 0.0), position=(0.5, 2.5, -0.3))
    b.camera_node("camera", eye=(1.5, 2.5, 4.5), target=(0.0, 0.4, 0.0), yfov=0.6)
    return b


def build_huge_ground():
    b = GltfBuilder()
    ground = b.lambertian("ground", (0.5, 0.5, 0.5))
    clay = b.lambertian("clay", (0.8, 0.6, 0.4))
    b.mesh_node("ground", [(horizontal_quad((0.0, 0.0, 0.0), 1e5, 1e5), ground)])
    b.mesh_node("box", [(box((-0.5, 0.0, -0.5), (0.5, 1.0, 0.5)), clay)])
    b.mesh_node("sphere", [(uv_sphere((0.0, 0.0, 0.0), 0.4), clay)], translation=(1.1, 0.4, 0.2))
    b.light_node("sun", b.directional_light("sun", 3.0), (-0.4, -1.0, -0.6))
    b.camera_node("camera", eye=(2.5, 1.8, 3.5), target=(0.3, 0.4, 0.0), yfov=0.7)
    return b


# ----------------------------------------------------------------------------- validation


class Invalid(Exception):
    pass


def check(cond, msg):
    if not cond:
        raise Invalid(msg)


def used_extensions(obj, found):
    if isinstance(obj, dict):
        found.update(obj.get("extensions", {}))
        for v in obj.values():
            used_extensions(v, found)
    elif isinstance(obj, list):
        for v in obj:
            used_extensions(v, found)
    return found


def validate_primitive(prim, where):
    """What the reader (tools/gltf_scene.py) accepts but these scenes must not have."""
    acc, pos = prim.position_accessor, prim.local_positions
    for c in range(3):
        check(acc["min"][c] == min(p[c] for p in pos) and acc["max"][c] == max(p[c] for p in pos),
              f"{where}: POSITION min/max do not match the data")
    acc, idx = prim.index_accessor, prim.local_indices
    check(acc is not None and acc["componentType"] == UINT, f"{where}: index type")
    check(len(idx) > 0, f"{where}: index count not a multiple of 3")
    check(prim.material is not None, f"{where}: bad material")
    nrm = prim.local_normals
    if nrm is not None:
        check(all(abs(length(n) - 1.0) < 1e-5 for n in nrm), f"{where}: normals not unit")
    for t in range(0, len(idx), 3):
        a, b, c = idx[t:t + 3]
        g = cross(sub(pos[b], pos[a]), sub(pos[c], pos[a]))
        check(length(g) > 1e-12, f"{where}: degenerate triangle {t // 3}")
        if nrm is not None:
            check(dot(g, add(add(nrm[a], nrm[b]), nrm[c])) > 0,
                  f"{where}: triangle {t // 3} winding disagrees with its normals")


def flatten(scene):
    """World-space content of a gltf_scene.Scene: {"prims": [(Material, [triangle]...)],
    "lights": [Light], "cameras": [Camera]}."""
    for node in scene.nodes:
        check(not ("matrix" in node.json and any(k in node.json for k in ("translation",
                                                                            "rotation", "scale"))),
              f"node {node.index}: matrix together with TRS")
    out = {"prims": [], "lights": list(scene.lights), "cameras": []}
    for inst in scene.meshes:
        for prim in inst.primitives:
            validate_primitive(prim, f"mesh {inst.mesh} prim {prim.index}")
            out["prims"].append((prim.material, prim.triangles))
    for cam in scene.cameras:
        check(cam.type == "perspective" and cam.yfov > 0, "camera")
        out["cameras"].append(cam)
    return out


def tri_normal(t):
    return normalize(cross(sub(t[1], t[0]), sub(t[2], t[0])))


def closed_volume(tris):
    """Signed volume of a closed, consistently wound mesh (> 0 when wound outward)."""
    key = lambda p: tuple(round(x, 6) for x in p)
    edges = {}
    for t in tris:
        for a, b in ((0, 1), (1, 2), (2, 0)):
            e = (key(t[a]), key(t[b]))
            edges[e] = edges.get(e, 0) + 1
    check(all(n == 1 and edges.get((b, a)) == 1 for (a, b), n in edges.items()),
          "mesh is not closed with consistent winding")
    return sum(dot(t[0], cross(t[1], t[2])) for t in tris) / 6.0


def near(a, b, eps=1e-6):
    return all(abs(x - y) <= eps for x, y in zip(a, b))


def same_content(a, b):
    """World-space equality of two flattened scenes (geometry, materials, lights, cameras)."""
    if len(a["prims"]) != len(b["prims"]) or len(a["lights"]) != len(b["lights"]):
        return False
    for (ma, ta), (mb, tb) in zip(a["prims"], b["prims"]):
        if ma.json != mb.json or len(ta) != len(tb):
            return False
        if not all(near(p, q) for x, y in zip(ta, tb) for p, q in zip(x, y)):
            return False
    for la, lb in zip(a["lights"], b["lights"]):
        if not (near(la.position, lb.position) and near(la.direction, lb.direction) and
                la.json == lb.json):
            return False
    return len(a["cameras"]) == len(b["cameras"]) and all(
        near(x.position, y.position) and near(x.forward, y.forward) and near(x.up, y.up) and
        x.json.get("perspective") == y.json.get("perspective")
        for x, y in zip(a["cameras"], b["cameras"]))


def check_lambertian(s, names=None):
    """The analytic answers (and the PPM golden checksums) need pure Lambertian surfaces: glTF
    says so with metallic 0 and KHR_materials_specular specularFactor 0."""
    for mat, _ in s["prims"]:
        if (names is None and mat.model != "dielectric") or (names and mat.name in names):
            check(mat.model == "lambertian", f"material {mat.name} must be Lambertian "
                  "(metallicFactor 0, KHR_materials_specular specularFactor 0)")


def check_cornell(s):
    check_lambertian(s, ("white", "red", "green", "light"))
    for mat, tris in s["prims"]:
        if mat.name in ("white", "red", "green"):
            check(all(dot(tri_normal(t), sub((0, 1, 0), t[0])) > 0 for t in tris),
                  "Cornell walls must face into the box")
        if mat.name == "light":
            check(all(near(tri_normal(t), (0, -1, 0)) for t in tris), "light must face -y")


def check_faces_up(s):
    check_lambertian(s)
    for mat, tris in s["prims"]:
        if mat.model != "dielectric" and not any(mat.emission):
            check(all(near(tri_normal(t), (0, 1, 0)) for t in tris), "floor must face +y")


def check_closed_box(s):
    check_lambertian(s)
    check(abs(closed_volume(s["prims"][0][1]) + 8.0) < 1e-6, "box must be closed, inward")


def check_closed_block(s):
    check_lambertian(s)
    check(abs(closed_volume(s["prims"][0][1]) + 8.0) < 1e-6, "box must be closed, inward")
    check(abs(closed_volume(s["prims"][1][1]) - 0.7 * 0.55 * 0.6) < 1e-6,
          "block must be closed, outward")


def check_spot(s):
    check_faces_up(s)
    check(near(s["lights"][0].direction, (0, -1, 0)), "spot must point down")


def check_sun(s):
    check_faces_up(s)
    check(near(s["lights"][0].direction, normalize(SUN_TRAVEL)), "sun direction")


def check_furnace(s):
    check(closed_volume(s["prims"][0][1]) > 0, "furnace sphere must be closed, outward")


SCENE_CHECKS = {"cornell.gltf": check_cornell, "sun.gltf": check_sun,
                "furnace.gltf": check_furnace, "cornell_heavy.glb": check_cornell,
                "closed_box.gltf": check_closed_box, "closed_block.gltf": check_closed_block,
                "spot.gltf": check_spot, "glass_slab.gltf": check_faces_up,
                "plane_point.gltf": check_faces_up}
# No camera; no light but for furnace.gltf, which has a camera and no light.
WITHOUT_CAMERA_OR_LIGHT = ("unlit.gltf", "exported.glb")
SAME_AS_PLANE_POINT = ("plane_point.glb", "plane_point_external.gltf", "nested.gltf")


def fmt_vec(v):
    return "(" + ", ".join(f"{x:.3g}" if abs(x) > 1e-9 else "0" for x in v) + ")"


def validate(path):
    """Validates one written file; returns (flattened scene, one-line summary)."""
    scene = gltf_scene.load(path)
    doc = scene.json
    check(doc["asset"]["version"] == "2.0", "asset.version")
    undeclared = used_extensions(doc, set()) - set(doc.get("extensionsUsed", []))
    check(not undeclared, f"extensions not in extensionsUsed: {sorted(undeclared)}")
    s = flatten(scene)
    for mat, tris in s["prims"]:
        pbr = mat.json["pbrMetallicRoughness"]
        check("metallicFactor" in pbr, f"material {mat.name}: metallicFactor must be explicit")
        if mat.model == "dielectric":
            check(closed_volume(tris) > 0, f"glass {mat.name}: must be closed, outward")
    bare = path.name in WITHOUT_CAMERA_OR_LIGHT
    check(len(s["cameras"]) == (0 if bare else 1), "exactly one camera expected" if not bare
          else "no camera expected")
    emitters = [(mat, tris) for mat, tris in s["prims"] if any(mat.emission)]
    check(bool(s["lights"] or emitters) != bare or path.name == "furnace.gltf",
          "no light expected" if bare else "no light")
    SCENE_CHECKS.get(path.name, lambda _: None)(s)

    tris = sum(len(t) for _, t in s["prims"])
    lights = [f"{l.type} I={l.json['intensity']:g} at {fmt_vec(l.position)}" for l in s["lights"]]
    lights += [f"emitter '{m.name}' Le={max(m.emission):g} "
               f"area={sum(length(cross(sub(t[1], t[0]), sub(t[2], t[0]))) / 2 for t in ts):.3g}"
               for m, ts in emitters]
    lights += [f"{l.type} E={l.json['intensity']:g} along {fmt_vec(l.direction)}"
               for l in s["lights"] if l.type == "directional"]
    lights = [x for x in lights if not x.startswith("directional I=")] or ["no light"]
    view = "no camera"
    if s["cameras"]:
        cam = s["cameras"][0]
        view = (f"camera {fmt_vec(cam.position)} -> {fmt_vec(cam.forward)} yfov {cam.yfov:g}")
    summary = (f"{path.name:27s} {tris:5d} tris, {len(s['prims'])} prims, "
               f"{len(doc['materials'])} mats, {'; '.join(lights)}; {view}, "
               f"{path.stat().st_size} bytes")
    return s, summary


# ----------------------------------------------------------------------------- main

OUTPUTS = [  # (file name, builder, writer)
    ("cornell.gltf", build_cornell, GltfBuilder.write_gltf),
    ("plane_point.gltf", build_plane_point, GltfBuilder.write_gltf),
    ("closed_box.gltf", build_closed_box, GltfBuilder.write_gltf),
    ("closed_block.gltf", build_closed_block, GltfBuilder.write_gltf),
    ("spot.gltf", build_spot, GltfBuilder.write_gltf),
    ("plane_point.glb", build_plane_point, GltfBuilder.write_glb),
    ("plane_point_external.gltf", build_plane_point, GltfBuilder.write_gltf_external),
    ("glass_slab.gltf", build_glass_slab, GltfBuilder.write_gltf),
    ("nested.gltf", build_nested, GltfBuilder.write_gltf),
    ("glossy_plane.gltf", build_glossy_plane, GltfBuilder.write_gltf),
    ("unlit.gltf", build_unlit, GltfBuilder.write_gltf),
    ("furnace.gltf", build_furnace, GltfBuilder.write_gltf),
    ("sun.gltf", build_sun, GltfBuilder.write_gltf),
    ("caustic.gltf", build_caustic, GltfBuilder.write_gltf),
    ("indirect_room.gltf", build_indirect, GltfBuilder.write_gltf),
    ("door_room.gltf", build_door_room, GltfBuilder.write_gltf),
]

CORPUS = [
    ("exported.glb", build_exported, GltfBuilder.write_glb),
    ("sun_spot.gltf", build_sun_spot, GltfBuilder.write_gltf),
    ("huge_ground.gltf", build_huge_ground, GltfBuilder.write_gltf),
]


HEAVY = ("cornell_heavy.glb", build_cornell_heavy, GltfBuilder.write_glb)
SMALLVCM = ("smallvcm_twin.gltf", build_smallvcm_twin, GltfBuilder.write_gltf)


def write_into(out_dir, outputs):
    """--heavy DIR, --corpus DIR: writes and validates only those files, into DIR."""
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, build, write in outputs:
        write(build(), out_dir / name)
        try:
            _, summary = validate(out_dir / name)
        except gltf_scene.GltfError as e:
            raise SystemExit(f"make_scenes: {name}: INVALID: {e.detail}")
        except (Invalid, KeyError, ValueError, struct.error) as e:
            raise SystemExit(f"make_scenes: {name}: INVALID: {e}")
        print(summary)


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.make_scenes",
                                 description=__doc__.split("\n\n")[0])
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--heavy", metavar="DIR", help="write only cornell_heavy.glb, into DIR")
    where.add_argument("--smallvcm", metavar="DIR", help="write only smallvcm_twin.gltf (the "
                       "benchmark's twin of SmallVCM's scene), into DIR")
    where.add_argument("--corpus", metavar="DIR", help="write only the exporter-style files of "
                       "tests/gltf/test_corpus.cpp, into DIR")
    args = ap.parse_args()
    if args.heavy or args.corpus or args.smallvcm:
        write_into(Path(args.heavy or args.corpus or args.smallvcm),
                   [HEAVY] if args.heavy else [SMALLVCM] if args.smallvcm else CORPUS)
        return
    out_dir = Path(REPO) / "scenes"
    out_dir.mkdir(exist_ok=True)
    for name, build, write in OUTPUTS:
        write(build(), out_dir / name)
    flat = {}
    for name, _, _ in OUTPUTS:
        try:
            flat[name], summary = validate(out_dir / name)
        except gltf_scene.GltfError as e:
            raise SystemExit(f"make_scenes: {name}: INVALID: {e.detail}")
        except (Invalid, KeyError, ValueError, struct.error) as e:
            raise SystemExit(f"make_scenes: {name}: INVALID: {e}")
        print(summary)
    for name in SAME_AS_PLANE_POINT:
        if not same_content(flat[name], flat["plane_point.gltf"]):
            raise SystemExit(f"make_scenes: {name}: world-space content differs from "
                             "plane_point.gltf")
    print(f"all {len(OUTPUTS)} scenes valid; {', '.join(SAME_AS_PLANE_POINT)} "
          "match plane_point.gltf in world space")


if __name__ == "__main__":
    main()
