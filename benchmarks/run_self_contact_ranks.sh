#!/usr/bin/env bash
# Self-contact's cost on several ranks and threads: the hanging 1024² S1-like sheet of
# jobs/make_large_sheet.sh, where nothing touches, on 1 and 2 ranks (and threads), with
# self-contact off and on (docs/contact.md, "Self-contact", "Parallel runs and restarts").
#   benchmarks/run_self_contact_ranks.sh [NAME=BUILD_DIR ...]
# Each NAME=BUILD_DIR (default: this=build/release) is a release build of the solver; the builds
# are run in turns, round by round, so that the machine's drift falls on each alike.
# Settings, from the environment: RANKS (default "1 2"), THREADS (threads a rank, default 1),
# ROUNDS (default 3), NODES (default 1024).
# A step's cost is (wall(120) − wall(60)) / 60 of runs with one frame each, the least over the
# rounds: the first step, which builds the candidate lists, and the start-up cancel.
# Writes benchmarks/results/self-contact-ranks-<host>-<date>.md (-2, -3, ... for later runs of
# the day).
set -euo pipefail
cd "$(dirname "$0")/.."
builds=("$@")
[[ ${#builds[@]} -eq 0 ]] && builds=(this=build/release)
ranks=${RANKS:-1 2}
threads=${THREADS:-1}
rounds=${ROUNDS:-3}
nodes=${NODES:-1024}
for spec in "${builds[@]}"; do
  [[ -x ${spec#*=}/cosserat ]] || {
    echo "error: no ${spec#*=}/cosserat (build it with cmake --build --preset release)" >&2
    exit 2
  }
done
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
jobs/make_large_sheet.sh "$nodes" 60 "$work/sheet.toml"
on=(--set 'self_contact={}' --set material.thickness=0.0005)

wall() {  # build ranks threads steps [args...]: one run's wall time, s
  local build=$1 p=$2 t=$3 steps=$4
  shift 4
  OMP_PROC_BIND=close mpiexec -n "$p" --oversubscribe --bind-to none "$build/cosserat" run \
    "$work/sheet.toml" -q --threads "$t" \
    -o "$work/run.h5" --overwrite --summary "$work/run.json" --set time.steps="$steps" \
    --set time.output_every="$steps" "$@" >/dev/null
  /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['wall_seconds'])" \
    "$work/run.json"
}

declare -A least
for ((round = 0; round < rounds; ++round)); do
  for spec in "${builds[@]}"; do
    for p in $ranks; do
      for t in $threads; do
        for mode in off on; do
          args=()
          [[ $mode == on ]] && args=("${on[@]}")
          for steps in 60 120; do
            key="${spec%%=*} $p $t $mode $steps"
            w=$(wall "${spec#*=}" "$p" "$t" "$steps" "${args[@]}")
            least[$key]=$(/usr/bin/python3 -c "print(min($w, ${least[$key]:-1e300}))")
          done
        done
      done
    done
  done
done

date=$(date -u +%Y-%m-%d)
stem=benchmarks/results/self-contact-ranks-$(hostname -s)-$date
out=$stem.md
for ((i = 2; ; ++i)); do  # a later run of the day beside the earlier ones
  [[ -e $out ]] || break
  out=$stem-$i.md
done
{
  echo "# Self-contact's cost on several ranks, $date"
  echo
  echo "Machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc --all) cores;"
  echo "compiler: $(c++ --version | head -1); git $(git rev-parse --short=12 HEAD); OMP_PROC_BIND=close."
  echo "\`benchmarks/run_self_contact_ranks.sh ${builds[*]}\`: the hanging ${nodes}² sheet, where"
  echo "nothing touches; ms a step after the first, (wall(120) − wall(60)) / 60, the least of"
  echo "$rounds rounds."
  echo
  echo "| build | ranks | threads | off (ms a step) | on (ms a step) | on / off − 1 |"
  echo "|---|---|---|---|---|---|"
  for spec in "${builds[@]}"; do
    for p in $ranks; do
      for t in $threads; do
        n=${spec%%=*}
        /usr/bin/python3 -c "
off = (${least[$n $p $t off 120]} - ${least[$n $p $t off 60]}) / 60
on = (${least[$n $p $t on 120]} - ${least[$n $p $t on 60]}) / 60
print(f'| $n | $p | $t | {1e3 * off:.1f} | {1e3 * on:.1f} | {on / off - 1:+.0%} |')"
      done
    done
  done
} >"$out"
cat "$out"
