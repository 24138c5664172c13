#!/usr/bin/env bash
# Builds everything with AddressSanitizer + UndefinedBehaviorSanitizer in build-sanitize/ and runs
# the fast tests (every label but slow). Extra arguments go to ctest.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/install-deps.sh"
cmake -S "$root" -B "$root/build-sanitize" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPHOTONBOUND_SANITIZE=ON >/dev/null
cmake --build "$root/build-sanitize"
cd "$root/build-sanitize"
# Embree and TBB keep allocations alive until exit by design: leaks are not checked here.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1
ctest --output-on-failure --timeout 900 -j 2 -LE slow "$@"
