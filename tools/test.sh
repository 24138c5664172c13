#!/usr/bin/env bash
# Installs missing Debian packages, builds, and runs the whole ctest suite (unit and slow
# labels). Extra arguments go to ctest, e.g. tools/test.sh -LE slow for the quick tests only.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
cd "$root/build"
ctest --output-on-failure --timeout 900 -j 2 "$@"
