#!/usr/bin/env bash
# jobs/slurm_large_sheet.sbatch under a real one-node Slurm that this test starts
# (jobs/slurm_local.sh), submitted at a small size twice: with the ranks and threads it derives
# from the machine, and with RANKS_PER_NODE=2 (two ranks through srun and PMIx). Checks that
# each job ends well, that its summary has the ranks and threads the job derived, that the
# scaling log has a line for each with the revision, ranks, threads, machine and date, and that
# both runs wrote the same positions bit for bit (the split changes nothing, docs/parallel.md).
#   tests/jobs/test_slurm.sh COSSERAT WORKDIR       (from the repository root)
# Exit status 77 (ctest: skipped), with the reason, where Slurm cannot start here.
set -euo pipefail
cosserat=$1
work=$2
mkdir -p "$work"
work=$(cd "$work" && pwd)
rm -rf "$work/runs" "$work"/job-*.log
trap 'jobs/slurm_local.sh stop "$work/slurm"' EXIT
status=0
jobs/slurm_local.sh start "$work/slurm" || status=$?
if [[ $status == 3 ]]; then
  echo "SKIPPED: Slurm cannot start on this machine (reason above)"
  exit 77
fi
[[ $status == 0 ]] || exit "$status"
export SLURM_CONF=$work/slurm/slurm.conf
fail() {
  echo "FAILED: $*" >&2
  cat "$work"/job-*.log >&2 || true
  exit 1
}

domains=$(lscpu -p=NODE | grep -v '^#' | sort -u | wc -l)
cores=$(lscpu -p=SOCKET,CORE | grep -v '^#' | sort -u | wc -l)
derived_ranks=$((domains > 0 ? domains : 1))
derived_threads=$((cores / derived_ranks > 0 ? cores / derived_ranks : 1))
grid=33
steps=20
for ranks_per_node in derived 2; do
  env=(OUTDIR="$work/runs" COSSERAT="$cosserat")
  [[ $ranks_per_node == derived ]] || env+=(RANKS_PER_NODE="$ranks_per_node")
  job=$(env "${env[@]}" sbatch --parsable --output="$work/job-%j.log" \
    jobs/slurm_large_sheet.sbatch "$grid" "$steps")
  # Polled here: sbatch --wait sleeps for seconds between its looks.
  state=
  for _ in $(seq 1200); do
    state=$(scontrol show job "$job" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
    [[ $state == PENDING || $state == RUNNING || $state == CONFIGURING || $state == COMPLETING ]] || break
    sleep 0.2
  done
  [[ $state == COMPLETED ]] || fail "job $job ($ranks_per_node ranks a machine) ended $state"
done

/usr/bin/python3 - "$work/runs" "$grid" "$steps" "$derived_ranks" "$derived_threads" <<'PY' || fail "the checks above"
import csv, json, sys
import h5py, numpy as np
runs, grid, steps, ranks, threads = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
expected = [(ranks, threads), (2, max(1, ranks * threads // 2))]
rows = list(csv.DictReader(open(f"{runs}/scaling.csv")))
assert len(rows) == 2, f"scaling.csv has {len(rows)} lines, not 2"
positions = []
for (r, t), row in zip(expected, rows):
    stem = f"{runs}/sheet{grid}-{r}x{t}"
    summary = json.load(open(stem + ".json"))
    assert (summary["ranks"], summary["threads"]) == (r, t), (stem, summary["ranks"], summary["threads"])
    assert summary["status"] == "ok" and summary["steps"] == steps, (stem, summary["status"], summary["steps"])
    for key in ("date", "revision", "machine", "cpu"):
        assert row[key], f"scaling.csv: no {key}"
    assert (int(row["ranks"]), int(row["threads"]), row["launcher"]) == (r, t, "slurm"), row
    assert row["grid"] == f"{grid}x{grid}" and float(row["node_steps_per_second"]) > 0, row
    with h5py.File(stem + ".h5") as f:
        positions.append(f["positions"][-1])
        assert f["step"][-1] == steps
assert np.array_equal(positions[0], positions[1]), "the two splits' positions differ"
print(f"ok: {expected[0][0]}x{expected[0][1]} and {expected[1][0]}x{expected[1][1]} under Slurm, "
      "the same positions; scaling.csv has both")
PY
