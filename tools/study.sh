#!/usr/bin/env bash
# Runs the speed-accuracy study from a fresh clone: installs missing Debian packages, builds
# photonbound (tools/build.sh), then runs python3 -m tools.study OUTDIR [its options] under the
# system Python, from any folder (the repository root is its import root; OUTDIR stays relative
# to the current folder). 2.6 minutes measured on 2 idle cores; see docs/study.md "The study".
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ $# -lt 1 ]; then
  echo "usage: tools/study.sh OUTDIR [python3 -m tools.study options]" >&2
  exit 2
fi
"$root/tools/build.sh" >/dev/null
PYTHONPATH="$root${PYTHONPATH:+:$PYTHONPATH}" exec /usr/bin/python3 -P -m tools.study "$@" \
  --photonbound "$root/build/photonbound"
