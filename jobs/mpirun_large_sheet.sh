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
# CHECKPOINT_EVERY=0: no checkpoints; COSSERAT_ARGS: more arguments of `cosserat run`, split at
# spaces (a scaling study's: --set time.output_every=STEPS --set output.fields=[]).
checkpoint=(--checkpoint-every "${CHECKPOINT_EVERY:-$(( steps / 10 > 0 ? steps / 10 : 1 ))}")
[[ ${CHECKPOINT_EVERY:-} == 0 ]] && checkpoint=()
read -ra more <<<"${COSSERAT_ARGS:-}"
# One rank per THREADS cores, its threads kept on them; with more ranks x threads than cores
# (OVERSUBSCRIBE=1) nothing is bound, since no binding can give each thread a core.
export OMP_NUM_THREADS=$threads OMP_PROC_BIND=close OMP_PLACES=cores
mapping=(--map-by "slot:PE=$threads" --bind-to core)
if [[ ${OVERSUBSCRIBE:-0} == 1 ]]; then
  mapping=(--oversubscribe --bind-to none)
  export OMP_PROC_BIND=false
fi
mpirun "${root[@]}" -np "$ranks" "${mapping[@]}" \
  "$cosserat" run "$stem.toml" -o "$stem.h5" --summary "$stem.json" \
  "${checkpoint[@]}" "${restart[@]}" "${more[@]}"
/usr/bin/python3 "$here/log_scaling.py" "$stem.json" "$outdir/scaling.csv" mpirun 1
