#!/usr/bin/python3
"""ctest entries for the Python tools, the package tools/ (registered in tests/CMakeLists.txt).

Each tool runs as `python3 -m tools.<name>` from the repository root, as users run it; the
shared modules (tools.exr, tools.cli, tools.analytic, tools.gltf_scene, tools.gltf_writer) are
imported.

  tools_test.py smoke --photonbound EXE       a tiny study (plane, 16x16, two targets, both
                                             confidences): the table and plots are written and
                                             the table agrees with `photonbound compare --json`,
                                             and references and renders have the channels of
                                             src/estimator/channels.def; then the Cornell
                                             sweep, whose shipped reference must be 10x below
                                             its smallest actual error; tools.claim_check's row
                                             against the same renders and compare; then the
                                             glTF reader (tools.gltf_scene) on .gltf, .glb,
                                             external buffers, a node hierarchy and
                                             interleaved data
  tools_test.py bad-input --photonbound EXE  missing files, wrong channels, bad options and
                                             unreadable glTF end with one line on stderr and a
                                             non-zero exit
  tools_test.py corpus --photonbound EXE     tools.make_corpus's Blender-style files (rough
                                             metals, textures with transforms, emissive
                                             textures, thin and volumetric glass, a double-sided
                                             emitter, a cut-out) render with exit 0 under both
                                             methods, print exactly the warnings make_corpus
                                             expects, and give finite images whose mean
                                             radiance lies in the expected range
"""

import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
import numpy as np

from tools import analytic, cli, exr, gltf_scene, gltf_writer, make_corpus, study  # noqa: E402
from tools.common import ToolError  # noqa: E402

PYTHON = sys.executable
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message, file=sys.stderr)


def run_tool(tool, *args):
    """`python3 -m tools.TOOL ARGS...` from the repository root (paths in ARGS are absolute)."""
    return subprocess.run([PYTHON, "-m", f"tools.{tool}", *args], cwd=REPO, capture_output=True,
                          text=True)


def table_rows(path):
    lines = [l for l in open(path, encoding="utf-8") if l.startswith("|")]
    header = [c.strip() for c in lines[0].strip().strip("|").split("|")]
    return header, [dict(zip(header, (c.strip() for c in l.strip().strip("|").split("|"))))
                    for l in lines[2:]]


def check_png(path):
    if not os.path.isfile(path):
        check(False, f"{path} was not written")
        return
    with open(path, "rb") as f:
        check(f.read(8) == PNG_MAGIC, f"{path} is not a PNG")
    spec = exr.need_oiio().ImageInput.open(path)
    check(spec is not None and spec.spec().width >= 64 and spec.spec().height >= 64,
          f"{path}: unreadable or tiny")
    if spec is not None:
        spec.close()


def smoke(exe, tmp):
    out = os.path.join(tmp, "study")
    targets = [0.03, 0.015]
    p = run_tool("study", out, "--scenes", "plane", "--targets", ",".join(map(str, targets)),
                 "--resolution", "16x16", "--photonbound", exe)
    if p.returncode != 0:
        check(False, f"tools.study failed ({p.returncode}): {p.stderr.strip()}")
        return
    header, rows = table_rows(os.path.join(out, "table.md"))
    check(header == ["scene", "confidence", "target", "actual mean error", "specified / actual",
                     "passes", "photons", "seconds", "coverage", "stop"],
          f"table header is {header}")
    check(len(rows) == 4, f"expected 4 rows (2 confidences x 2 targets), got {len(rows)}")
    with open(os.path.join(out, "results.json"), encoding="utf-8") as f:
        results = json.load(f)
    check(len(results) == len(rows), "results.json and table.md differ in rows")
    ref = os.path.join(out, "references", "plane_16x16_exact.exr")
    layout = sorted(exr.channel_names())
    check(sorted(exr.read_exr(ref).planes) == layout,
          f"{ref}: channels {sorted(exr.read_exr(ref).planes)}, not {layout}")
    for row in rows:
        conf = int(row["confidence"].rstrip("%"))
        target = float(row["target"])
        path = os.path.join(out, "runs", f"plane_c{conf}_t{target:g}.exr")
        check(os.path.isfile(path), f"{path} missing")
        # Measured again here, independently of the study.
        c = cli.compare_json(exe, path, ref)
        actual = float(row["actual mean error"])
        check(abs(actual - c["mean_abs_error"]) <= 5e-4 * c["mean_abs_error"],
              f"{path}: table says actual {actual}, compare says {c['mean_abs_error']}")
        check(abs(float(row["coverage"]) - c["coverage"]) <= 5e-4,
              f"{path}: table says coverage {row['coverage']}, compare says {c['coverage']}")
        check(abs(float(row["specified / actual"]) - target / c["mean_abs_error"]) <=
              0.005 + 1e-3 * target / c["mean_abs_error"], f"{path}: specified / actual is off")
        img = exr.read_exr(path)
        check(sorted(img.planes) == layout, f"{path}: channels {sorted(img.planes)}, not {layout}")
        meta = img.metadata
        passes = int(meta["photonbound:passes_done"])
        check(int(row["passes"]) == passes, f"{path}: passes {row['passes']} vs {passes}")
        check(float(row["photons"]) == float(f"{int(meta['photonbound:photons_emitted']):.3g}"),
              f"{path}: photons {row['photons']}")
        log = cli.read_log(path[:-4] + ".jsonl")
        check(log[-1]["pass"] == passes, f"{path}: the log ends at pass {log[-1]['pass']}")
        check(abs(log[-1]["mae"] - c["mean_abs_error"]) <= 1e-6 * max(1.0, c["mean_abs_error"]),
              f"{path}: the log's last mae differs from compare")
        # A stop at the target means the render's own mean bound met it.
        if row["stop"] == "target-error":
            check(float(meta["photonbound:mean_error_bound"]) <= target,
                  f"{path}: stopped for the target with a mean bound above it")
    for name in ("convergence_time.png", "convergence_passes.png", "convergence_sweep.png"):
        check_png(os.path.join(out, name))
    for conf in (50, 90):
        for kind in ("radiance", "bound", "noise_bias", "bounded"):
            check_png(os.path.join(out, "views", f"plane_c{conf}_t{min(targets):g}_{kind}.png"))
    leftovers = [f for _, _, fs in os.walk(out) for f in fs if f.startswith(".")]
    check(not leftovers, f"temporary files left behind: {leftovers}")
    cornell_reference_margin(exe, tmp)
    adaptive_study(exe, tmp)
    claim_check(exe, tmp)
    mitsuba_translation(tmp)
    cycles_reading(exe, tmp)
    gltf_reading(tmp)


def claim_check(exe, tmp):
    """tools.claim_check on the plane under a point light (16x16, a loose target, a longer render of 3x): its row
    agrees with `photonbound compare` of the same two renders redone, and its verdict with its
    own figures (the renders are deterministic: same seeds, same images)."""
    scene = os.path.join(REPO, "scenes", "plane_point.gltf")
    rows_json = os.path.join(tmp, "claims.json")
    p = run_tool("claim_check", scene, "--target", "0.05", "--resolution", "16x16", "--factor",
                 "3", "--photonbound", exe, "--json", rows_json)
    check(p.returncode == 0, f"tools.claim_check: {p.stderr.strip()}")
    if p.returncode != 0:
        return
    (row,) = json.load(open(rows_json))
    a, b = os.path.join(tmp, "cc_stop.exr"), os.path.join(tmp, "cc_long.exr")
    base = [exe, "render", scene, "--resolution", "16x16", "--progress"]
    subprocess.run(base + ["-o", a, "--target-error", "0.05", "--time", "60", "--seed", "1"],
                   check=True, capture_output=True)
    subprocess.run(base + ["-o", b, "--passes", str(3 * row["passes"]), "--time", "150", "--seed",
                           "2"], check=True, capture_output=True)
    c = json.loads(subprocess.run([exe, "compare", a, b, "--json"], check=True,
                                  capture_output=True, text=True).stdout)
    check(row["mae"] == c["mean_abs_error"],
          f"tools.claim_check: mae {row['mae']} but compare says {c['mean_abs_error']}")
    own = 0.75 * row["long_claim"]
    want = math.sqrt(max(0.0, row["mae"] ** 2 - own ** 2))
    check(abs(row["actual"] - want) <= 1e-12 * max(1.0, want),
          f"tools.claim_check: actual {row['actual']}, expected {want}")
    verdict = ("cut" if row["stop"] != "target-error"
               else "within" if row["actual"] <= row["claim"] else "exceeded")
    check(row["verdict"] == verdict, f"tools.claim_check: verdict {row['verdict']}, not {verdict}")


def adaptive_study(exe, tmp):
    """tools.adaptive_study's table says what the renders it made say: one row per target, each
    mode's passes as the EXR records them, the actual error as compare measures it."""
    out = os.path.join(tmp, "adaptive")
    p = run_tool("adaptive_study", out, "--scenes", "plane", "--targets", "0.03",
                 "--resolution", "16x16", "--modes", "none,radius+photons", "--photonbound", exe)
    if p.returncode != 0:
        check(False, f"tools.adaptive_study failed ({p.returncode}): {p.stderr.strip()}")
        return
    header, rows = table_rows(os.path.join(out, "table.md"))
    check(len(rows) == 1 and header[0] == "target", f"adaptive table: {header}, {rows}")
    with open(os.path.join(out, "results.json"), encoding="utf-8") as f:
        results = json.load(f)
    check([r["mode"] for r in results] == ["none", "radius+photons"], f"modes {results}")
    ref = os.path.join(out, "runs", "plane_16x16_exact_area.exr")
    for r in results:
        path = os.path.join(out, "runs", f"plane_t0.03_{r['mode']}.exr")
        meta = exr.read_exr(path).metadata
        check(meta["photonbound:adaptive"] == r["mode"].replace("+", ","),
              f"{path}: adaptive is not {r['mode']}")
        check(int(meta["photonbound:passes_done"]) == r["passes"], f"{path}: passes differ")
        actual = cli.compare_json(exe, path, ref)["mean_abs_error"]
        check(abs(actual - r["actual"]) <= 1e-9 * max(1.0, actual), f"{path}: actual differs")
        check(rows[0][f"{r['mode']}: passes"] == str(r["passes"]),
              f"table passes for {r['mode']}")


def mitsuba_translation(tmp):
    """tools.mitsuba_side_by_side's translation for the peer (Mitsuba itself never runs in CI):
    the caustic's meshes go out as PLY files with every triangle, its materials as the peer
    reads them; a glossy material is refused by name; and its fit is exact on a power law."""
    from tools import mitsuba_side_by_side as mss
    out = os.path.join(tmp, "mitsuba")
    os.makedirs(out, exist_ok=True)
    desc = json.load(open(mss.translate(os.path.join(REPO, "scenes", "caustic.gltf"), out, 32,
                                        24), encoding="utf-8"))
    kinds = sorted(m["material"]["kind"] for m in desc["meshes"])
    check(kinds == ["dielectric", "diffuse", "diffuse"], f"caustic materials {kinds}")
    scene = gltf_scene.load(os.path.join(REPO, "scenes", "caustic.gltf"))
    want = [len(p.indices) // 3 for m in scene.meshes for p in m.primitives]
    for m, n in zip(desc["meshes"], want):
        with open(m["ply"], "rb") as f:
            data = f.read()
        head = data[:data.index(b"end_header\n")].decode("ascii")
        faces = int(head.split("element face ")[1].split()[0])
        check(faces == n, f"{m['ply']}: {faces} faces, the file has {n}")
        vertices = int(head.split("element vertex ")[1].split()[0])
        stride = 24 if m["smooth"] else 12
        size = len(data) - len(head) - len("end_header\n")
        check(size == vertices * stride + faces * 13, f"{m['ply']}: {size} bytes of data")
    try:
        mss.translate(os.path.join(REPO, "scenes", "glossy_plane.gltf"), out, 8, 8)
        check(False, "a glossy material was translated")
    except ToolError as e:
        check("only Lambertian and dielectric" in str(e), f"glossy refusal: {e}")
    rows = [{"seconds": 2.0 ** k, "error": 0.1 * 2.0 ** (-0.5 * k)} for k in range(5)]
    check(abs(mss.fit(rows) + 0.5) < 1e-12, f"fit slope {mss.fit(rows)}")
    check(abs(mss.seconds_at(rows, 0.1 * 2.0 ** -1.25) - 2.0 ** 2.5) < 1e-9, "seconds_at")


def cycles_reading(exe, tmp):
    """tools.cycles_side_by_side's reading of a render (Blender itself never runs in CI): the
    view it gives Cycles is the one the metadata records, the sky is on only without a light,
    an environment map is refused by name, and the ratios are taken over covered pixels only."""
    from tools import cycles_side_by_side as cyc
    path = os.path.join(tmp, "cyc.exr")
    cli.render(exe, os.path.join(REPO, "scenes", "cornell.gltf"), path,
               ["--resolution", "16x12", "--passes", "1", "--quiet", "--fov", "50",
                "--look-from", "0,1,3", "--look-at", "0,1,0"])
    meta = exr.read_exr(path).metadata
    view = cyc.view_of(meta, path)
    check(view["from"] == [0.0, 1.0, 3.0] and view["at"][2] < 3.0, f"view {view}")
    check(abs(view["fov"] - 50.0) < 1e-5 and  # the camera keeps yfov as a float
          (view["width"], view["height"]) == (16, 12),
          f"view {view}")
    check(cyc.has_light(gltf_scene.load(os.path.join(REPO, "scenes", "cornell.gltf"))),
          "the Cornell box has a light")
    check(not cyc.has_light(gltf_scene.load(os.path.join(REPO, "scenes", "unlit.gltf"))),
          "unlit.gltf has no light")
    try:
        cyc.view_of(dict(meta, **{"photonbound:environment": "sky.exr"}), path)
        check(False, "an environment map was accepted")
    except ToolError as e:
        check("not translated" in str(e), f"environment refusal: {e}")
    ours = np.ones((2, 2, 3))
    theirs = np.full((2, 2, 3), 0.5)
    alpha = np.array([[1.0, 1.0], [0.0, 0.4]])
    theirs[1, :, :] = 100.0  # uncovered pixels do not count
    r = cyc.ratios(ours, theirs, alpha)
    check(r["pixels"] == 2 and abs(r["R"] - 2.0) < 1e-12, f"ratios {r}")


def cornell_reference_margin(exe, tmp):
    """The shipped Cornell reference judges the study's own Cornell sweep with the 10x margin
    the issue asks for (its bound against the smallest actual error). Seed 1 and the fixed pass
    counts make this deterministic: 13.5x when the reference was made."""
    out = os.path.join(tmp, "cornell")
    p = run_tool("study", out, "--scenes", "cornell", "--photonbound", exe)
    if p.returncode != 0:
        check(False, f"Cornell study failed ({p.returncode}): {p.stderr.strip()}")
        return
    check("warning" not in p.stderr, f"Cornell study warned: {p.stderr.strip()}")
    rows = json.load(open(os.path.join(out, "results.json")))
    bound = study.reference_quality(study.CORNELL_REFERENCE)[0]
    smallest = min(r["actual"] for r in rows)
    check(len(rows) == 8 and bound > 0 and smallest >= study.REFERENCE_MARGIN * bound,
          f"Cornell reference bound {bound:.3g} is not 10x below the smallest error {smallest:.3g}")
    # --method sppm judges the Cornell box by its SPPM (pixel-area) reference: one short run.
    out = os.path.join(tmp, "cornell_sppm")
    p = run_tool("study", out, "--scenes", "cornell", "--method", "sppm", "--stop-rule",
                 "mean-error", "--targets", "0.04", "--confidences", "0.5", "--photonbound", exe)
    check(p.returncode == 0, f"SPPM Cornell study failed ({p.returncode}): {p.stderr.strip()}")
    if p.returncode == 0:
        rows = json.load(open(os.path.join(out, "results.json")))
        check(len(rows) == 1 and 0.0 < rows[0]["actual"] < 0.08,
              f"SPPM Cornell study: rows {rows}")
        check("cornell_64x64_sppm_reference.exr" in open(os.path.join(out, "table.md")).read(),
              "SPPM Cornell study: the table does not name the SPPM reference")
    # The warning itself: given for a loose reference, not for a tight or an exact one.
    check(study.reference_warning("x", 0.002, 0.01) is not None, "no warning at 5x")
    check(study.reference_warning("x", 0.0005, 0.01) is None, "warning at 20x")
    check(study.reference_warning("x", 0.0, 0.01) is None, "warning for an exact reference")


def test_gltf_document():
    """A small scene that exercises the reader: one bufferView of interleaved POSITION and
    NORMAL (byteStride 24), UNSIGNED_SHORT indices, a mirroring "matrix" under a TRS parent,
    a camera turned by a quaternion, spot and point lights, and materials relying on the glTF
    defaults. Returns (JSON document, binary buffer)."""
    verts = [((0, 0, 0), (0, 0, 1)), ((1, 0, 0), (0, 0, 1)), ((0, 1, 0), (0, 0, 1))]
    data = b"".join(struct.pack("<6f", *p, *n) for p, n in verts)
    data += struct.pack("<3H", 0, 1, 2) + b"\0\0"
    h = math.sqrt(0.5)
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [
            {"translation": [0, 0, 5], "children": [1, 2, 3, 4]},
            {"mesh": 0, "matrix": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1]},
            {"camera": 0, "rotation": [0, h, 0, h]},
            {"translation": [0, 1, 0], "scale": [2, 2, 2],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 1.5,
                                                           "znear": 0.1}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "intensity": 3, "spot": {"outerConeAngle": 0.5}},
            {"type": "point", "color": [1, 0.5, 0], "intensity": 4}]}},
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1],
                                      "metallicFactor": 0}, "emissiveFactor": [1, 2, 3],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2}}},
            {},
            {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                            "KHR_materials_ior": {"ior": 1.3}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
                                    "material": 0}]}],
        "buffers": [{"byteLength": len(data)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 72, "byteStride": 24},
                        {"buffer": 0, "byteOffset": 72, "byteLength": 6}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 3,
             "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    }
    return doc, data


def gltf_reading(tmp):
    """tools/gltf_scene.py: the shipped plane_point family (.gltf, .glb, external buffer, node
    hierarchy) reads the same in world space, and a hand-made file reads as worked out here."""
    scenes = os.path.join(REPO, "scenes")
    base = analytic.Gltf(os.path.join(scenes, "plane_point.gltf"))
    for name in ("plane_point.glb", "plane_point_external.gltf", "nested.gltf"):
        other = analytic.Gltf(os.path.join(scenes, name))
        a, b = base.camera(), other.camera()
        check(all(np.allclose(a[k], b[k], atol=1e-12) for k in a if k != "aspect"),
              f"{name}: camera {b} differs from plane_point.gltf's {a}")
        check(all(np.allclose(x, y, atol=1e-12) for (p, i), (q, j) in
                  zip(base.point_lights(), other.point_lights()) for x, y in ((p, q), (i, j))),
              f"{name}: point lights differ from plane_point.gltf's")
        check(all(np.allclose(x, y, atol=1e-7) for (lo, hi, _), (lo2, hi2, _) in
                  zip(base.mesh_instances(), other.mesh_instances())
                  for x, y in ((lo, lo2), (hi, hi2))),
              f"{name}: mesh bounds differ from plane_point.gltf's")
    refs = []
    for name in ("plane_point.gltf", "plane_point.glb"):  # tools.reference reads both containers
        refs.append(os.path.join(tmp, name + ".exr"))
        p = run_tool("reference", "exact", "plane", "-o", refs[-1], "--resolution", "8x8",
                     "--scene", os.path.join(scenes, name))
        check(p.returncode == 0, f"tools.reference exact plane --scene {name}: {p.stderr.strip()}")
    if all(os.path.isfile(r) for r in refs):
        a, b = (exr.read_exr(r).rgb() for r in refs)
        check(np.array_equal(a, b), "the exact plane differs between the .gltf and the .glb")
    # Pixel-area references (SPPM's): the mean of 4x4 rays per pixel is the block mean of the
    # centre values of a 4x finer image, and it is within 2% of the centre value wherever the
    # field is smooth (the plane's radiance varies by under 10% across a pixel at 8x8).
    gltf = analytic.Gltf(os.path.join(scenes, "plane_point.gltf"))
    area = analytic.exact_image("plane", gltf, 8, 8, 4)
    fine = analytic.exact_plane(gltf, 32, 32)
    check(np.allclose(area, fine.reshape(8, 4, 8, 4, 3).mean(axis=(1, 3)), rtol=1e-12),
          "the pixel-area reference is not the mean of its sub-pixel rays")
    centre = analytic.exact_image("plane", gltf, 8, 8, 1)
    whole = np.all(fine.reshape(8, 4, 8, 4, 3) > 0, axis=(1, 3, 4))  # pixels wholly on the plane
    check(whole.any() and np.all(np.abs(area - centre)[whole] <= 0.02 * centre[whole]),
          "pixel-area and pixel-centre references differ by more than 2% on the plane")
    area_ref = os.path.join(tmp, "area.exr")
    p = run_tool("reference", "exact", "plane", "-o", area_ref, "--resolution", "8x8",
                 "--pixel", "area", "--sub", "4")
    check(p.returncode == 0 and np.allclose(exr.read_exr(area_ref).rgb(), area, rtol=1e-6),
          f"tools.reference exact --pixel area: {p.stderr.strip()}")
    doc, data = test_gltf_document()
    near = lambda a, b: a is not None and np.allclose(a, b, atol=1e-12)  # noqa: E731
    for name, write in (("test.glb", gltf_writer.write_glb),
                        ("test.gltf", gltf_writer.write_gltf)):
        path = os.path.join(tmp, name)
        write(path, doc, data)
        try:
            s = gltf_scene.load(path)
        except ToolError as e:
            check(False, f"{name}: not read: {e}")
            continue
        (inst,) = s.meshes
        (prim,) = inst.primitives
        check(inst.mirrored and prim.indices == [0, 2, 1],
              f"{name}: mirrored mesh indices {prim.indices}, expected [0, 2, 1]")
        check(near(prim.positions, [(1, 0, 5), (0, 0, 5), (1, 1, 5)]),
              f"{name}: world positions {prim.positions}")
        check(near(prim.normals, [(0, 0, 1)] * 3), f"{name}: world normals {prim.normals}")
        m = prim.material
        check(m.base_color == (0.5, 0.25, 0.125) and m.metallic == 0 and m.roughness == 1 and
              m.emission == (2, 4, 6) and m.model == "glossy",
              f"{name}: material 0 read as {vars(m)}")
        d, g = s.materials[1], s.materials[2]
        check(d.base_color == (1, 1, 1) and d.metallic == 1 and d.roughness == 1 and
              d.model == "glossy" and d.emission == (0, 0, 0),
              f"{name}: material 1 (all defaults) read as {vars(d)}")
        check(g.model == "thin" and g.ior == 1.3, f"{name}: material 2 read as {vars(g)}")
        (cam,) = s.cameras
        check(near(cam.position, (0, 0, 5)) and near(cam.forward, (-1, 0, 0)) and
              near(cam.up, (0, 1, 0)) and near(cam.right, (0, 0, -1)) and cam.yfov == 0.5 and
              cam.aspect == 1.5, f"{name}: camera read as {vars(cam)}")
        spot, point = s.lights
        check(spot.type == "spot" and near(spot.position, (0, 1, 5)) and
              near(spot.direction, (0, 0, -1)) and spot.intensity == (3, 3, 3) and
              spot.inner_cone == 0 and spot.outer_cone == 0.5, f"{name}: spot read as {vars(spot)}")
        check(point.type == "point" and near(point.position, (0, 0, 5)) and
              point.intensity == (4, 2, 0), f"{name}: point light read as {vars(point)}")


def expect_failure(what, p, needle):
    lines = p.stderr.strip().splitlines()
    check(p.returncode != 0, f"{what}: exit code 0")
    check(len(lines) == 1 and needle in p.stderr,
          f"{what}: expected one line mentioning '{needle}', got: {p.stderr.strip()!r}")


def bad_input(exe, tmp):
    missing = os.path.join(tmp, "missing.exr")
    expect_failure("views of a missing file", run_tool("views", missing, "-o", tmp), missing)
    rgb_only = os.path.join(tmp, "rgb_only.exr")
    z = np.zeros((4, 4), np.float32)
    exr.write_exr(rgb_only, {exr.channel("Radiance", c): z for c in exr.RGB}, {})
    expect_failure("views of an EXR without bounds", run_tool("views", rgb_only, "-o", tmp),
                   "has no channel " + exr.channel("ErrorBound", "R"))
    check(not any(f.endswith(".png") for f in os.listdir(tmp)), "views wrote PNGs for bad input")
    text = os.path.join(tmp, "not_a_log.jsonl")
    with open(text, "w") as f:
        f.write("hello\n")
    expect_failure("plot of a non-log", run_tool("plot_logs", "-o", tmp, text),
                   "not a JSON line")
    expect_failure("plot of a missing log", run_tool("plot_logs", "-o", tmp, missing),
                   "no such file")
    expect_failure("study of an unknown scene",
                   run_tool("study", os.path.join(tmp, "s"), "--scenes", "teapot",
                            "--photonbound", exe), "--scenes teapot")
    expect_failure("study with a missing photonbound",
                   run_tool("study", os.path.join(tmp, "s"), "--photonbound", missing),
                   "no photonbound executable")
    expect_failure("study at a size the Cornell reference lacks",
                   run_tool("study", os.path.join(tmp, "s"), "--scenes", "cornell",
                            "--resolution", "8x8", "--photonbound", exe), "not 8x8")
    expect_failure("exact reference of a scene that is not a plane",
                   run_tool("reference", "exact", "plane", "-o", rgb_only, "--resolution",
                            "8x8", "--scene",
                            os.path.join(REPO, "scenes", "closed_box.gltf")),
                   "is not a horizontal plane")
    expect_failure("bad resolution", run_tool("reference", "exact", "box", "-o", rgb_only,
                                              "--resolution", "8by8"), "expected WxH")
    bad_gltf(tmp, rgb_only)


def bad_gltf(tmp, out):
    """Files tools/gltf_scene.py cannot read: one line naming the file and what is wrong."""
    doc, data = test_gltf_document()
    cases = []
    path = os.path.join(tmp, "bad_header.glb")
    with open(path, "wb") as f:
        f.write(b"glTF" + struct.pack("<II", 1, 20) + b"\0" * 8)
    cases.append(("a GLB with a bad header", path, "bad GLB header"))
    path = os.path.join(tmp, "lost_buffer.gltf")
    gltf_writer.write_gltf_external(path, doc, data)
    os.remove(os.path.join(tmp, "lost_buffer.bin"))
    cases.append(("a glTF whose buffer is missing", path, "cannot read lost_buffer.bin"))
    path = os.path.join(tmp, "sparse.glb")
    sparse = json.loads(json.dumps(doc))
    sparse["accessors"][0]["sparse"] = {"count": 1}
    gltf_writer.write_glb(path, sparse, data)
    cases.append(("a sparse accessor", path, "sparse accessors are not read"))
    path = os.path.join(tmp, "overflow.gltf")
    over = json.loads(json.dumps(doc))
    over["accessors"][1]["count"] = 4
    gltf_writer.write_gltf(path, over, data)
    cases.append(("an accessor past its bufferView", path, "accessor 1 overflows"))
    path = os.path.join(tmp, "cycle.gltf")
    cycle = json.loads(json.dumps(doc))
    cycle["nodes"][1]["children"] = [0]
    gltf_writer.write_gltf(path, cycle, data)
    cases.append(("a node cycle", path, "node 0 reached twice"))
    for what, path, needle in cases:
        p = run_tool("reference", "exact", "plane", "-o", out, "--resolution", "8x8",
                     "--scene", path)
        expect_failure(what, p, needle)
        check(p.stderr.startswith(f"reference: {path}: "),
              f"{what}: the message does not name the file: {p.stderr.strip()!r}")


def corpus(exe, tmp):
    folder = os.path.join(tmp, "corpus")
    p = run_tool("make_corpus", folder)
    check(p.returncode == 0, f"tools.make_corpus failed: {p.stderr.strip()}")
    if p.returncode != 0:
        return
    for name, (warnings, (lo, hi)) in make_corpus.CORPUS.items():
        path = os.path.join(folder, name)
        for method in ("sppm", "ppm"):
            out = os.path.join(tmp, f"{name}.{method}.exr")
            what = f"{name} ({method})"
            try:
                r = cli.render(exe, path, out, ["--passes", "6", "--resolution", "48x48",
                                                "--photons-per-pass", "20000", "--method", method,
                                                "--quiet"])
            except ToolError as e:
                check(False, f"{what}: {e}")
                continue
            prefix = f"photonbound: warning: {path}: "
            got = [l[len(prefix):] for l in r.stderr.splitlines() if l.startswith(prefix)]
            other = [l for l in r.stderr.splitlines() if not l.startswith(prefix)]
            check(got == warnings, f"{what}: warnings {got}, expected {warnings}")
            check(not other, f"{what}: unexpected output {other}")
            rgb = exr.read_exr(out).rgb()
            check(bool(np.all(np.isfinite(rgb)) and np.all(rgb >= 0)),
                  f"{what}: radiance not finite and >= 0")
            mean = float(rgb.mean())
            centre = float(rgb[20:28, 20:28].mean())
            print(f"{what}: mean radiance {mean:.4g}, centre {centre:.4g}")
            check(lo <= mean <= hi, f"{what}: mean radiance {mean:.4g} outside [{lo}, {hi}]")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["smoke", "bad-input", "corpus"])
    ap.add_argument("--photonbound", required=True)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix=f"pb_tools_{args.mode}_")
    try:
        {"smoke": smoke, "bad-input": bad_input, "corpus": corpus}[args.mode](args.photonbound,
                                                                             tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print(f"{len(failures)} check(s) failed", file=sys.stderr)
        return 1
    print(f"{args.mode}: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
