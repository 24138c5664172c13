#!/usr/bin/python3
"""ctest entries for distributed renders (docs/distributed.md), registered in tests/CMakeLists.txt
when the build found MPI. Each runs `mpirun --oversubscribe -np K photonbound ...` on this machine
(ranks on one node: the same code paths as a cluster, over shared memory).

  mpi_test.py MODE --photonbound EXE --mpirun MPIRUN --scenes DIR

  same-image   SPPM and PPM renders (and SPPM with --adaptive paths) with 1, 2 and 3 ranks
               (one thread each) and the plain
               binary give the same pixels bit for bit: each rank traces its own photons, every
               rank gathers from all of them in photon order, and each pixel's state is computed
               by one rank exactly as one process computes it
  target-stop  a --target-error render stops at the same pass, with the same stop line and
               image, on 2 ranks as in one process
  resume       4 passes on 2 ranks, resumed on 3 ranks to 8, equal the plain 8-pass render (and
               with --adaptive paths, 18 on 2 ranks and 3 more on 3)
  failure      a rank killed mid-render ends the run with a non-zero exit and mpirun's line
               naming the rank, and the last checkpoint resumes in one process; SIGUSR1 to
               mpirun (which forwards it) stops a render as Ctrl-C stops one process: the pass
               is finished and the image and state written; --adaptive photons is refused with
               one line
"""

import argparse
import hashlib
import os
import re
import select
import signal
import subprocess
import sys
import tempfile
import time

import OpenImageIO as oiio

# mpirun as root (CI containers); ranks on one node over shared memory only (btl self,vader: no
# network transport to probe), without the kernel's cross-memory attach (containers forbid
# ptrace) and with the shared-memory files in /tmp (a container's /dev/shm may be 64 MB); started
# by the "isolated" launcher: every rank on this node, with no ssh needed (a fresh machine has
# none, and mpirun's default launcher refuses to start without it even for local ranks).
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_btl="self,vader", OMPI_MCA_btl_vader_single_copy_mechanism="none",
           OMPI_MCA_btl_vader_backing_directory="/tmp", OMPI_MCA_plm="isolated",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def pixels(path):
    """A digest of an EXR's pixels (its metadata holds the command line, which differs)."""
    buf = oiio.ImageBuf(path)
    data = buf.get_pixels(oiio.FLOAT)
    if data is None or buf.has_error:
        sys.exit(f"cannot read {path}: {buf.geterror()}")
    return hashlib.sha256(data.tobytes()).hexdigest()


class Runner:
    def __init__(self, args, work):
        self.exe, self.mpirun, self.scenes, self.work = args.photonbound, args.mpirun, args.scenes, work

    def path(self, name):
        return os.path.join(self.work, name)

    def plain(self, *argv):
        return subprocess.run([self.exe, *argv], capture_output=True, text=True, env=ENV,
                              timeout=300)

    def ranks(self, k, *argv):
        return subprocess.run([self.mpirun, "--oversubscribe", "-np", str(k), self.exe, *argv,
                               "--threads", "1"], capture_output=True, text=True, env=ENV,
                              timeout=300)


def ok(result, what):
    if result.returncode != 0:
        sys.exit(f"{what}: exit {result.returncode}\n{result.stdout}\n{result.stderr}")
    return result


def same_image(r):
    cornell = os.path.join(r.scenes, "cornell.gltf")
    # --adaptive paths allocates from pass 17 on (kPathsMinPasses) from every pixel's variances,
    # each computed by the rank that owns the pixel and shared before the allocation.
    for method, passes, adaptive in (("sppm", 8, "radius"), ("ppm", 6, "radius"),
                                     ("sppm", 20, "radius,paths")):
        common = ["--resolution", "96x72", "--passes", str(passes), "--seed", "3", "--quiet",
                  "--method", method, "--adaptive", adaptive]
        ok(r.plain("render", cornell, "-o", r.path("plain.exr"), *common), "plain render")
        want = pixels(r.path("plain.exr"))
        for k in (1, 2, 3):
            out = r.path(f"np{k}.exr")
            ok(r.ranks(k, "render", cornell, "-o", out, *common), f"-np {k} {method}")
            if pixels(out) != want:
                sys.exit(f"{method}: -np {k} gives another image than one process")
        print(f"{method} --adaptive {adaptive}: -np 1, 2, 3 and the plain binary give the same "
              "pixels")


def stop_line(stderr):
    lines = [l for l in stderr.splitlines() if l.startswith("photonbound: stopped")]
    if not lines:
        sys.exit("no stop line in:\n" + stderr)
    # The seconds differ; the pass, the reason and the figures must not.
    return re.sub(r"passes, [0-9.e+-]+ s;", "passes, T s;", lines[-1])


def target_stop(r):
    cornell = os.path.join(r.scenes, "cornell.gltf")
    common = ["--resolution", "96x72", "--target-error", "0.02", "--time", "120", "--seed", "5",
              "--progress"]
    one = ok(r.plain("render", cornell, "-o", r.path("one.exr"), *common), "plain render")
    two = ok(r.ranks(2, "render", cornell, "-o", r.path("two.exr"), *common), "-np 2 render")
    a = stop_line(one.stderr).replace(r.path("one.exr"), "OUT")
    b = stop_line(two.stderr).replace(r.path("two.exr"), "OUT")
    if "(target-error)" not in a or a != b:
        sys.exit(f"stop lines differ or not on the target:\n  one process: {a}\n  2 ranks:     {b}")
    if pixels(r.path("one.exr")) != pixels(r.path("two.exr")):
        sys.exit("the 2-rank target stop wrote another image than one process")
    if "2 MPI ranks; per pass" not in two.stderr:
        sys.exit("no exchange line from the 2-rank render:\n" + two.stderr)
    print("target stop: same pass, bound and image;", b)


def resume(r):
    cornell = os.path.join(r.scenes, "cornell.gltf")
    # With paths, the state file holds every pixel's path history, which each rank keeps for
    # the pixels it owns: the first part runs past pass 16, where the allocation begins.
    for adaptive, first, total in (("radius", 4, 8), ("radius,paths", 18, 21)):
        common = ["--resolution", "96x72", "--seed", "3", "--quiet", "--adaptive", adaptive]
        state = r.path("s.pbstate")
        ok(r.ranks(2, "render", cornell, "-o", r.path("r4.exr"), *common, "--passes",
                   str(first), "--state", state), f"-np 2 first {first} passes")
        ok(r.ranks(3, "resume", state, "-o", r.path("r8.exr"), "--passes", str(total),
                   "--quiet"), "-np 3 resume")
        ok(r.plain("render", cornell, "-o", r.path("p8.exr"), *common, "--passes", str(total)),
           f"plain {total}")
        if pixels(r.path("r8.exr")) != pixels(r.path("p8.exr")):
            sys.exit(f"--adaptive {adaptive}: 2 ranks then 3 ranks resumed give another image "
                     f"than {total} passes in one process")
        print(f"resume, --adaptive {adaptive}: {first} passes on 2 ranks + {total - first} on 3 "
              f"ranks = {total} passes in one process")


def descends_from(pid, ancestor):
    """Whether process `pid` is `ancestor` or below it."""
    for _ in range(16):
        if pid == ancestor:
            return True
        try:
            with open(f"/proc/{pid}/stat") as f:
                pid = int(f.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            return False
        if pid <= 1:
            return False
    return False


def rank_pid(rank, mpirun):
    """The pid of the running photonbound of this MPI rank under the mpirun process `mpirun`
    (from its environment; other tests' ranks may be running too)."""
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or not descends_from(int(pid), mpirun):
            continue
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if b"photonbound" not in f.read().split(b"\0")[0]:
                    continue
            with open(f"/proc/{pid}/environ", "rb") as f:
                env = f.read().split(b"\0")
        except OSError:
            continue
        if f"OMPI_COMM_WORLD_RANK={rank}".encode() in env:
            return int(pid)
    return None


def running(r, out, state, extra):
    cornell = os.path.join(r.scenes, "cornell.gltf")
    argv = [r.mpirun, "--oversubscribe", "-np", "2", r.exe, "render", cornell, "-o", out,
            "--resolution", "128x96", "--passes", "1000000", "--state", state, "--threads", "1",
            *extra]
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=ENV)


def wait_for(path, proc, seconds=60):
    end = time.time() + seconds
    while not os.path.exists(path):
        if proc.poll() is not None or time.time() > end:
            proc.kill()
            sys.exit(f"{path} was never written; exit {proc.returncode}\n{proc.communicate()}")
        time.sleep(0.1)


def failure(r):
    # A killed rank: the run ends (no rank waits forever in a collective), mpirun names the rank,
    # and the last checkpoint resumes.
    out, state = r.path("k.exr"), r.path("k.pbstate")
    proc = running(r, out, state, ["--checkpoint-every", "0.3", "--quiet"])
    wait_for(state, proc)
    time.sleep(0.5)
    pid = rank_pid(1, proc.pid)
    if pid is None:
        proc.kill()
        sys.exit("rank 1 not found")
    os.kill(pid, signal.SIGKILL)
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        sys.exit("the run did not end within 60 s of a rank's death")
    if proc.returncode == 0 or "rank 1" not in err:
        sys.exit(f"a killed rank: exit {proc.returncode}, stderr:\n{err}")
    ok(r.plain("resume", state, "-o", r.path("k2.exr"), "--passes", "1", "--quiet"),
       "resuming the last checkpoint of the killed run")
    print("killed rank 1: exit", proc.returncode, "with mpirun naming rank 1; the checkpoint resumes")

    # SIGUSR1 to mpirun: rank 0 finishes the pass and writes, as on Ctrl-C in one process.
    out, state = r.path("u.exr"), r.path("u.pbstate")
    proc = running(r, out, state, ["--progress"])
    # After the first progress line a pass has run, so every rank is past installing its
    # handler (before it, SIGUSR1's default action would end a rank).
    seen = []
    deadline = time.time() + 60
    while time.time() < deadline:
        ready, _, _ = select.select([proc.stderr], [], [], 1.0)
        line = proc.stderr.readline() if ready else ""
        if line:
            seen.append(line)
        if line.startswith("pass ") or proc.poll() is not None:
            break
    proc.send_signal(signal.SIGUSR1)
    try:
        _, rest = proc.communicate(timeout=60)
        err = "".join(seen) + rest
    except subprocess.TimeoutExpired:
        proc.kill()
        sys.exit("SIGUSR1 did not end the run within 60 s")
    if proc.returncode != 0 or "stopped (interrupted)" not in err:
        sys.exit(f"SIGUSR1: exit {proc.returncode}, stderr:\n{err}")
    if not (os.path.exists(out) and os.path.exists(state)):
        sys.exit("SIGUSR1: the image or the state was not written")
    ok(r.plain("resume", state, "-o", r.path("u2.exr"), "--passes", "1", "--quiet"),
       "resuming after SIGUSR1")
    print("SIGUSR1: stopped (interrupted), image and state written")

    # What does not run distributed yet is refused in one line, not rendered wrongly.
    cornell = os.path.join(r.scenes, "cornell.gltf")
    res = r.ranks(2, "render", cornell, "-o", r.path("a.exr"), "--adaptive", "photons",
                  "--passes", "2", "--quiet")
    if res.returncode == 0 or "does not run distributed yet" not in res.stderr:
        sys.exit(f"--adaptive photons on 2 ranks: exit {res.returncode}\n{res.stderr}")
    if os.path.exists(r.path("a.exr")):
        sys.exit("--adaptive photons on 2 ranks wrote an image")
    print("--adaptive photons on 2 ranks: refused")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["same-image", "target-stop", "resume", "failure"])
    p.add_argument("--photonbound", required=True)
    p.add_argument("--mpirun", required=True)
    p.add_argument("--scenes", required=True)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as work:
        r = Runner(args, work)
        {"same-image": same_image, "target-stop": target_stop, "resume": resume,
         "failure": failure}[args.mode](r)


if __name__ == "__main__":
    main()
