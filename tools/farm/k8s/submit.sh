#!/usr/bin/env bash
# submit.sh — a farm render on Kubernetes: a ConfigMap with the job description (job.env), an
# Indexed Job of PARTS pods (completion index k renders part k, numbered by
# tools/farm/part_args.sh like the Slurm array tasks) and, once that Job is complete, a merge Job.
# Fills in parts-job.yaml and merge-job.yaml beside this script.
#
#   submit.sh --name JOB --image IMAGE --pvc CLAIM --scene SCENE --spp N --parts P --outdir DIR
#             [options] [-- RENDER OPTIONS...]
#   submit.sh --name JOB --rerun LIST|failed [--wait] [--dry-run]
#
#   --name JOB          job name: lowercase letters, digits, '-' (at most 40)
#   --image IMAGE       container image with obscura and tools/farm (see tools/farm/README.md)
#   --pvc CLAIM         a ReadWriteMany PersistentVolumeClaim holding the scenes and the output
#   --mount PATH        where the claim is mounted in the pods (default /farm)
#   --scene PATH        the scene, as the pods see it (e.g. /farm/scenes/sponza/sponza.gltf)
#   --spp N / --parts P / --tiles T   as tools/farm/slurm/submit.sh (--tiles defaults to P)
#   --outdir DIR        the job folder, as the pods see it (e.g. /farm/out/JOB); new
#   --output NAME       merged image in DIR (default frame.exr)
#   --bin PATH          obscura in the image (default /opt/obscura/bin/obscura)
#   --farm-dir PATH     tools/farm in the image (default /opt/obscura/tools/farm)
#   --parallelism K     pods at a time (default min(P, 16))
#   --retries R         retries of a failed pod, per index (backoffLimitPerIndex, default 2)
#   --cpu C             CPU request of a render pod (default 2)
#   --gpu               ask for one nvidia.com/gpu per render pod
#   --manifests DIR     where the filled-in manifests and job.env are kept on this host
#                       (default ./obscura-farm-JOB); --rerun reads them from there
#   --rerun LIST        a new Indexed Job of just the parts LIST ("3,7" or "3-5,7"), e.g. those the
#                       merge Job's log names as missing; "failed": the parts Job's
#                       .status.failedIndexes. Then a new merge Job.
#   --wait              wait for the parts Job, then apply the merge Job and wait for it
#                       (without it: apply the parts Job and print the merge step)
#   --dry-run           write the manifests and print them; apply nothing (no kubectl needed)
set -euo pipefail
FARM_PROG=k8s/submit.sh
k8s_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=../farm_lib.sh
source "$k8s_dir/../farm_lib.sh"

usage() { sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit "${1:-2}"; }
need() { [ $# -ge 2 ] && [ -n "$2" ] || farm_die "$1 needs a value"; }

job="" image="" pvc="" mount=/farm manifests="" parallelism="" retries=2 cpu=2 gpu=0
rerun="" wait=0 dry_run=0
OBSCURA_BIN=/opt/obscura/bin/obscura OBSCURA_FARM_DIR=/opt/obscura/tools/farm
OBSCURA_SCENE="" OBSCURA_OUTDIR="" OBSCURA_PARTS="" OBSCURA_TILES="" OBSCURA_SPP=""
OBSCURA_OUTPUT=frame.exr OBSCURA_RENDER_OPTS=()
while [ $# -gt 0 ]; do
  if [[ $1 == --*=* ]]; then set -- "${1%%=*}" "${1#*=}" "${@:2}"; fi
  case $1 in
    --name) need "$@"; job=$2; shift 2 ;;
    --image) need "$@"; image=$2; shift 2 ;;
    --pvc) need "$@"; pvc=$2; shift 2 ;;
    --mount) need "$@"; mount=$2; shift 2 ;;
    --scene|--spp|--parts|--tiles|--outdir|--output|--bin|--farm-dir) need "$@"; farm_job_option "$1" "$2"; shift 2 ;;
    --parallelism) need "$@"; parallelism=$2; shift 2 ;;
    --retries) need "$@"; retries=$2; shift 2 ;;
    --cpu) need "$@"; cpu=$2; shift 2 ;;
    --gpu) gpu=1; shift ;;
    --manifests) need "$@"; manifests=$2; shift 2 ;;
    --rerun) need "$@"; rerun=$2; shift 2 ;;
    --wait) wait=1; shift ;;
    --dry-run) dry_run=1; shift ;;
    -h|--help) usage 0 ;;
    --) shift; OBSCURA_RENDER_OPTS=("$@"); break ;;
    *) farm_die "unknown option '$1' (render options go after --; --help)" ;;
  esac
done
[[ $job =~ ^[a-z0-9]([-a-z0-9]{0,38}[a-z0-9])?$ ]] \
  || farm_die "--name: lowercase letters, digits and '-', at most 40, got '$job'"
manifests=${manifests:-./obscura-farm-$job}
((dry_run)) || command -v kubectl >/dev/null || farm_die "kubectl not found (--dry-run writes the manifests only)"

# The values go into YAML double-quoted strings or plain scalars: keep them simple.
yaml_safe() {
  case $2 in *[\"\\\$\'\`\|\&]*) farm_die "$1 must not hold quotes, backslashes, \$, |, & or \`: '$2'" ;; esac
  [[ $2 != *[[:cntrl:]]* ]] || farm_die "$1 must not hold control characters"
}

if [ -z "$rerun" ]; then
  for v in image pvc; do [ -n "${!v}" ] || farm_die "--$v is required (--help)"; done
  farm_check_job_options
  for v in OBSCURA_SCENE OBSCURA_OUTDIR OBSCURA_BIN OBSCURA_FARM_DIR mount; do
    [[ ${!v} == /* ]] || farm_die "${v} must be an absolute path in the pods, got '${!v}'"
  done
  for v in image pvc mount OBSCURA_FARM_DIR; do yaml_safe "$v" "${!v}"; done
  [[ $cpu =~ ^[0-9]+(\.[0-9]+|m)?$ ]] || farm_die "--cpu: a Kubernetes CPU quantity (2, 500m), got '$cpu'"
  [[ $retries =~ ^[0-9]+$ ]] || farm_die "--retries must be a non-negative integer"
  [ -e "$manifests/job.env" ] && farm_die "$manifests holds job $job already: use --rerun, or another --manifests"
  mkdir -p "$manifests"
  farm_write_job_env "$manifests/job.env"
  printf 'image=%q\npvc=%q\nmount=%q\ncpu=%q\ngpu=%q\nretries=%q\n' \
    "$image" "$pvc" "$mount" "$cpu" "$gpu" "$retries" >"$manifests/k8s.env"
  list="" completions=$OBSCURA_PARTS suffix=""
else
  [ -f "$manifests/job.env" ] && [ -f "$manifests/k8s.env" ] \
    || farm_die "no $manifests/job.env: --rerun needs the --manifests folder of the first submit"
  farm_load_job_env "$manifests/job.env"
  # shellcheck disable=SC1091
  source "$manifests/k8s.env"
  if [ "$rerun" = failed ]; then
    ((!dry_run)) || farm_die "--rerun failed asks the cluster; give the list with --dry-run"
    rerun=$(kubectl get job "$job-parts" -o jsonpath='{.status.failedIndexes}')
    [ -n "$rerun" ] || farm_die "job $job-parts lists no failed indexes (.status.failedIndexes)"
  fi
  indices=$(farm_expand_indices "$rerun") || farm_die "--rerun: a list like 3,7 or 3-5,7, got '$rerun'"
  indices=$(sort -n -u <<<"$indices")
  while read -r k; do
    ((k < OBSCURA_PARTS)) || farm_die "--rerun: part $k is not a part of this $OBSCURA_PARTS-part job"
  done <<<"$indices"
  list=$(farm_index_ranges <<<"$indices")
  completions=$(wc -l <<<"$indices")
  n=1
  while [ -e "$manifests/parts-job-r$n.yaml" ]; do n=$((n + 1)); done
  suffix=-r$n
fi
parallelism=${parallelism:-$((completions < 16 ? completions : 16))}
[[ $parallelism =~ ^[1-9][0-9]*$ ]] || farm_die "--parallelism must be a positive integer"
limits="{}"
((gpu)) && limits='{"nvidia.com/gpu": 1}'

fill() {
  sed -e "s|@JOB@|$job|g; s|@SUFFIX@|$suffix|g; s|@COMPLETIONS@|$completions|g" \
      -e "s|@PARALLELISM@|$parallelism|g; s|@RETRIES@|$retries|g; s|@IMAGE@|$image|g" \
      -e "s|@FARM_DIR@|$OBSCURA_FARM_DIR|g; s|@PART_LIST@|$list|g; s|@CPU@|$cpu|g" \
      -e "s|@LIMITS@|$limits|g; s|@MOUNT@|$mount|g; s|@PVC@|$pvc|g" "$1"
}
configmap=$manifests/configmap.yaml
parts_yaml=$manifests/parts-job$suffix.yaml
merge_yaml=$manifests/merge-job$suffix.yaml
{
  printf 'apiVersion: v1\nkind: ConfigMap\nmetadata:\n  name: %s-job\n  labels:\n' "$job"
  printf '    app.kubernetes.io/name: obscura-farm\n    obscura-farm/job: %s\ndata:\n  job.env: |\n' "$job"
  sed 's/^/    /' "$manifests/job.env"
} >"$configmap"
fill "$k8s_dir/parts-job.yaml" >"$parts_yaml"
fill "$k8s_dir/merge-job.yaml" >"$merge_yaml"

if ((dry_run)); then
  for f in "$configmap" "$parts_yaml" "$merge_yaml"; do
    echo "--- # $f"
    cat "$f"
  done
  exit 0
fi

# job_state NAME — Complete, Failed or "" (running).
job_state() {
  kubectl get job "$1" -o jsonpath='{range .status.conditions[?(@.status=="True")]}{.type}{" "}{end}' \
    | tr ' ' '\n' | grep -xE 'Complete|Failed' | head -n 1 || true
}
wait_job() {
  local state=""
  while [ -z "$state" ]; do sleep 10; state=$(job_state "$1"); done
  echo "$state"
}
kubectl apply -f "$configmap" -f "$parts_yaml"
echo "k8s/submit.sh: job $job-parts$suffix: $completions parts -> $OBSCURA_OUTDIR/parts/"
if ((!wait)); then
  echo "k8s/submit.sh: when it is complete (kubectl wait --for=condition=complete job/$job-parts$suffix):"
  echo "  kubectl apply -f $merge_yaml"
  exit 0
fi
state=$(wait_job "$job-parts$suffix")
if [ "$state" != Complete ]; then
  failed=$(kubectl get job "$job-parts$suffix" -o jsonpath='{.status.failedIndexes}')
  # Under --rerun, failedIndexes are positions in the list, not part indices.
  echo "k8s/submit.sh: job $job-parts$suffix failed (failed indexes: ${failed:-?}$([ -z "$suffix" ] || echo " of list $list"))." >&2
  [ -n "$suffix" ] || echo "k8s/submit.sh: run again: $0 --name $job --manifests $manifests --rerun failed --wait" >&2
  exit 1
fi
kubectl apply -f "$merge_yaml"
state=$(wait_job "$job-merge$suffix")
kubectl logs "job/$job-merge$suffix" || true
[ "$state" = Complete ] || { echo "k8s/submit.sh: merge failed; its log above names the missing parts (--rerun LIST)" >&2; exit 1; }
echo "k8s/submit.sh: done: $OBSCURA_OUTDIR/$OBSCURA_OUTPUT on claim $pvc"
