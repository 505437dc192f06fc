#!/usr/bin/env bash
# run_part.sh JOB_ENV [INDEX] — renders one part of a farm job (what a Slurm array task and a
# Kubernetes Indexed Job pod run). INDEX defaults to $SLURM_ARRAY_TASK_ID, else
# $JOB_COMPLETION_INDEX. With OBSCURA_PART_LIST="3,7" (or "3-5,7") in the environment, INDEX is a
# position in that list (a Kubernetes Job re-running some parts: completion index 1 renders part 7).
#
# Writes OBSCURA_OUTDIR/parts/part-KKKK.exr (obscura writes it atomically: a part file is whole or
# absent). A part whose file exists is left alone (so re-running a whole job is harmless) unless
# OBSCURA_FORCE=1. A failed render is tried again, OBSCURA_ATTEMPTS (default 2) tries in all.
set -euo pipefail
FARM_PROG=run_part.sh
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=farm_lib.sh
source "$here/farm_lib.sh"

job_env=${1:?usage: run_part.sh JOB_ENV [INDEX]}
farm_load_job_env "$job_env"
index=${2:-${SLURM_ARRAY_TASK_ID:-${JOB_COMPLETION_INDEX:-}}}
[ -n "$index" ] || farm_die "no part index: give INDEX, or run as a Slurm array task or an Indexed Job pod"
if [ -n "${OBSCURA_PART_LIST:-}" ]; then
  expanded=$(farm_expand_indices "$OBSCURA_PART_LIST") || farm_die "bad OBSCURA_PART_LIST '$OBSCURA_PART_LIST'"
  mapfile -t list <<<"$expanded"
  [[ $index =~ ^[0-9]+$ ]] && ((index < ${#list[@]})) \
    || farm_die "index $index is outside OBSCURA_PART_LIST ($OBSCURA_PART_LIST)"
  index=${list[index]}
fi

args_line=$(farm_part_args "$index")
read -r -a part_args <<<"$args_line"
name=$(farm_part_name "$index")
mkdir -p "$OBSCURA_OUTDIR/parts"
out=$OBSCURA_OUTDIR/parts/$name
if [ -e "$out" ] && [ "${OBSCURA_FORCE:-0}" != 1 ]; then
  echo "run_part.sh: part $index ($name) exists; not rendering it again (OBSCURA_FORCE=1 does)"
  exit 0
fi

# The temporary file of an earlier render of this part killed while writing (obscura writes
# .part-KKKK.tmp<pid>.exr, then renames it).
rm -f "$OBSCURA_OUTDIR/parts/.${name%.exr}.tmp"*.exr

attempts=${OBSCURA_ATTEMPTS:-2}
cmd=("$OBSCURA_BIN" render "$OBSCURA_SCENE" -o "$out" --spp "$OBSCURA_SPP"
     ${OBSCURA_RENDER_OPTS[@]+"${OBSCURA_RENDER_OPTS[@]}"} "${part_args[@]}")
for ((try = 1; ; try++)); do
  echo "run_part.sh: part $index of $OBSCURA_PARTS on $(hostname) (try $try of $attempts): ${cmd[*]}"
  status=0
  "${cmd[@]}" || status=$?
  if ((status == 0)); then
    [ -s "$out" ] || farm_die "obscura exited 0 but left no $out"
    exit 0
  fi
  echo "run_part.sh: part $index: obscura exited $status" >&2
  ((try < attempts)) || exit "$status"
  sleep 5
done
