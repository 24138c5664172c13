#!/usr/bin/env bash
# Fuzzes the glTF loader (JSON, GLB, and what they decode) or the image decoders with libFuzzer
# (clang) under AddressSanitizer + UBSan.
#   tools/fuzz.sh [SECONDS] [WORKERS] [loader|image]   default: 900 s on 2 workers = 30 CPU-minutes
# Builds fuzz/ in build-fuzz/, seeds the loader's corpus with every shipped scene and the image
# decoders' with small images of every format OpenImageIO writes here, and runs in fork mode
# so that one finding does not end the run. Findings (crash-*, leak-*, timeout-*, oom-*) land in
# build-fuzz/findings-TARGET/; each one fixed is kept in tests/data/fuzz/ (images: fuzz/images/),
# where test_gltf_loader_files (test_image_limits) replays it.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-900}"
workers="${2:-2}"
target="${3:-loader}"
case "$target" in
  loader | image) ;;
  *) echo "fuzz.sh: the target is loader or image, not '$target'" >&2; exit 2 ;;
esac
"$root/tools/install-deps.sh" clang libclang-rt-14-dev nlohmann-json3-dev python3-openimageio \
  python3-numpy
cmake -S "$root/fuzz" -B "$root/build-fuzz" -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build "$root/build-fuzz"
findings="$root/build-fuzz/findings-$target"
mkdir -p "$findings"
cd "$root/build-fuzz"
# Embree and TBB keep allocations alive until exit by design: leaks are not findings here.
export ASAN_OPTIONS=detect_leaks=0
if [ "$target" = loader ]; then
  corpus="$root/build-fuzz/corpus"
  mkdir -p "$corpus"
  cp "$root"/scenes/*.gltf "$root"/scenes/*.glb "$corpus"/
  cp "$root"/tests/data/fuzz/* "$corpus"/ 2>/dev/null || true
  "$root/build-fuzz/make_gltf_corpus" "$corpus"  # Draco, meshopt, quantised, sparse, skin
  ./fuzz_gltf_loader -fork="$workers" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -dict="$root/fuzz/gltf.dict" \
    -artifact_prefix="$findings/" "$corpus"
else
  corpus="$root/build-fuzz/corpus-image"
  mkdir -p "$corpus"
  # Seeds: a 16x12 gradient in glTF's formats (PNG 8 and 16 bit, grey, grey + alpha, RGB,
  # RGBA; baseline and progressive JPEG; WebP) and, for the refusal path, the other formats
  # OpenImageIO writes here.
  /usr/bin/python3 - "$corpus" <<'PY'
import sys
import numpy as np
import OpenImageIO as oiio
out = sys.argv[1]
pixels = np.linspace(0.0, 1.0, 16 * 12 * 4, dtype=np.float32).reshape(12, 16, 4)
for ext, fmt, ch, extra in [
        ("png", "uint8", 4, None), ("png", "uint16", 3, None), ("png", "uint8", 1, None),
        ("png", "uint16", 2, None), ("jpg", "uint8", 3, None), ("jpg", "uint8", 1, None),
        ("jpg", "uint8", 3, "jpeg:progressive"), ("webp", "uint8", 3, None),
        ("webp", "uint8", 4, None), ("tga", "uint8", 4, None), ("bmp", "uint8", 3, None),
        ("hdr", "float", 3, None), ("exr", "half", 4, None), ("tif", "uint16", 4, None)]:
    spec = oiio.ImageSpec(16, 12, ch, fmt)
    if extra:
        spec.attribute(extra, 1)
    path = f"{out}/seed_{fmt}_{ch}{'_' + extra.split(':')[1] if extra else ''}.{ext}"
    o = oiio.ImageOutput.create(path)
    if o and o.open(path, spec):
        o.write_image(pixels[:, :, :ch])
        o.close()
PY
  cp "$root"/tests/data/fuzz/images/* "$corpus"/  # the findings fixed so far
  ./fuzz_image_decode -fork="$workers" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$findings/" "$corpus"
fi
echo "fuzz: corpus $(ls "$corpus" | wc -l) inputs; findings: $(ls "$findings" | wc -l)" >&2
ls -l "$findings" >&2
# CPU time of this script and its children (the fuzzer processes): user and system.
times
