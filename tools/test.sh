#!/usr/bin/env bash
# Installs missing Debian packages, builds, and runs the whole ctest suite (unit and slow
# labels), then the fast tests again under AddressSanitizer + UndefinedBehaviorSanitizer.
# Extra arguments go to the first ctest run, e.g. tools/test.sh -LE slow.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
(cd "$root/build" && ctest --output-on-failure --timeout 900 -j 2 "$@")
"$root/tools/sanitize.sh"
