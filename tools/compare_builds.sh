#!/usr/bin/env bash
# Byte-for-byte regression check of two builds of cosserat:
#
#   tools/compare_builds.sh OLD_BUILD_DIR NEW_BUILD_DIR [WORK_DIR]
#
# Runs every scene in scenes/*.toml with every explicit integrator, and the semi-implicit one
# on S1 only (it is slow), for a bounded number of steps, with OLD_BUILD_DIR/cosserat and
# NEW_BUILD_DIR/cosserat (`cosserat run SCENE --set ... -q -o X.h5`, one rank, one thread),
# and prints one line per (scene, integrator): identical or DIFFERENT. Exits 1 on any
# difference, 2 on bad usage. Meant for changes that must not change the numbers (refactoring,
# build flags, moving code): a release build against a release build.
#
# What "identical" means:
#   - the two runs' exit statuses are equal (a run that goes unstable within the step count is
#     fine, as long as both builds do so the same way), and so is whether each left an .h5/.xmf;
#   - the .xmf files are equal (cmp); both runs write the same file name in their own folder;
#   - the .h5 files are equal byte for byte (cmp), EXCEPT the four seconds bytes of each HDF5
#     "object modification time" message (header message type 0x0012, one per dataset:
#     /positions, /time, /step). Builds before 2026-11-27 stamp every dataset with the
#     wall-clock second it was last written (HDF5's default), so two runs of the SAME such
#     binary a second apart differ there and nowhere else; later builds turn the stamps off
#     (src/io/frame_writer.cpp), which also moves the header bytes: between a stamped and an
#     unstamped build only the dataset check below can say "same numbers".
#     Those bytes are masked in both files, only where both files have such a message at the
#     same offset; every other byte (superblock, object headers, the attributes scene /
#     integrator / version / overrides, chunk indexes, all raw data) must match;
#   - and, as a second check that says which data differ, the raw bytes of /positions, /time
#     and /step (h5py .tobytes(), with shape and dtype) and the values of the root attributes.
#
# Environment: SCENES (default: the repository's scenes/*.toml), STEPS (400), OUTPUT_EVERY (50),
# SEMI_STEPS (20), SEMI_OUTPUT_EVERY (5), INTEGRATORS (the explicit ones, space-separated).
# Needs /usr/bin/python3 with h5py (Debian: python3-h5py) and cmp.
set -uo pipefail

if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 OLD_BUILD_DIR NEW_BUILD_DIR [WORK_DIR]" >&2
  exit 2
fi
old_exe=$(realpath -m "$1")/cosserat
new_exe=$(realpath -m "$2")/cosserat
for exe in "$old_exe" "$new_exe"; do
  if [[ ! -x $exe ]]; then
    echo "$0: no executable $exe" >&2
    exit 2
  fi
done
repo=$(cd "$(dirname "$0")/.." && pwd)
if [[ $# -eq 3 ]]; then
  work=$3
  mkdir -p "$work" || exit 2
else
  work=$(mktemp -d /tmp/compare_builds.XXXXXX) || exit 2
fi
work=$(cd "$work" && pwd)

steps=${STEPS:-400}
output_every=${OUTPUT_EVERY:-50}
semi_steps=${SEMI_STEPS:-20}
semi_output_every=${SEMI_OUTPUT_EVERY:-5}
read -r -a integrators <<<"${INTEGRATORS:-verlet symplectic-euler euler midpoint rk4 leapfrog velocity-verlet tc-verlet verlet-lagged}"
if [[ -n ${SCENES:-} ]]; then
  read -r -a scenes <<<"$SCENES"
else
  scenes=("$repo"/scenes/*.toml)
fi

# One rank (an MPI singleton), one thread: the same environment for both builds.
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

compare_h5=$(cat <<'PY'
import re, sys
import h5py

a_path, b_path = sys.argv[1], sys.argv[2]
a, b = open(a_path, "rb").read(), open(b_path, "rb").read()
problems = []
if len(a) != len(b):
    problems.append(f"file sizes {len(a)} / {len(b)}")
else:
    # Object modification time message, version 1 object header: type 0x0012, size 8, flags,
    # 3 reserved; body: version 1, 3 reserved, 4 bytes of seconds since the epoch.
    stamp = re.compile(rb"\x12\x00\x08\x00.\x00\x00\x00\x01\x00\x00\x00", re.S)
    masked = {m.end() for m in stamp.finditer(a)} & {m.end() for m in stamp.finditer(b)}
    ma, mb = bytearray(a), bytearray(b)
    for o in masked:
        ma[o:o + 4] = mb[o:o + 4] = b"\0\0\0\0"
    if ma != mb:
        first = next(i for i in range(len(ma)) if ma[i] != mb[i])
        count = sum(1 for x, y in zip(ma, mb) if x != y)
        problems.append(f"{count} bytes differ outside the modification-time stamps, first at {first}")
with h5py.File(a_path, "r") as fa, h5py.File(b_path, "r") as fb:
    if sorted(fa.keys()) != sorted(fb.keys()):
        problems.append(f"objects {sorted(fa.keys())} / {sorted(fb.keys())}")
    for name in sorted(set(fa.keys()) & set(fb.keys())):
        da, db = fa[name], fb[name]
        if da.shape != db.shape or da.dtype != db.dtype:
            problems.append(f"/{name}: {da.shape} {da.dtype} / {db.shape} {db.dtype}")
        elif da[()].tobytes() != db[()].tobytes():
            problems.append(f"/{name} differs")
    attrs_a, attrs_b = dict(fa.attrs), dict(fb.attrs)
    for key in sorted(set(attrs_a) | set(attrs_b)):
        if key not in attrs_a or key not in attrs_b or attrs_a[key] != attrs_b[key]:
            problems.append(f"attribute {key} differs")
if problems:
    print("; ".join(problems))
    sys.exit(1)
PY
)

# run BUILD_LABEL EXE SCENE INTEGRATOR STEPS OUTPUT_EVERY -> status in $work/LABEL/NAME.status
run_one() {
  local label=$1 exe=$2 scene=$3 integrator=$4 n=$5 every=$6 name=$7
  local dir=$work/$label
  mkdir -p "$dir"
  rm -f "$dir/$name.h5" "$dir/$name.xmf"
  # Same relative output name in both folders, so that the .xmf (which names its .h5) agree.
  (cd "$dir" && "$exe" run "$scene" --set time.integrator=\""$integrator"\" \
     --set time.steps="$n" --set time.output_every="$every" -q -o "$name.h5" \
     >"$name.log" 2>&1)
  echo $? >"$dir/$name.status"
}

# compare NAME -> prints the verdict line, returns 0 when identical
compare() {
  local name=$1 o=$work/old/$1 n=$work/new/$1 why=()
  local so sn
  so=$(cat "$o.status") sn=$(cat "$n.status")
  [[ $so == "$sn" ]] || why+=("exit status $so / $sn")
  for ext in h5 xmf; do
    if [[ -e $o.$ext && -e $n.$ext ]]; then
      if [[ $ext == xmf ]]; then
        cmp -s "$o.$ext" "$n.$ext" || why+=(".xmf differs")
      elif ! cmp -s "$o.$ext" "$n.$ext"; then
        local detail
        if ! detail=$(/usr/bin/python3 -c "$compare_h5" "$o.$ext" "$n.$ext" 2>&1); then
          why+=("${detail:-h5 comparison failed}")
        fi
      fi
    elif [[ -e $o.$ext || -e $n.$ext ]]; then
      why+=(".$ext written by one build only")
    fi
  done
  if [[ ${#why[@]} -eq 0 ]]; then
    printf '%-40s identical (exit %s)\n' "$name" "$so"
    return 0
  fi
  local joined
  joined=$(printf '%s; ' "${why[@]}")
  printf '%-40s DIFFERENT: %s\n' "$name" "${joined%; }"
  return 1
}

start=$SECONDS
failures=0 cases=0
check() {
  local scene=$1 integrator=$2 n=$3 every=$4
  local name
  name=$(basename "$scene" .toml)-$integrator
  run_one old "$old_exe" "$scene" "$integrator" "$n" "$every" "$name"
  run_one new "$new_exe" "$scene" "$integrator" "$n" "$every" "$name"
  cases=$((cases + 1))
  compare "$name" || failures=$((failures + 1))
}

echo "old: $old_exe"
echo "new: $new_exe"
echo "work: $work ($steps steps, a frame every $output_every; semi-implicit $semi_steps / $semi_output_every)"
for scene in "${scenes[@]}"; do
  scene=$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")
  for integrator in "${integrators[@]}"; do
    check "$scene" "$integrator" "$steps" "$output_every"
  done
  if [[ $(basename "$scene") == s1_* ]]; then
    check "$scene" semi-implicit "$semi_steps" "$semi_output_every"
  fi
done

echo "$cases cases, $failures DIFFERENT, $((SECONDS - start)) s"
[[ $failures -eq 0 ]]
