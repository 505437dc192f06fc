# slurm_lib.sh — sourced by submit.sh and resubmit-missing.sh (after ../farm_lib.sh).
# OUTDIR/slurm.env keeps the sbatch options of a job, so that a resubmission asks for the same
# resources; OUTDIR/slurm-jobs.txt lists the Slurm jobs submitted for it, one a line:
#   <array job id> parts <indices>
#   <job id> merge after <array job id or "-">

SLURM_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
: "${DRY_RUN:=0}"

# slurm_write_env FILE — OBSCURA_SBATCH_OPTS / _PART_ / _MERGE_ (arrays) and OBSCURA_MAX_RUNNING.
slurm_write_env() {
  local file=$1 v o
  {
    echo "# sbatch options of this obscura farm job (bash syntax)"
    for v in OBSCURA_SBATCH_OPTS OBSCURA_PART_SBATCH_OPTS OBSCURA_MERGE_SBATCH_OPTS; do
      local -n arr=$v
      printf '%s=(' "$v"
      for o in ${arr[@]+"${arr[@]}"}; do printf ' %q' "$o"; done
      printf ' )\n'
      unset -n arr
    done
    printf 'OBSCURA_MAX_RUNNING=%q\n' "${OBSCURA_MAX_RUNNING:-}"
  } >"$file.tmp.$$"
  mv -f "$file.tmp.$$" "$file"
}

# slurm_sbatch NAME ARGS... — sbatch --parsable ARGS; prints the job id. DRY_RUN=1: prints the
# command on stderr and NAME in place of the id.
slurm_sbatch() {
  local name=$1
  shift
  if ((DRY_RUN)); then
    printf '%q ' sbatch --parsable "$@" >&2
    echo >&2
    echo "$name"
    return
  fi
  local out
  out=$(sbatch --parsable "$@") || farm_die "sbatch failed: sbatch $*"
  echo "${out%%;*}"
}

# slurm_submit_parts INDICES — an array job of the loaded job's parts INDICES ("0-15", "3,7");
# prints its id. Each task is requeued by Slurm when its node fails or it is preempted (--requeue);
# a render that fails is tried again by run_part.sh (OBSCURA_ATTEMPTS).
slurm_submit_parts() {
  local indices=$1
  ((DRY_RUN)) || mkdir -p "$OBSCURA_OUTDIR/logs"
  slurm_sbatch ARRAY_JOB_ID --array="$indices${OBSCURA_MAX_RUNNING:+%$OBSCURA_MAX_RUNNING}" --requeue \
    --job-name=obscura-part --output="$OBSCURA_OUTDIR/logs/part-%a.%A.out" \
    ${OBSCURA_SBATCH_OPTS[@]+"${OBSCURA_SBATCH_OPTS[@]}"} \
    ${OBSCURA_PART_SBATCH_OPTS[@]+"${OBSCURA_PART_SBATCH_OPTS[@]}"} \
    "$SLURM_DIR/obscura-part.sbatch" "$OBSCURA_OUTDIR/job.env"
}

# slurm_submit_merge [ARRAY_JOB_ID] — the merge job, after the array job succeeds (when given);
# cancelled by Slurm when a part fails for good (--kill-on-invalid-dep=yes). Prints its id.
slurm_submit_merge() {
  local dep=()
  [ -z "${1:-}" ] || dep=(--dependency="afterok:$1" --kill-on-invalid-dep=yes)
  slurm_sbatch MERGE_JOB_ID ${dep[@]+"${dep[@]}"} --job-name=obscura-merge \
    --output="$OBSCURA_OUTDIR/logs/merge.%j.out" \
    ${OBSCURA_SBATCH_OPTS[@]+"${OBSCURA_SBATCH_OPTS[@]}"} \
    ${OBSCURA_MERGE_SBATCH_OPTS[@]+"${OBSCURA_MERGE_SBATCH_OPTS[@]}"} \
    "$SLURM_DIR/obscura-merge.sbatch" "$OBSCURA_OUTDIR/job.env"
}

# slurm_submit INDICES — the parts INDICES and a merge after them; records both, prints both.
slurm_submit() {
  local indices=$1 array merge
  array=$(slurm_submit_parts "$indices")
  merge=$(slurm_submit_merge "$array")
  if ((!DRY_RUN)); then
    {
      echo "$array parts $indices"
      echo "$merge merge after $array"
    } >>"$OBSCURA_OUTDIR/slurm-jobs.txt"
  fi
  echo "array job $array: parts $indices -> $OBSCURA_OUTDIR/parts/"
  echo "merge job $merge: after $array -> $OBSCURA_OUTDIR/$OBSCURA_OUTPUT"
  # Last line, for scripts: the two job ids.
  echo "$array $merge"
}
