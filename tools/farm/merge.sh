#!/usr/bin/env bash
# merge.sh JOB_ENV [MERGE OPTIONS...] — merges a farm job's parts (what the Slurm merge job and the
# Kubernetes merge Job run): obscura merge OUTDIR/parts/part-KKKK.exr... -o OUTDIR/OUTPUT [options,
# e.g. --partial], with the job's part files that exist.
# When parts are missing, obscura exits non-zero and writes nothing; this prints the missing parts
# as part indices too, and how to render them.
set -euo pipefail
FARM_PROG=merge.sh
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=farm_lib.sh
source "$here/farm_lib.sh"

job_env=${1:?usage: merge.sh JOB_ENV [MERGE OPTIONS...]}
shift
farm_load_job_env "$job_env"
out=$OBSCURA_OUTDIR/$OBSCURA_OUTPUT
mapfile -t files < <(farm_part_files)
echo "merge.sh: $OBSCURA_BIN merge <${#files[@]} of $OBSCURA_PARTS parts in $OBSCURA_OUTDIR/parts> -o $out $*"
status=0
if ((${#files[@]})); then
  "$OBSCURA_BIN" merge "${files[@]}" -o "$out" "$@" || status=$?
else
  echo "merge.sh: no part file in $OBSCURA_OUTDIR/parts" >&2
  status=2
fi
if ((status != 0)); then
  missing=$(farm_missing_parts | farm_index_ranges)
  echo "merge.sh: obscura merge exited $status; parts missing: ${missing:-none by file}" >&2
  echo "merge.sh: render them with tools/farm/slurm/resubmit-missing.sh $OBSCURA_OUTDIR" \
       "(Slurm) or tools/farm/k8s/submit.sh --name JOB --rerun ${missing:-LIST} (Kubernetes)" >&2
  exit "$status"
fi
echo "merge.sh: wrote $out"
