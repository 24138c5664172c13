"""The closed-form answers the tools compute, in one place.

  exact_plane   L = rho/pi I cos(theta) / d^2: a horizontal Lambertian plane under point
                lights (scenes/plane_point.gltf and its family)
  exact_box     L = Le / (1 - rho): anywhere inside a closed box of emitting Lambertian walls
                (scenes/closed_box.gltf)
  exact_image   either of them per pixel, at the pixel centres or averaged over each pixel
  expected_abs_noise  E|X| = sqrt(2/pi) sd of normal noise of standard deviation sd

The camera, lights, reflectance and emission are read from the scene's glTF file (Gltf, the
reader tools/gltf_scene.py in numpy arrays), and camera rays are made as src/scene/camera.cpp makes
them. The C++ tests have their own copies of these formulas (tests/analytic.h,
tests/reference_truth.h): a change to one side needs the same change to the other.
"""

import math

import numpy as np

from . import gltf_scene
from .common import ToolError


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
    """Unit directions through the pixel centres, (height, width, 3), as src/scene/camera.cpp makes
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


def _lambertian(gltf, material, what):
    if material is None:
        raise ToolError(f"{gltf.path}: the {what} has no material")
    if material.model != "lambertian":
        raise ToolError(f"{gltf.path}: the {what}'s material is not plain Lambertian")
    return np.array(material.base_color, float)


def exact_plane(gltf, width, height):
    """L = rho/pi I cos(theta) / d^2 on a horizontal plane under point lights (scenes/README)."""
    meshes = gltf.mesh_instances()
    if len(meshes) != 1 or len(meshes[0][2]) != 1:
        raise ToolError(f"{gltf.path}: expected a single one-primitive plane mesh")
    lo, hi, (material,) = meshes[0]
    if hi[1] - lo[1] > 1e-9 * max(1.0, float(np.max(hi - lo))):
        raise ToolError(f"{gltf.path}: the mesh is not a horizontal plane")
    rho = _lambertian(gltf, material, "plane")
    if any(material.emission):
        raise ToolError(f"{gltf.path}: the plane emits light")
    lights = gltf.point_lights()
    if not lights:
        raise ToolError(f"{gltf.path}: has no point light")
    cam = gltf.camera()
    o = cam["position"]
    d = camera_rays(cam, width, height)
    y = lo[1]
    if not (o[1] > y and all(lp[1] > y for lp, _ in lights)):
        raise ToolError(f"{gltf.path}: camera and lights must be above the plane")
    t = (y - o[1]) / d[..., 1]  # camera ray hits the plane where the height is y
    p = o + t[..., None] * d
    on_plane = (t > 0) & np.all((p[..., [0, 2]] >= lo[[0, 2]]) & (p[..., [0, 2]] <= hi[[0, 2]]),
                                axis=-1)
    radiance = np.zeros((height, width, 3))
    for lp, intensity in lights:
        v = lp - p
        dist2 = np.sum(v * v, axis=-1)
        cos = v[..., 1] / np.sqrt(dist2)  # the plane's normal is +y (it faces the camera)
        radiance += (rho / math.pi)[None, None, :] * intensity[None, None, :] * (
            cos / dist2)[..., None]
    radiance[~on_plane] = 0.0  # rays that miss see the black background
    return radiance


def exact_box(gltf, width, height):
    """L = Le / (1 - rho) everywhere inside a closed box of emitting Lambertian walls."""
    meshes = gltf.mesh_instances()
    if len(meshes) != 1:
        raise ToolError(f"{gltf.path}: expected a single box mesh")
    lo, hi, materials = meshes[0]
    first = materials[0]
    if any(m is not first for m in materials):
        raise ToolError(f"{gltf.path}: the walls must share one material")
    rho = _lambertian(gltf, first, "box")
    emission = np.array(first.emission, float)
    o = gltf.camera()["position"]
    if not np.all((o > lo) & (o < hi)):
        raise ToolError(f"{gltf.path}: the camera is not inside the box")
    return np.broadcast_to(emission / (1.0 - rho), (height, width, 3)).copy()


EXACT = {"plane": exact_plane, "box": exact_box}


def exact_image(kind, gltf, width, height, sub=1):
    """The exact answer of `kind` ("plane" or "box") per pixel: at the pixel centres (sub = 1),
    or averaged over sub x sub stratified positions in each pixel. The centres of a sub-times
    finer image are exactly those positions ((x + (i + 0.5) / sub) / width), so its blocks
    average to the pixel-area value."""
    fine = EXACT[kind](gltf, width * sub, height * sub)
    return fine.reshape(height, sub, width, sub, 3).mean(axis=(1, 3))


def expected_abs_noise(sd):
    """The mean absolute error E|X| = sqrt(2/pi) sd of zero-mean normal noise of standard
    deviation sd (elementwise)."""
    return np.sqrt(2.0 / np.pi) * sd
