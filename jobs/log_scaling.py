#!/usr/bin/python3
"""Appends one run of the job scripts to a scaling log, a CSV file with a header.

    jobs/log_scaling.py SUMMARY.json LOG.csv LAUNCHER NODES

SUMMARY.json is the run's summary (docs/output.md); LAUNCHER says what started it (slurm,
mpirun); NODES is the number of machines it ran on. Each line carries what makes the number
comparable: the date, the git revision of the source it was built from, the machine, the
ranks, threads and split, the grid, and the measured rates (jobs/README.md).
"""
import csv
import datetime
import json
import os
import platform
import subprocess
import sys

FIELDS = ["date", "revision", "machine", "cpu", "launcher", "machines", "ranks", "threads",
          "split", "grid", "steps", "wall_seconds", "node_steps_per_second", "halo_seconds",
          "status", "summary"]


def revision(where):
    """The source's commit, marked -dirty when it has changes; 'unknown' outside git."""
    try:
        head = subprocess.run(["git", "-C", where, "rev-parse", "--short=12", "HEAD"],
                              capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", where, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
        return head + ("-dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main():
    if len(sys.argv) != 5:
        sys.stderr.write(__doc__)
        return 2
    summary_path, log_path, launcher, machines = sys.argv[1:]
    try:
        with open(summary_path) as f:
            summary = json.load(f)
    except (OSError, ValueError) as error:
        sys.stderr.write(f"log_scaling.py: cannot read the summary {summary_path}: {error}\n")
        return 2
    row = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "revision": revision(os.path.dirname(os.path.abspath(__file__))),
        "machine": platform.node(),
        "cpu": cpu_model(),
        "launcher": launcher,
        "machines": machines,
        "ranks": summary.get("ranks"),
        "threads": summary.get("threads"),
        "split": "x".join(str(s) for s in summary.get("split", [])),
        "grid": "x".join(str(g) for g in summary.get("grid", [])),
        "steps": summary.get("steps"),
        "wall_seconds": summary.get("wall_seconds"),
        "node_steps_per_second": summary.get("node_steps_per_second"),
        "halo_seconds": summary.get("halo_seconds"),
        "status": summary.get("status"),
        "summary": summary_path,
    }
    new = not os.path.exists(log_path) or os.path.getsize(log_path) == 0
    with open(log_path, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        if new:
            writer.writeheader()
        writer.writerow(row)
    print(f"{log_path}: {row['ranks']} ranks x {row['threads']} threads, "
          f"{row['node_steps_per_second']} node-steps/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
