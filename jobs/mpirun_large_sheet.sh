#!/usr/bin/env bash
# A large S1-like sheet under plain mpirun, RANKS x THREADS on this machine.
#   jobs/mpirun_large_sheet.sh RANKS THREADS [NODES=4096] [STEPS=1000] [OUTDIR=runs]
# Writes OUTDIR/sheet<NODES>-<RANKS>x<THREADS>.{toml,h5,xmf,json} (the run summary beside the
# output) and a checkpoint every STEPS/10 steps, and appends the run to OUTDIR/scaling.csv
# (jobs/log_scaling.py). Run it again with RESUME=1 to continue from the checkpoint after a
# kill (or to start over when the kill came before the first one), or with OVERWRITE=1 to
# replace the files of an earlier run, which a run otherwise refuses to.
set -euo pipefail
if [[ $# -lt 2 ]]; then
  sed -n '2,8p' "$0"
  exit 2
fi
ranks=$1
threads=$2
nodes=${3:-4096}
steps=${4:-1000}
outdir=${5:-runs}
here=$(cd "$(dirname "$0")" && pwd)
cosserat=${COSSERAT:-$here/../build/release/cosserat}
if [[ ! -x $cosserat ]]; then
  echo "error: $cosserat not found: build first (bash quickstart.sh demo) or set COSSERAT" >&2
  exit 2
fi
mkdir -p "$outdir"
stem=$outdir/sheet$nodes-${ranks}x$threads
"$here/make_large_sheet.sh" "$nodes" "$steps" "$stem.toml"

restart=()
if [[ ${RESUME:-0} == 1 ]]; then
  if [[ -f $stem.checkpoint.h5 ]]; then restart=(--restart "$stem.checkpoint.h5"); else restart=(--overwrite); fi
elif [[ ${OVERWRITE:-0} == 1 ]]; then
  restart=(--overwrite)
fi
root=()
if [[ $(id -u) == 0 ]]; then root=(--allow-run-as-root); fi
# One rank per THREADS cores, its threads kept on them.
export OMP_NUM_THREADS=$threads OMP_PROC_BIND=close OMP_PLACES=cores
mpirun "${root[@]}" -np "$ranks" --map-by "slot:PE=$threads" --bind-to core \
  "$cosserat" run "$stem.toml" -o "$stem.h5" --summary "$stem.json" \
  --checkpoint-every $(( steps / 10 > 0 ? steps / 10 : 1 )) "${restart[@]}"
/usr/bin/python3 "$here/log_scaling.py" "$stem.json" "$outdir/scaling.csv" mpirun 1
