#!/usr/bin/env bash
# submit.sh — a farm render on Slurm: one array job of PARTS tasks (part k = task k, numbered by
# tools/farm/part_args.sh) and a merge job that runs when all of them succeeded.
#
#   submit.sh --scene SCENE --spp N --parts P --outdir DIR [options] [-- RENDER OPTIONS...]
#
#   --scene PATH        the scene (.gltf), as the compute nodes see it
#   --spp N             samples per pixel of the whole frame
#   --parts P           number of parts = array tasks (Slurm's MaxArraySize, 1001 by default, bounds it)
#   --tiles T           horizontal strips (default P: strips only, which merge bit-exactly);
#                       P/T sample ranges of N/(P/T) samples each
#   --outdir DIR        new job folder on a file system the nodes share: job.env, parts/, logs/,
#                       the merged image. Refused when it holds a job already.
#   --bin PATH          obscura binary as the nodes see it (default $OBSCURA_BIN, else this
#                       checkout's build/obscura)
#   --output NAME       merged image in DIR, .exr or .png (default frame.exr)
#   --farm-dir DIR      tools/farm as the nodes see it (default this checkout's)
#   --sbatch-opt OPT    an sbatch option for both jobs, e.g. --sbatch-opt=--partition=render;
#                       repeatable; $OBSCURA_SBATCH_OPTS (words) come first
#   --part-sbatch-opt OPT / --merge-sbatch-opt OPT   for one kind of job, e.g. --gres=gpu:1
#   --max-running K     at most K parts at a time (--array=0-99%K)
#   --dry-run           print the job description and the sbatch commands; submit nothing
# RENDER OPTIONS go to every `obscura render`, e.g. -- --width 1920 --height 1080 --seed 7.
#
# Prints the job ids; the last line is "ARRAY_JOB_ID MERGE_JOB_ID". Missing or failed parts:
# resubmit-missing.sh DIR.
set -euo pipefail
FARM_PROG=submit.sh
slurm_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
OBSCURA_FARM_DIR=$(cd "$slurm_dir/.." && pwd)
# shellcheck source=../farm_lib.sh
source "$OBSCURA_FARM_DIR/farm_lib.sh"
# shellcheck source=slurm_lib.sh
source "$slurm_dir/slurm_lib.sh"

usage() { sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit "${1:-2}"; }
need() { [ $# -ge 2 ] && [ -n "$2" ] || farm_die "$1 needs a value"; }

OBSCURA_BIN=${OBSCURA_BIN:-$(cd "$OBSCURA_FARM_DIR/../.." && pwd)/build/obscura}
OBSCURA_SCENE="" OBSCURA_OUTDIR="" OBSCURA_PARTS="" OBSCURA_TILES="" OBSCURA_SPP=""
OBSCURA_OUTPUT=frame.exr OBSCURA_MAX_RUNNING=""
read -r -a OBSCURA_SBATCH_OPTS <<<"${OBSCURA_SBATCH_OPTS:-}"
OBSCURA_PART_SBATCH_OPTS=() OBSCURA_MERGE_SBATCH_OPTS=() OBSCURA_RENDER_OPTS=()
DRY_RUN=0
while [ $# -gt 0 ]; do
  opt=$1 val=""
  if [[ $opt == --*=* ]]; then val=${opt#*=} opt=${opt%%=*}; set -- "$opt" "$val" "${@:2}"; fi
  case $opt in
    --scene|--spp|--parts|--tiles|--outdir|--output|--bin|--farm-dir) need "$@"; farm_job_option "$1" "$2"; shift 2 ;;
    --sbatch-opt) need "$@"; OBSCURA_SBATCH_OPTS+=("$2"); shift 2 ;;
    --part-sbatch-opt) need "$@"; OBSCURA_PART_SBATCH_OPTS+=("$2"); shift 2 ;;
    --merge-sbatch-opt) need "$@"; OBSCURA_MERGE_SBATCH_OPTS+=("$2"); shift 2 ;;
    --max-running) need "$@"; OBSCURA_MAX_RUNNING=$2; shift 2 ;;
    --dry-run) DRY_RUN=1; shift ;;
    -h|--help) usage 0 ;;
    --) shift; OBSCURA_RENDER_OPTS=("$@"); break ;;
    *) farm_die "unknown option '$1' (render options go after --; --help)" ;;
  esac
done
farm_check_job_options
[[ -z $OBSCURA_MAX_RUNNING || $OBSCURA_MAX_RUNNING =~ ^[1-9][0-9]*$ ]] \
  || farm_die "--max-running must be a positive integer"
# Paths as absolute ones: the jobs do not start in this folder.
OBSCURA_OUTDIR=$(realpath -m -- "$OBSCURA_OUTDIR")
[[ $OBSCURA_SCENE == /* ]] || OBSCURA_SCENE=$(realpath -m -- "$OBSCURA_SCENE")
[[ $OBSCURA_BIN == /* ]] || OBSCURA_BIN=$(realpath -m -- "$OBSCURA_BIN")
[ -e "$OBSCURA_OUTDIR/job.env" ] \
  && farm_die "$OBSCURA_OUTDIR holds a job already (job.env); resubmit-missing.sh $OBSCURA_OUTDIR completes it, or choose a new --outdir"

if ((DRY_RUN)); then
  echo "--- $OBSCURA_OUTDIR/job.env (not written: --dry-run)"
  farm_print_job_env
else
  command -v sbatch >/dev/null || farm_die "sbatch not found (Slurm's client commands)"
  mkdir -p "$OBSCURA_OUTDIR/parts" "$OBSCURA_OUTDIR/logs"
  slurm_write_env "$OBSCURA_OUTDIR/slurm.env"
  farm_write_job_env "$OBSCURA_OUTDIR/job.env"
fi
slurm_submit "0-$((OBSCURA_PARTS - 1))"
