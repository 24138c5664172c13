"""A hostile corpus (issue 36): one small file, or command, per class of hostile input that
photonbound now handles, written into a temporary folder and run with a time and a memory limit.

  python3 -m tools.hostile [--photonbound build/photonbound] [--only NAME] [--keep DIR]
                           [--seconds 60] [--memory-gb 4]

Each case must end the way it says: "refuse", a clean refusal (exit 1 or 2, the last line of
stderr one line naming the problem, no output file left), or "render" (exit 0 and the image
written); and never by a signal, a crash, the time limit or the memory limit. No input file may
change. Prints one line per case and exits 1 if any fails. Standard library only (the files are
written by tools/gltf_writer.py and by hand). tests/CMakeLists.txt runs it as Tools.hostile.

Left out (covered by the C++ tests, whose files are not a few bytes of standard-library
output): a data: URI over its 256 MiB cap (tests/gltf/test_gltf_budgets.cpp) and EXR headers
claiming gigabytes or deep data for compare, preview and --reference (tests/io/
test_image_limits.cpp); signals during a checkpoint (tests/app/test_checkpoint.cpp).
"""

import argparse
import hashlib
import os
import resource
import shutil
import struct
import subprocess
import tempfile
import time
import zlib

from . import gltf_writer
from .cli import check_photonbound, default_photonbound
from .common import REPO, ToolError, run_main
from .gltf_scene import FLOAT, UNSIGNED_INT

FAST = ["--resolution", "16x16", "--photons-per-pass", "2000", "--passes", "2", "--quiet"]


# ------------------------------------------------------------------------------ the files

def scene_doc(buf, copies=1, node_matrix=None, extra_node=None, image_uri=None):
    """A floor, one triangle (listed `copies` times) under a node (with `node_matrix`), a camera
    and a point light; with image_uri, the floor's material has that base colour texture."""
    def vec3s(vs):
        lo = [min(v[i] for v in vs) for i in range(3)]
        hi = [max(v[i] for v in vs) for i in range(3)]
        data = b"".join(struct.pack("<3f", *v) for v in vs)
        return buf.accessor(data, FLOAT, len(vs), "VEC3", gltf_writer.ARRAY_BUFFER, (lo, hi))

    def indices(ix):
        return buf.accessor(struct.pack(f"<{len(ix)}I", *ix), UNSIGNED_INT, len(ix), "SCALAR",
                            gltf_writer.ELEMENT_ARRAY_BUFFER)

    floor = {"attributes": {"POSITION": vec3s([(-2, 0, -2), (2, 0, -2), (2, 0, 2), (-2, 0, 2)])},
             "indices": indices([0, 2, 1, 0, 3, 2])}
    tri = {"attributes": {"POSITION": vec3s([(-0.5, 0.2, 0), (0.5, 0.2, 0), (0, 1.2, 0)])},
           "indices": indices([0, 1, 2] * copies)}
    shape = {"name": "shape", "mesh": 1}
    if node_matrix is not None:
        shape["matrix"] = node_matrix
    nodes = [{"mesh": 0}, shape, {"camera": 0, "translation": [0, 1, 4]},
             {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 3, 1]}]
    if extra_node is not None:
        nodes.append(extra_node)
    doc = {"asset": {"version": "2.0"}, "scene": 0,
           "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
           "meshes": [{"primitives": [floor]}, {"name": "tri", "primitives": [tri]}],
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
           "extensionsUsed": ["KHR_lights_punctual"],
           "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point",
                                                             "intensity": 20}]}}}
    if image_uri is not None:
        floor["material"] = 0
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        doc["textures"] = [{"source": 0}]
        doc["images"] = [{"uri": image_uri}]
    doc["accessors"], doc["bufferViews"] = buf.accessors, buf.views
    return doc


def write_scene(path, **kw):
    buf = gltf_writer.Buffer()
    doc = scene_doc(buf, **kw)
    gltf_writer.write_gltf(path, doc, buf.data)


def write_scene_external(path, uri, **kw):
    """A scene whose buffer is the file `uri` (written as NAME.bin beside it unless uri differs)."""
    buf = gltf_writer.Buffer()
    doc = scene_doc(buf, **kw)
    data = bytes(buf.data) + b"\0" * (-len(buf.data) % 4)
    doc["buffers"] = [{"byteLength": len(data), "uri": uri}]
    with open(path, "w", encoding="utf-8") as f:
        f.write(gltf_writer.json.dumps(doc))
    return data


def png(width, height):
    """A grey 8-bit RGB PNG, by hand (zlib and struct)."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\0" + b"\x80" * (3 * width) for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0,
                                                               0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# ------------------------------------------------------------------------------ the cases

class Case:
    """A case: make(folder) writes its files and returns the command's options after
    `photonbound` (the scene folder is the working directory); expect is "refuse" or "render"."""

    def __init__(self, name, expect, make, says=""):
        self.name, self.expect, self.make, self.says = name, expect, make, says


def render_args(scene, *extra):
    return ["render", scene, "-o", "out.exr", *FAST, *extra]


def uri_case(uri):
    def make(d):
        write_scene_external(os.path.join(d, "scene.gltf"), uri)
        return render_args("scene.gltf")
    return make


def make_secret_outside(d):
    with open(os.path.join(os.path.dirname(d), "secret.bin"), "wb") as f:
        f.write(b"\0" * 4096)
    return uri_case("../secret.bin")(d)


def make_symlink_out(d):
    os.symlink("/etc", os.path.join(d, "etc"))
    return uri_case("etc/hostname")(d)


def make_pipe_uri(d):
    os.mkfifo(os.path.join(d, "pipe.bin"))
    return uri_case("pipe.bin")(d)


def make_dir_uri(d):
    os.mkdir(os.path.join(d, "folder.bin"))
    return uri_case("folder.bin")(d)


def make_pipe_scene(d):
    os.mkfifo(os.path.join(d, "scene.gltf"))
    return render_args("scene.gltf")


def edited_scene(d, old, new):
    """The scene with its first `old` replaced by `new` in the JSON text."""
    path = os.path.join(d, "scene.gltf")
    write_scene(path)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace(old, new, 1))
    return render_args("scene.gltf")


def make_deep_json(d):
    deep = "[" * 100000 + "]" * 100000
    return edited_scene(d, '"asset": {', '"extras": ' + deep + ', "asset": {')


def make_string_number(d):
    return edited_scene(d, '"intensity": 20', '"intensity": "NaN"')


def texture_scene(d, name, data, *extra):
    """The scene with the floor's base colour texture `name` holding `data`."""
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)
    write_scene(os.path.join(d, "scene.gltf"), image_uri=name)
    return render_args("scene.gltf", *extra)


def make_truncated_png(d):
    return texture_scene(d, "tex.png", png(64, 64)[:60])


def make_truncated_jpeg(d):
    # The shipped 8 x 8 JPEG cut before its last third: libjpeg would fill the rest with grey.
    with open(os.path.join(REPO, "tests", "data", "textures", "solid_200_100_50.jpg"), "rb") as f:
        data = f.read()
    return texture_scene(d, "tex.jpg", data[:2 * len(data) // 3])


def make_huge_resolution(d):
    # 16384 x 16384 pixels: about 150 GiB of per-pixel state, refused by the estimate up front.
    write_scene(os.path.join(d, "scene.gltf"))
    return ["render", "scene.gltf", "-o", "out.exr", "--resolution", "16384x16384", "--passes",
            "1", "--max-memory", "2G", "--quiet"]


def make_preview_over_input(d):
    # preview IN -o IN: refused before IN is read (so IN need not even be an EXR).
    with open(os.path.join(d, "render.exr"), "wb") as f:
        f.write(b"not an image")
    return ["preview", "render.exr", "-o", "render.exr"]


def make_png_claiming_huge(d):
    # A valid 1x1 PNG whose header then claims 16384 x 16384: the rows cannot come from its few
    # bytes (deflate expands at most 1032:1), so it is refused from the header, unallocated.
    data = bytearray(png(1, 1))
    data[16:24] = struct.pack(">II", 16384, 16384)
    data[29:33] = struct.pack(">I", zlib.crc32(bytes(data[12:29])) & 0xFFFFFFFF)
    return texture_scene(d, "tex.png", bytes(data))


def make_image_beyond_memory(d):
    # A real 4096 x 4096 PNG (48 MiB of texels) under --max-memory 160M: with the program's own
    # 140 MiB the render does not fit, and it is refused before it starts.
    return texture_scene(d, "tex.png", png(4096, 4096), "--max-memory", "160M")


def make_copies(d):
    write_scene(os.path.join(d, "scene.gltf"), copies=65536)
    return render_args("scene.gltf")


def matrix_case(m):
    def make(d):
        write_scene(os.path.join(d, "scene.gltf"), node_matrix=m)
        return render_args("scene.gltf")
    return make


def output_case(*flags):
    def make(d):
        write_scene(os.path.join(d, "scene.gltf"))
        return ["render", "scene.gltf", *FAST, *flags]
    return make


def make_long_pass(d):
    # Five million photons: a pass of a few seconds (cut by --time between photon batches) that
    # the memory estimate allows (about 0.85 GB, inside the run's 4 GB address space).
    write_scene(os.path.join(d, "scene.gltf"))
    return ["render", "scene.gltf", "-o", "out.exr", "--resolution", "16x16",
            "--photons-per-pass", "5000000", "--time", "0.5", "--quiet"]


def make_huge_pass(d):
    # 2e8 photons a pass: about 32 GiB of photon hits, refused by the memory estimate up front.
    write_scene(os.path.join(d, "scene.gltf"))
    return ["render", "scene.gltf", "-o", "out.exr", "--resolution", "16x16",
            "--photons-per-pass", "200000000", "--time", "2", "--max-memory", "2G", "--quiet"]


IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]

CASES = [
    Case("uri-parent", "refuse", make_secret_outside, "../"),
    Case("uri-absolute", "refuse", uri_case("/etc/hostname")),
    Case("uri-percent", "refuse", uri_case("%2e%2e/secret.bin")),
    Case("uri-device", "refuse", uri_case("/dev/zero")),
    Case("uri-symlink-out", "refuse", make_symlink_out),
    Case("uri-pipe", "refuse", make_pipe_uri),
    Case("uri-directory", "refuse", make_dir_uri),
    Case("scene-pipe", "refuse", make_pipe_scene),
    Case("deep-json", "refuse", make_deep_json),
    Case("string-number", "refuse", make_string_number),
    Case("truncated-png", "refuse", make_truncated_png),
    Case("coincident-triangles", "render", make_copies),
    Case("matrix-projective", "refuse", matrix_case([1, 0, 0, 0.5] + IDENTITY[4:])),
    Case("matrix-singular", "refuse", matrix_case([1, 0, 0, 0, 0, 1, 0, 0] + [0] * 7 + [1])),
    Case("matrix-shear", "render", matrix_case([1, 0, 1, 0] + IDENTITY[4:]), "shears"),
    Case("matrix-mirror", "render", matrix_case([-1, 0, 0, 0] + IDENTITY[4:])),
    Case("output-is-scene", "refuse", output_case("-o", "out.exr", "--state", "scene.gltf")),
    Case("output-not-exr", "refuse", output_case("-o", "out.jpg")),
    Case("truncated-jpeg", "refuse", make_truncated_jpeg),
    Case("png-claims-huge", "refuse", make_png_claiming_huge),
    Case("resolution-beyond-memory", "refuse", make_huge_resolution),
    Case("preview-over-input", "refuse", make_preview_over_input),
    Case("image-beyond-memory", "refuse", make_image_beyond_memory),
    Case("long-pass-time", "render", make_long_pass),
    Case("pass-beyond-memory", "refuse", make_huge_pass),
]


# ------------------------------------------------------------------------------ running

def snapshot(folder):
    """Every regular file under folder (links not followed) -> its SHA-256."""
    out = {}
    for root, _, files in os.walk(folder):
        for name in files:
            p = os.path.join(root, name)
            if os.path.isfile(p) and not os.path.islink(p):
                with open(p, "rb") as f:
                    out[os.path.relpath(p, folder)] = hashlib.sha256(f.read()).hexdigest()
    return out


def sanitized(exe):
    """True for an AddressSanitizer build (tools/sanitize.sh), which reserves terabytes of
    address space for its shadow memory: an address-space limit would kill it at start."""
    with open(exe, "rb") as f:
        return b"__asan_init" in f.read()


def run_case(exe, case, base, seconds, memory, limit_address_space=True):
    d = os.path.join(base, case.name, "scene")
    os.makedirs(d)
    args = case.make(d)
    before = snapshot(os.path.dirname(d))

    def limits():
        if limit_address_space:
            resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))

    t0 = time.monotonic()
    try:
        r = subprocess.run([exe, *args], cwd=d, stdin=subprocess.DEVNULL, capture_output=True,
                           text=True, timeout=seconds, preexec_fn=limits)
    except subprocess.TimeoutExpired:
        return f"still running after {seconds} s"
    took = time.monotonic() - t0
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    last = lines[-1] if lines else ""
    if r.returncode < 0:
        return f"killed by signal {-r.returncode} after {took:.1f} s: {last}"
    # The largest resident set of any case run so far (Linux reports KiB): checked after each
    # case, so the first case past the limit is the one named.
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
    if peak > memory:
        return f"peak memory {peak / 2**30:.2f} GiB, over {memory / 2**30:.2f} GiB"
    changed = [f for f, h in before.items()
               if snapshot(os.path.dirname(d)).get(f) != h and not f.endswith("out.exr")]
    if changed:
        return f"changed its inputs: {', '.join(changed)}"
    if case.expect == "refuse":
        if r.returncode not in (1, 2):
            return f"exit {r.returncode}, expected a refusal (1 or 2): {last}"
        if not last.startswith("photonbound: ") or "\n" in last:
            return f"no one-line message: {r.stderr[-300:]!r}"
        for out in ("out.exr", "out.jpg"):
            if os.path.exists(os.path.join(d, out)):
                return f"refused but left {out}"
        return None, took, last
    if r.returncode != 0 or not os.path.isfile(os.path.join(d, "out.exr")):
        return f"exit {r.returncode}, expected a render: {last}"
    if case.says and case.says not in r.stderr:
        return f"rendered without saying '{case.says}'"
    return None, took, last or "(rendered)"


def main():
    ap = argparse.ArgumentParser(prog="python3 -m tools.hostile",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("--photonbound", default=default_photonbound())
    ap.add_argument("--only", action="append", help="run only this case (repeatable)")
    ap.add_argument("--keep", help="write the cases into DIR (kept) instead of a temporary folder")
    ap.add_argument("--seconds", type=float, default=60.0, help="time limit per case")
    ap.add_argument("--memory-gb", type=float, default=4.0, help="address-space limit per case")
    args = ap.parse_args()
    exe = os.path.abspath(check_photonbound(args.photonbound))
    cases = [c for c in CASES if not args.only or c.name in args.only]
    if args.only and len(cases) != len(args.only):
        raise ToolError("unknown case; the cases are: " + ", ".join(c.name for c in CASES))
    base = args.keep or tempfile.mkdtemp(prefix="pb_hostile_")
    if args.keep:
        shutil.rmtree(base, ignore_errors=True)
        os.makedirs(base)
    failed = 0
    limit_address_space = not sanitized(exe)
    if not limit_address_space:
        print("hostile: an AddressSanitizer build: peak memory checked, address space not limited")
    try:
        for c in cases:
            result = run_case(exe, c, base, args.seconds, int(args.memory_gb * 2**30),
                              limit_address_space)
            if isinstance(result, str):
                failed += 1
                print(f"FAIL {c.name}: {result}")
            else:
                _, took, last = result
                print(f"ok   {c.name} ({c.expect}, {took:.1f} s): {last[:160]}")
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    if failed:
        raise ToolError(f"{failed} of {len(cases)} hostile cases failed")
    return 0


if __name__ == "__main__":
    run_main("hostile", main)
