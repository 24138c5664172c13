"""The Blender side of tools.cycles_side_by_side: run by Blender, not by python3.

  blender --background --factory-startup --python tools/cycles_peer.py -- JSON

JSON (one argument) holds: scene (a glTF path), output (an EXR path), width, height, from, at,
up (glTF's world space, y up), fov (vertical, degrees), sky (the uniform sky's radiance, 0 for
none), samples and seed; lambertian (the names of the materials photonbound reads as
Lambertian), specular (name -> KHR_materials_specular's factor), one_sided (the emissive
materials that are not doubleSided) and principled (keep Blender's import as it is). The file
is imported by Blender's glTF importer with its lights in the importer's compatibility units
(convert_lighting_mode COMPAT: a point light's W/sr as glTF gives them, photonbound's
reading), the materials matched (match_materials), a camera is made for the view photonbound
rendered, and Cycles renders it on the CPU with a box pixel filter, no clamping, no denoising,
caustics on and 64 bounces of every kind; the EXR is scene-linear RGBA (alpha: the share of
the pixel a surface covers).
"""

import json
import math
import sys

import bpy
import mathutils


def to_blender(p):
    # The importer turns glTF's y-up into Blender's z-up: (x, y, z) -> (x, -z, y).
    x, y, z = p
    return mathutils.Vector((x, -z, y))


def front_only(mat, socket):
    """Multiplies what drives `socket` (an emission strength) by 1 - Backfacing: glTF's
    emitters are one-sided unless doubleSided, Cycles' meshes emit from both sides (a lamp
    under a ceiling would light the ceiling from its back)."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    geometry = nodes.new("ShaderNodeNewGeometry")
    front = nodes.new("ShaderNodeMath")
    front.operation = "SUBTRACT"
    front.inputs[0].default_value = 1.0
    links.new(geometry.outputs["Backfacing"], front.inputs[1])
    scaled = nodes.new("ShaderNodeMath")
    scaled.operation = "MULTIPLY"
    scaled.inputs[0].default_value = socket.default_value
    for link in list(socket.links):
        links.new(link.from_socket, scaled.inputs[0])
    links.new(front.outputs[0], scaled.inputs[1])
    links.new(scaled.outputs[0], socket)


def match_materials(lambertian, specular, one_sided):
    """Blender 3.4's importer reads neither KHR_materials_specular nor a specular factor of 0,
    which is how glTF says "Lambertian": every Principled BSDF gets Specular 0.5 (F0 0.04) and
    Disney's diffuse with its retro-reflection. A material photonbound reads as Lambertian gets
    Cycles' Diffuse BSDF (Lambert) with the same colour, texture links kept; any other gets
    Specular = 0.5 x specularFactor. Without it a white Cornell box is 25-30% brighter in
    Cycles. One-sided emitters emit from their front only (front_only)."""
    for mat in bpy.data.materials:
        if not mat.node_tree:
            continue
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        for node in list(nodes):
            if node.type != "BSDF_PRINCIPLED":
                continue
            if mat.name in lambertian:
                diffuse = nodes.new("ShaderNodeBsdfDiffuse")
                base = node.inputs["Base Color"]
                diffuse.inputs["Color"].default_value = base.default_value
                for link in list(base.links):
                    links.new(link.from_socket, diffuse.inputs["Color"])
                out = diffuse.outputs[0]
                emit_colour = node.inputs["Emission"]
                emit_strength = node.inputs["Emission Strength"]
                if emit_colour.links or max(emit_colour.default_value[:3]) > 0.0:
                    # The Principled node carried the emission too: Diffuse + Emission.
                    emission = nodes.new("ShaderNodeEmission")
                    emission.inputs["Color"].default_value = emit_colour.default_value
                    emission.inputs["Strength"].default_value = emit_strength.default_value
                    for link in list(emit_colour.links):
                        links.new(link.from_socket, emission.inputs["Color"])
                    for link in list(emit_strength.links):
                        links.new(link.from_socket, emission.inputs["Strength"])
                    if mat.name in one_sided:
                        front_only(mat, emission.inputs["Strength"])
                    add = nodes.new("ShaderNodeAddShader")
                    links.new(out, add.inputs[0])
                    links.new(emission.outputs[0], add.inputs[1])
                    out = add.outputs[0]
                for link in list(node.outputs[0].links):
                    links.new(out, link.to_socket)
            else:
                if mat.name in specular:
                    node.inputs["Specular"].default_value = 0.5 * specular[mat.name]
                emit = node.inputs["Emission"]
                if mat.name in one_sided and (emit.links or max(emit.default_value[:3]) > 0.0):
                    front_only(mat, node.inputs["Emission Strength"])


def main():
    args = json.loads(sys.argv[sys.argv.index("--") + 1])
    # Debian 12's Blender 3.4 glTF importer uses numpy.bool, an alias NumPy 1.24 (Debian's)
    # removed: it fails on every file without it.
    import numpy
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=args["scene"], convert_lighting_mode="COMPAT")
    if not args.get("principled"):
        match_materials(set(args.get("lambertian", [])), args.get("specular", {}),
                        set(args.get("one_sided", [])))
    scene = bpy.context.scene

    eye, at, up = to_blender(args["from"]), to_blender(args["at"]), to_blender(args["up"])
    data = bpy.data.cameras.new("photonbound view")
    cam = bpy.data.objects.new("photonbound view", data)
    scene.collection.objects.link(cam)
    forward = (at - eye).normalized()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    rot = mathutils.Matrix(((right.x, true_up.x, -forward.x), (right.y, true_up.y, -forward.y),
                            (right.z, true_up.z, -forward.z)))
    cam.matrix_world = mathutils.Matrix.Translation(eye) @ rot.to_4x4()
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(args["fov"])
    data.clip_start = args.get("clip_start", 1e-3)
    data.clip_end = args.get("clip_end", 1e6)
    scene.camera = cam

    world = bpy.data.worlds.new("photonbound sky")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs[0].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs[1].default_value = float(args["sky"])
    scene.world = world

    render = scene.render
    render.engine = "CYCLES"
    render.resolution_x, render.resolution_y = args["width"], args["height"]
    render.resolution_percentage = 100
    render.film_transparent = True
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = args["samples"]
    cycles.seed = args.get("seed", 0)
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    for bounces in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                    "transparent_max_bounces"):
        setattr(cycles, bounces, 64)
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.exposure = 0.0
    render.image_settings.file_format = "OPEN_EXR"
    render.image_settings.color_depth = "32"
    render.image_settings.color_mode = "RGBA"
    render.filepath = args["output"]
    bpy.ops.render.render(write_still=True)


main()
