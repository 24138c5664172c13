#!/usr/bin/env bash
# Time to a stated error, against an earlier binary in the same run (issue 40's time-to-error
# figure): README's first command (the default scene to a predicted mean error of 0.01 at 90%)
# with the old and the new binary alternately, RUNS times each; medians of the passes, the
# pass loop's seconds (the stop line's) and the whole process's wall seconds, and old / new.
# Timings are printed, never asserted; run it on a quiet machine.
#   bench/time_to_error.sh OLD [RUNS] [render options...]
#     OLD: a photonbound binary, or a git revision, which is built beside this checkout (a
#     worktree under ${TMPDIR:-/tmp}, Release, the same compiler) before the runs.
#   bench/time_to_error.sh HEAD~3 3                          the default scene, 512x512
#   bench/time_to_error.sh /tmp/old/photonbound 3 --resolution 1920x1080
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
new="$root/build/photonbound"
old="${1:?usage: bench/time_to_error.sh OLD [RUNS] [render options...]}"
runs="${2:-3}"
shift $(($# < 2 ? $# : 2))
if [[ ! -x "$old" ]]; then
  rev="$(git -C "$root" rev-parse --verify "$old^{commit}")" ||
    { echo "bench/time_to_error.sh: $old is neither a binary nor a revision" >&2; exit 1; }
  tree="${TMPDIR:-/tmp}/photonbound-$rev"
  [[ -d "$tree" ]] || git -C "$root" worktree add --detach "$tree" "$rev" >/dev/null
  cmake -S "$tree" -B "$tree/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  ninja -C "$tree/build" photonbound >/dev/null
  old="$tree/build/photonbound"
fi
[[ -x "$new" ]] || { echo "bench/time_to_error.sh: build $new first (tools/build.sh)" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "bench/time_to_error.sh: $(nproc) hardware threads; load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "  old: $old ($("$old" --version | head -1))"
echo "  new: $new ($("$new" --version | head -1))"
echo "  render scenes/cornell.gltf --target-error 0.01 --time 900 $*"

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
one() {  # name exe
  local start end
  start=$(date +%s.%N)
  "$2" render "$root/scenes/cornell.gltf" -o "$work/$1.exr" --target-error 0.01 --time 900 \
    "${@:3}" 2>"$work/$1.err"
  end=$(date +%s.%N)
  sed -n 's/.*stopped (\([a-z-]*\)) after \([0-9]*\) passes, \([0-9.e+-]*\) s;.*/\1 \2 \3/p' \
    "$work/$1.err" | {
    read -r why passes seconds
    [[ "$why" == target-error ]] || echo "  $1: stopped by $why, not the target" >&2
    echo "$passes $seconds $(awk -v a="$start" -v b="$end" 'BEGIN {print b - a}')" >>"$work/$1.t"
  }
}
for ((i = 0; i < runs; i++)); do
  one old "$old" "$@"
  one new "$new" "$@"
done
col() { awk -v c="$2" '{print $c}' "$work/$1.t" | median; }
printf '  %-4s %8s %12s %12s\n' "" passes "loop s" "process s"
for b in old new; do printf '  %-4s %8s %12s %12s\n' "$b" "$(col $b 1)" "$(col $b 2)" "$(col $b 3)"; done
ratio() { awk -v a="$(col old "$1")" -v b="$(col new "$1")" 'BEGIN {printf "%.2f", a / b}'; }
echo "  old / new: passes $(ratio 1), pass loop $(ratio 2)x, process $(ratio 3)x"
