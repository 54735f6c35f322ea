#!/usr/bin/python3
"""Kill-and-restart stress test (issue 12, deliver 4).

Each trial runs one scene to its end through 1-3 SIGKILLs: every segment starts on 1, 2 or 3
ranks (another count than the segment before), restarts from the run's checkpoint when there
is one (else starts over), and is killed at a random moment, right when a checkpoint is being
written (its .partial file exists), or right when a frame is being written (the HDF5 file has
just grown); the last segment runs to the end. The trial's output must then equal an
uninterrupted run's bitwise (dataset bytes of /positions, /time, /step), and its XDMF file must
parse and name every frame. The tally and one line per trial go to
benchmarks/results/stress-restart-<host>-<date>.md with the machine, compiler and git revision.

    /usr/bin/python3 benchmarks/run_stress_restart.py [--cosserat build/rel/cosserat]
        [--trials 30] [--seed 1]

Uses mpirun (Open MPI: --allow-run-as-root --oversubscribe) and h5py; nothing else.
"""
import argparse
import datetime
import os
import random
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as xml

import h5py

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(REPO, "scenes", "s1_clothesline.toml")
# 24 x 24 nodes, 3000 steps: a few seconds a run, 121 frames and 9 checkpoints to be killed in.
OVERRIDES = ["grid.nodes=[24,24]", "time.steps=3000", "time.output_every=25"]
# --adaptive: the same sheet over the same 3 s in adaptive steps (docs/stability.md), its fix
# window in seconds (a window in steps is refused there), frames every 0.025 s.
ADAPTIVE_OVERRIDES = ["grid.nodes=[24,24]", "time={duration=3.0, output_dt=0.025}",
                      "fix=[{nodes=[[0,0],[0,9]]}]"]
# --contact: the cube thrown into a net (scenes/contact/cube_net_25.toml), a free body in
# contact from step 450 on, for its first 0.6 s (3000 steps of 0.2 ms), frames every 0.01 s;
# the solids' datasets are compared too.
CONTACT_SCENE = os.path.join(REPO, "scenes", "contact", "cube_net_25.toml")
CONTACT_OVERRIDES = ["time.duration=0.6"]
CHECKPOINT_EVERY = 330
SEGMENT_TIMEOUT = 300  # seconds; a segment still running then has hung
MODES = ("random", "checkpoint", "frame")


def command(cosserat, ranks, output, restart):
    line = ["mpirun", "-np", str(ranks), "--allow-run-as-root", "--oversubscribe", cosserat,
            "run", SCENE, "-q", "-o", output, "--checkpoint-every", str(CHECKPOINT_EVERY)]
    for o in OVERRIDES:
        line += ["--set", o]
    # A segment without a checkpoint to restart from starts the output over, as a user would
    # after a kill before the first checkpoint.
    line += ["--restart", restart] if restart else ["--overwrite"]
    return line


def environment():
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_MCA_mpi_yield_when_idle="1",
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def ranks_of(mpirun_pid):
    """The rank processes mpirun started (its children on this one machine)."""
    try:
        with open(f"/proc/{mpirun_pid}/task/{mpirun_pid}/children") as f:
            return [int(p) for p in f.read().split()]
    except OSError:
        return []


def datasets(path):
    with h5py.File(path, "r") as f:
        names = ["/positions", "/time", "/step"]
        if "solids" in f:
            names += [f"/solids/{i}/{d}" for i in f["solids"]
                      for d in ("position", "orientation", "world_vertices")]
        return {name: f[name][()].tobytes() for name in names}


def xdmf_frames(path):
    """The entries of the temporal collection: one per frame (the cloth alone, or the cloth and
    the solids in a spatial collection)."""
    root = xml.parse(path).getroot()
    return len(root.findall("./Domain/Grid[@CollectionType='Temporal']/Grid"))


def run_segment(cosserat, ranks, output, restart, mode, duration, rng, log):
    """Starts a segment and kills one of its ranks as `mode` says; returns (killed, rc, when)."""
    process = subprocess.Popen(command(cosserat, ranks, output, restart), env=environment(),
                               stdout=log, stderr=log)
    start = time.monotonic()
    partial = os.path.splitext(output)[0] + ".checkpoint.h5.partial"
    killed, when = False, ""
    # After the start and, mostly, after the first checkpoint, so that most segments restart.
    deadline = start + rng.uniform(0.25, 0.95) * duration
    size = None
    while process.poll() is None and not killed:
        now = time.monotonic()
        if now - start > SEGMENT_TIMEOUT:
            break
        fire = False
        if mode == "random":
            fire = now >= deadline
        elif mode == "checkpoint":
            fire = now >= deadline and os.path.exists(partial)
        elif mode == "frame":
            try:
                current = os.stat(output).st_size
            except OSError:
                current = None
            fire = now >= deadline and size is not None and current != size
            size = current
        if fire:
            targets = ranks_of(process.pid)
            if targets:
                target = rng.choice(targets)
                try:
                    os.kill(target, signal.SIGKILL)
                    killed = True
                    when = f"{now - start:.2f} s"
                except ProcessLookupError:
                    pass
        if mode != "frame" and not fire:
            time.sleep(0.001)
    try:
        rc = process.wait(timeout=max(1, SEGMENT_TIMEOUT - (time.monotonic() - start)))
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        return killed, "hang", when
    return killed, rc, when


def trial(cosserat, index, directory, reference, duration, rng):
    output = os.path.join(directory, "out.h5")
    checkpoint = os.path.join(directory, "out.checkpoint.h5")
    log_path = os.path.join(directory, "log.txt")
    segments, kills, previous = [], 0, None
    planned = rng.randint(1, 3)
    with open(log_path, "w") as log:
        while True:
            ranks = rng.choice([r for r in (1, 2, 3) if r != previous])
            previous = ranks
            restart = checkpoint if os.path.exists(checkpoint) else None
            final = kills >= planned
            mode = "none" if final else rng.choice(MODES)
            if final:
                process = subprocess.run(command(cosserat, ranks, output, restart),
                                         env=environment(), stdout=log, stderr=log,
                                         timeout=SEGMENT_TIMEOUT)
                rc, killed, when = process.returncode, False, ""
            else:
                killed, rc, when = run_segment(cosserat, ranks, output, restart, mode,
                                               duration[ranks], rng, log)
            segments.append(f"{ranks}r{'+R' if restart else ''}:{mode}"
                            f"{'@' + when if killed else ''}->{rc}")
            if rc == "hang":
                return segments, kills, "hang: a segment ran past the timeout"
            if killed:
                kills += 1
                continue
            if rc != 0:
                return segments, kills, f"segment exited {rc} without being killed"
            if final or not killed:
                break
    got = datasets(output)
    for name, expected in reference.items():
        if got[name] != expected:
            return segments, kills, f"{name} differs from the uninterrupted run"
    frames = len(got["/time"]) // 8
    named = xdmf_frames(os.path.splitext(output)[0] + ".xmf")
    if named != frames:
        return segments, kills, f"XDMF names {named} frames, the file holds {frames}"
    return segments, kills, None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cosserat", default=os.path.join(REPO, "build", "rel", "cosserat"))
    parser.add_argument("--trials", type=int, default=30)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--keep", action="store_true", help="keep the trial folders")
    parser.add_argument("--adaptive", action="store_true",
                        help="adaptive steps instead of the fixed step")
    parser.add_argument("--contact", action="store_true",
                        help="the cube thrown into a net: contact with a free body")
    args = parser.parse_args()
    global SCENE
    if args.adaptive:
        OVERRIDES[:] = ADAPTIVE_OVERRIDES
    if args.contact:
        SCENE = CONTACT_SCENE
        OVERRIDES[:] = CONTACT_OVERRIDES
    rng = random.Random(args.seed)
    work = tempfile.mkdtemp(prefix="cosserat_stress_")

    # Uninterrupted runs on 1, 2 and 3 ranks: the reference (they must agree), and how long a
    # segment on that many ranks takes, which the kill moments are drawn against.
    duration, reference = {}, None
    for ranks in (1, 2, 3):
        started = time.monotonic()
        path = os.path.join(work, f"reference_{ranks}.h5")
        subprocess.run(command(args.cosserat, ranks, path, None), env=environment(), check=True,
                       stdout=subprocess.DEVNULL)
        duration[ranks] = time.monotonic() - started
        if reference is None:
            reference = datasets(path)
        elif datasets(path) != reference:
            sys.exit(f"the uninterrupted run on {ranks} ranks differs from the one on 1 rank")

    rows, tally = [], {"trials": 0, "kills": 0, "identical": 0, "failures": 0}
    for index in range(args.trials):
        directory = os.path.join(work, f"trial_{index:02d}")
        os.makedirs(directory)
        segments, kills, failure = trial(args.cosserat, index, directory, reference, duration,
                                         rng)
        tally["trials"] += 1
        tally["kills"] += kills
        tally["identical" if failure is None else "failures"] += 1
        rows.append((index, " ".join(segments), failure or "identical"))
        print(f"trial {index}: {' '.join(segments)}: {failure or 'identical'}", flush=True)
        if failure is None and not args.keep:
            shutil.rmtree(directory)

    host = socket.gethostname().split(".")[0]
    date = datetime.date.today().isoformat()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), "unknown")
    compiler = subprocess.run(["c++", "--version"], capture_output=True,
                              text=True).stdout.splitlines()[0]
    mpi = subprocess.run(["mpirun", "--version"], capture_output=True,
                         text=True).stdout.splitlines()[0]
    revision = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    kinds = {m: sum(s.count(f":{m}@") for _, s, _ in rows) for m in MODES}
    lines = [
        f"# Kill-and-restart stress test, {date}", "",
        f"Machine: {cpu}, {os.cpu_count()} cores, host {host}; compiler: {compiler}, -O3; "
        f"{mpi}; git {revision}{' (with uncommitted changes)' if dirty else ''}; seed {args.seed}.",
        "",
        f"Scene: `{os.path.relpath(SCENE, REPO)}` with `{' '.join('--set ' + o for o in OVERRIDES)}`, "
        f"`--checkpoint-every {CHECKPOINT_EVERY}`, one OpenMP thread per rank; the uninterrupted "
        f"reference runs took {duration[1]:.1f}, {duration[2]:.1f} and {duration[3]:.1f} s on "
        "1, 2 and 3 ranks (and agree bitwise). "
        "Each trial: 1-3 segments killed (SIGKILL to one rank chosen at random; mpirun ends the "
        "others), each on another rank count than the one before (1, 2 or 3, oversubscribed), "
        "restarting from the checkpoint when there is one, then a segment run to the end. Kill "
        "moments, after 25-95 % of an uninterrupted run's wall time on that many ranks: `random` "
        "(then), `checkpoint` (as soon as after that the checkpoint's `.partial` file is seen: "
        "mid-checkpoint), `frame` (as soon as after that the HDF5 file is seen to grow: inside a "
        "frame's write, flush and XDMF append). The output must equal the reference's "
        "/positions, /time and /step (and each solid's position, orientation and placed surface) "
        "byte for byte, and its XDMF file must parse and name every frame.", "",
        "`benchmarks/run_stress_restart.py --trials "
        f"{args.trials} --seed {args.seed}{' --adaptive' if args.adaptive else ''}"
        f"{' --contact' if args.contact else ''}`", "",
        "| trials | kills | random | mid-checkpoint | mid-frame | identical | failures |",
        "|---|---|---|---|---|---|---|",
        f"| {tally['trials']} | {tally['kills']} | {kinds['random']} | {kinds['checkpoint']} | "
        f"{kinds['frame']} | {tally['identical']} | {tally['failures']} |", "",
        "Segments: ranks, `+R` a restart from the checkpoint, the kill moment and when it came "
        "after the segment's start, then the exit status (137: killed; Open MPI reports the "
        "killed rank's signal).", "",
        "| trial | segments | result |", "|---|---|---|"]
    lines += [f"| {i} | {s} | {r} |" for i, s, r in rows]
    kind = ("stress-restart-contact" if args.contact
            else "stress-restart-adaptive" if args.adaptive else "stress-restart")
    stem = os.path.join(REPO, "benchmarks", "results", f"{kind}-{host}-{date}")
    with open(stem + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines[:14]))
    print(f"wrote {stem}.md; trial folders of failures kept in {work}")
    if tally["failures"] == 0 and not args.keep:
        shutil.rmtree(work)
    return 1 if tally["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
