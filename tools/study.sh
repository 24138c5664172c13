#!/usr/bin/env bash
# Runs the speed-accuracy study from a fresh clone: installs missing Debian packages, builds
# photonbound (tools/build.sh), then runs tools/study.py OUTDIR [its options] under the system
# Python. 2.6 minutes measured on 2 idle cores; see README "Measuring the trade".
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ $# -lt 1 ]; then
  echo "usage: tools/study.sh OUTDIR [tools/study.py options]" >&2
  exit 2
fi
"$root/tools/build.sh" >/dev/null
exec /usr/bin/python3 "$root/tools/study.py" "$@" --photonbound "$root/build/photonbound"
