#!/usr/bin/env bash
# Distributed renders against one process (issue 38, docs/distributed.md): the pass rate of
# `mpirun -np 2` with one thread per rank against one process with two threads, on the default
# scene (512x512 Cornell box, 100k photons per pass) and at 1080p with 1M photons per pass, and
# what rank 0 exchanged per pass. Runs alternate (one, two, one, two, ...); medians of RUNS.
# Without --progress (stderr is not a terminal): the image is developed, and the states brought
# to rank 0, once at the end. Timings are printed, never asserted.
#   bench/mpi.sh [RUNS]        (build/photonbound from tools/build.sh; about 3 minutes)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
exe="$root/build/photonbound"
runs="${1:-3}"
scene="$root/scenes/cornell.gltf"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_plm=isolated  # tests/mpi_test.py says why
if ! "$exe" --version | grep -q mpirun; then
  echo "bench/mpi.sh: $exe was built without MPI" >&2
  exit 1
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "bench/mpi.sh: $(nproc) hardware threads; load average $(cut -d' ' -f1-3 /proc/loadavg)"

# The stop line's seconds (the pass loop, without loading) over its passes.
seconds_of() { sed -n 's/.*stopped (passes) after \([0-9]*\) passes, \([0-9.e+-]*\) s;.*/\2/p' "$1"; }
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

bench() {  # name passes args...
  local name="$1" passes="$2"
  shift 2
  : >"$work/one.t"
  : >"$work/two.t"
  for ((i = 0; i < runs; i++)); do
    "$exe" render "$scene" -o "$work/one.exr" --passes "$passes" --seed 1 --threads 2 \
      "$@" 2>"$work/one.err"
    seconds_of "$work/one.err" >>"$work/one.t"
    mpirun --oversubscribe -np 2 "$exe" render "$scene" -o "$work/two.exr" --passes "$passes" \
      --seed 1 --threads 1 "$@" 2>"$work/two.err"
    seconds_of "$work/two.err" >>"$work/two.t"
  done
  local one two
  one="$(median <"$work/one.t")"
  two="$(median <"$work/two.t")"
  echo "== $name, $passes passes"
  awk -v a="$one" -v b="$two" -v n="$passes" 'BEGIN {
    printf "  one process, 2 threads   %.3f s per pass\n", a / n
    printf "  -np 2, 1 thread each     %.3f s per pass\n", b / n
    printf "  pass rate -np 2 / one    %.3f\n", a / b }'
  sed -n 's/^photonbound: 2 MPI ranks; /  /p' "$work/two.err"
}

bench "default scene (512x512, 100k photons per pass)" 40
bench "1920x1080, 1M photons per pass" 4 --resolution 1920x1080 --photons-per-pass 1000000
