#!/usr/bin/env bash
# Strong and weak scaling of the S1-like sheet on this machine: every layout of LAYOUTS run
# through jobs/mpirun_large_sheet.sh, each run appended to OUTDIR/{strong,weak}/scaling.csv
# (date, revision, machine, ranks, threads, rates), then the efficiency table and plot
# (jobs/plot_scaling.py) as OUTDIR/scaling.{md,png}.
#   jobs/scaling_study.sh [OUTDIR=runs/scaling]
# Settings, from the environment:
#   LAYOUTS  ranks x threads            (default "1x1 1x2 2x1 2x2")
#   STRONG   the strong study's grid    (default 1024: 1024² nodes on every layout)
#   WEAK     the weak study's grid on one core (default 512: WEAK² nodes a core, the grid
#            rounded to the nearest node)
#   STEPS    steps a run                (default 200)
# Layouts with more ranks x threads than this machine's cores run unbound, and are marked so.
# Only the first and last positions are written, with no fields and no checkpoint, so the
# time is the step's.
set -euo pipefail
outdir=${1:-runs/scaling}
here=$(cd "$(dirname "$0")" && pwd)
layouts=${LAYOUTS:-1x1 1x2 2x1 2x2}
strong=${STRONG:-1024}
weak=${WEAK:-512}
steps=${STEPS:-200}
cores=$(nproc)
export CHECKPOINT_EVERY=0 OVERWRITE=1
export COSSERAT_ARGS="-q --set time.output_every=$steps --set output.fields=[]"
for layout in $layouts; do
  ranks=${layout%x*}
  threads=${layout#*x}
  over=0
  (( ranks * threads > cores )) && over=1
  grid=$(/usr/bin/python3 -c "print(round($weak * ($ranks * $threads) ** 0.5))")
  echo "== $layout: strong $strong², weak $grid²$( ((over)) && echo ", oversubscribed: $((ranks * threads)) threads on $cores cores")"
  OVERSUBSCRIBE=$over "$here/mpirun_large_sheet.sh" "$ranks" "$threads" "$strong" "$steps" "$outdir/strong"
  OVERSUBSCRIBE=$over "$here/mpirun_large_sheet.sh" "$ranks" "$threads" "$grid" "$steps" "$outdir/weak"
done
/usr/bin/python3 "$here/plot_scaling.py" --strong "$outdir/strong/scaling.csv" \
  --weak "$outdir/weak/scaling.csv" --cores "$cores" --output "$outdir/scaling"
