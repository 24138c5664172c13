#!/usr/bin/env python3
"""The layering rule of src/ (docs/design.md, "Layering"), checked on every source's includes.

src/CMakeLists.txt declares each folder's target with the folders it may use (DEPS) and its
third-party libraries (PUBLIC_LIBS, PRIVATE_LIBS). Every folder sits on the include path of
every folder above it and the system headers on all of them, so a header-only include of a
folder or library a target does not declare would compile: this test is what makes the table
hold. A folder may include its own headers, the headers of the folders it declares and of the
folders those declare (PUBLIC, so transitively), the third-party headers of the libraries it
declares, and the PUBLIC libraries of the folders below it. Exit status 1 lists every violation.
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SRC = ROOT / "src"

# Third-party include prefixes and the CMake target that provides them.
LIBRARIES = {
    "embree3/": "embree",
    "OpenImageIO/": "PkgConfig::OIIO",
    "OpenEXR/openexr": "OpenEXR::OpenEXRCore",  # the C core library's headers (openexr*.h)
    "OpenEXR/": "OpenEXR::OpenEXR",
    "libdeflate.h": "PkgConfig::DEFLATE",
    "tiny_gltf.h": "TinyGLTF::TinyGLTF",
    "draco/": "draco::draco",
    "meshoptimizer.h": "meshoptimizer::meshoptimizer",
    "nlohmann/": "nlohmann_json::nlohmann_json",
    "boost/": "Boost::headers",
    "tbb/": "TBB::tbb",
    "oneapi/tbb": "TBB::tbb",
    "glm/": "glm::glm",
    "gtest/": "GTest",
    "mpi.h": "MPI::MPI_CXX",
}


def modules():
    """{folder: (deps, public_libs, private_libs)} from the pb_module calls, and from the
    pb_loaded_module calls, whose folder is a subfolder (io/oiio)."""
    text = (SRC / "CMakeLists.txt").read_text()
    text = re.sub(r"#.*", "", text)
    found = {}
    for call in re.finditer(r"pb_(?:loaded_)?module\(([^)]*)\)", text):
        words = call.group(1).split()
        if words[0] in ("name", "path"):
            continue  # the functions' own definitions
        name, section = words[0], None
        parts = {"DEPS": [], "PUBLIC_LIBS": [], "PRIVATE_LIBS": [], "SOURCES": []}
        for w in words[1:]:
            if w in parts:
                section = w
            else:
                parts[section].append(w)
        found[name] = (parts["DEPS"], parts["PUBLIC_LIBS"], parts["PRIVATE_LIBS"])
    return found


def allowed(mods, name):
    """The folders and libraries `name` may include."""
    folders, libs, stack = {name}, set(mods[name][1]) | set(mods[name][2]), list(mods[name][0])
    while stack:
        dep = stack.pop()
        if dep in folders:
            continue
        if dep not in mods:
            raise SystemExit(f"src/CMakeLists.txt: {name} depends on unknown folder {dep}")
        folders.add(dep)
        libs |= set(mods[dep][1])
        stack.extend(mods[dep][0])
    return folders, libs


def violations():
    mods = modules()
    found = []
    for path in sorted(SRC.rglob("*")):
        if path.suffix not in (".h", ".cpp", ".def") or path.parent == SRC:
            if path.suffix in (".h", ".cpp"):
                found.append(f"{path.relative_to(ROOT)}: a source outside every folder")
            continue
        parts = path.relative_to(SRC).parts
        folder = "/".join(parts[:2]) if "/".join(parts[:2]) in mods else parts[0]
        if folder not in mods:
            found.append(f"{path.relative_to(ROOT)}: folder {folder} is no target")
            continue
        folders, libs = allowed(mods, folder)
        for n, line in enumerate(path.read_text().splitlines(), 1):
            m = re.match(r'\s*#\s*include\s*([<"])([^>"]+)[>"]', line)
            if not m:
                continue
            header = m.group(2)
            where = f"{path.relative_to(ROOT)}:{n}: {header}"
            lib = next((t for p, t in LIBRARIES.items() if header.startswith(p)), None)
            if lib is not None:
                if lib not in libs:
                    found.append(f"{where}: {lib} is not declared by {folder}/ or below it")
            elif m.group(1) == '"':
                target = header.split("/")[0] if "/" in header else None
                if target is None or not (SRC / header).exists():
                    found.append(f"{where}: not a src/ folder's header (write folder/file.h)")
                elif target not in folders:
                    found.append(f"{where}: {folder}/ may not use {target}/")
    return found


if __name__ == "__main__":
    bad = violations()
    for line in bad:
        print(line)
    print(f"layering: {len(bad)} violation(s) in {sum(1 for _ in SRC.rglob('*.[hc]*'))} files")
    sys.exit(1 if bad else 0)
