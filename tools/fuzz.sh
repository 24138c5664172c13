#!/usr/bin/env bash
# Fuzzes the glTF loader with libFuzzer (clang) under AddressSanitizer + UBSan.
#   tools/fuzz.sh [SECONDS] [WORKERS]     default: 900 s on 2 workers = 30 CPU-minutes
# Builds fuzz/ in build-fuzz/, seeds the corpus with every shipped scene, and runs in fork mode
# so that one finding does not end the run. Findings (crash-*, leak-*, timeout-*, oom-*) land in
# build-fuzz/findings/; each one fixed is kept in tests/data/fuzz/ where test_gltf_loader_files replays it.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-900}"
workers="${2:-2}"
"$root/tools/install-deps.sh" clang libclang-rt-14-dev nlohmann-json3-dev
cmake -S "$root/fuzz" -B "$root/build-fuzz" -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build "$root/build-fuzz"
corpus="$root/build-fuzz/corpus"
findings="$root/build-fuzz/findings"
mkdir -p "$corpus" "$findings"
cp "$root"/scenes/*.gltf "$root"/scenes/*.glb "$corpus"/
cp "$root"/tests/data/fuzz/* "$corpus"/ 2>/dev/null || true
"$root/build-fuzz/make_gltf_corpus" "$corpus"  # Draco, meshopt, quantised, sparse, skin
cd "$root/build-fuzz"
# Embree and TBB keep allocations alive until exit by design: leaks are not findings here.
export ASAN_OPTIONS=detect_leaks=0
./fuzz_gltf_loader -fork="$workers" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
  -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -dict="$root/fuzz/gltf.dict" \
  -artifact_prefix="$findings/" "$corpus"
echo "fuzz: corpus $(ls "$corpus" | wc -l) inputs; findings: $(ls "$findings" | wc -l)" >&2
ls -l "$findings" >&2
# CPU time of this script and its children (the fuzzer processes): user and system.
times
