#!/usr/bin/env bash
# resubmit-missing.sh OUTDIR [--dry-run] — completes a Slurm farm render that submit.sh started:
# finds the parts without a part file in OUTDIR/parts (and those `obscura merge --list-missing`
# names, where the binary runs on this host), submits exactly those array indices
# (sbatch --array=3,7 with the job's sbatch options from OUTDIR/slurm.env) and a new merge job
# after them. When no part is missing but the merged image is, submits the merge job alone.
# Refuses while parts of this job are still queued or running (they may yet write their files):
# wait for them, or scancel them first.
#
# Prints the job ids; the last line is "ARRAY_JOB_ID MERGE_JOB_ID" ("- MERGE_JOB_ID" for a merge
# alone, nothing when the image is there).
set -euo pipefail
FARM_PROG=resubmit-missing.sh
slurm_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=../farm_lib.sh
source "$slurm_dir/../farm_lib.sh"
# shellcheck source=slurm_lib.sh
source "$slurm_dir/slurm_lib.sh"

DRY_RUN=0 outdir=""
for a in "$@"; do
  case $a in
    --dry-run) DRY_RUN=1 ;;
    -h|--help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) farm_die "unknown option '$a'" ;;
    *) [ -z "$outdir" ] || farm_die "one OUTDIR only"; outdir=$a ;;
  esac
done
[ -n "$outdir" ] || farm_die "usage: resubmit-missing.sh OUTDIR [--dry-run]"
outdir=$(realpath -m -- "$outdir")
farm_load_job_env "$outdir/job.env"
[ "$OBSCURA_OUTDIR" = "$outdir" ] \
  || farm_die "$outdir/job.env names the job folder $OBSCURA_OUTDIR: run this where it has that path"
OBSCURA_SBATCH_OPTS=() OBSCURA_PART_SBATCH_OPTS=() OBSCURA_MERGE_SBATCH_OPTS=() OBSCURA_MAX_RUNNING=""
# shellcheck disable=SC1091
[ ! -f "$outdir/slurm.env" ] || source "$outdir/slurm.env"

# This job's Slurm jobs that are still in the queue.
if [ -f "$outdir/slurm-jobs.txt" ] && command -v squeue >/dev/null; then
  ids=$(awk '$2 == "parts" { printf "%s%s", sep, $1; sep = "," }' "$outdir/slurm-jobs.txt")
  if [ -n "$ids" ]; then
    queued=$(squeue -h -r -o '%F %i %T' | awk -v ids=",$ids," 'index(ids, "," $1 ",") { print $2 " " $3 }')
    [ -z "$queued" ] || farm_die "parts of this job are still queued or running; wait for them or scancel them:
$queued"
  fi
fi

missing=$(farm_missing_parts | farm_index_ranges)
if [ -n "$missing" ]; then
  echo "resubmit-missing.sh: parts missing: $missing"
  slurm_submit "$missing"
elif [ ! -e "$OBSCURA_OUTDIR/$OBSCURA_OUTPUT" ]; then
  echo "resubmit-missing.sh: all $OBSCURA_PARTS parts are there; submitting the merge alone"
  merge=$(slurm_submit_merge)
  ((DRY_RUN)) || echo "$merge merge after -" >>"$OBSCURA_OUTDIR/slurm-jobs.txt"
  echo "merge job $merge -> $OBSCURA_OUTDIR/$OBSCURA_OUTPUT"
  echo "- $merge"
else
  echo "resubmit-missing.sh: complete: all $OBSCURA_PARTS parts and $OBSCURA_OUTDIR/$OBSCURA_OUTPUT are there"
fi
