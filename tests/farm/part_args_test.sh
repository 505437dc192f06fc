#!/usr/bin/env bash
# part_args_test.sh [SOURCE_DIR] — the farm's one part numbering (tools/farm/part_args.sh) and that
# both cluster managers use it: every (strip, sample) of a frame is rendered by exactly one part,
# bad input exits 2, the Slurm submission is an array 0..P-1, the Kubernetes Indexed Job has P
# completions, and run_part.sh (which both run) renders the part its index names. No Slurm,
# Kubernetes or GPU needed: obscura is a stub that records its arguments.
set -euo pipefail
src=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
farm=$src/tools/farm
pa=$farm/part_args.sh
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
expect() {  # expect "OUTPUT" ARGS... — part_args.sh ARGS prints OUTPUT and exits 0
  local want=$1 got
  shift
  got=$("$pa" "$@" 2>&1) || { fail "part_args.sh $* exited $?: $got"; return; }
  [ "$got" = "$want" ] || fail "part_args.sh $*: '$got', expected '$want'"
}
expect_bad() {  # expect_bad ARGS... — exits 2 with a message
  local got status=0
  got=$("$pa" "$@" 2>&1) || status=$?
  [ "$status" -eq 2 ] && [ -n "$got" ] || fail "part_args.sh $*: exit $status ('$got'), expected 2 and a message"
}

# ---- Examples.
expect "--tile 0/4 --samples 0:8" 0 4 4 8
expect "--tile 3/4 --samples 0:8" 3 4 4 8
expect "--tile 0/2 --samples 0:4" 0 4 2 8
expect "--tile 1/2 --samples 0:4" 1 4 2 8
expect "--tile 0/2 --samples 4:8" 2 4 2 8
expect "--tile 1/2 --samples 4:8" 3 4 2 8
expect "--tile 0/1 --samples 0:3" 0 3 1 10
expect "--tile 0/1 --samples 3:6" 1 3 1 10
expect "--tile 0/1 --samples 6:10" 2 3 1 10
expect "--tile 0/1 --samples 0:1" 0 1 1 1
expect "part-0007.exr" --name 7 8 4 8
expect "part-9999.exr" --name 9999 10000 10000 1
expect "--tile 0/1 --samples 0:1048576" 0 1 1 1048576

# ---- Bad input.
expect_bad
expect_bad 0 4 4
expect_bad 0 4 4 8 9
expect_bad 4 4 4 8        # index = parts
expect_bad 0 6 4 8        # parts not a multiple of tiles
expect_bad 0 8 1 4        # 8 sample ranges of 4 samples: empty ones
expect_bad 0 0 1 8
expect_bad 0 4 0 8
expect_bad 0 4 4 0
expect_bad -1 4 4 8
expect_bad x 4 4 8
expect_bad 08 10 10 8     # leading zero
expect_bad 0 10001 1 20000
expect_bad 0 '4 ' 4 8
expect_bad --name 4 4 4 8

# ---- Every (strip, sample) in exactly one part; ranges balanced; names distinct.
for case in "1 1 1" "4 4 8" "4 2 8" "4 1 4" "6 3 7" "12 4 5" "9 3 64" "5 5 1" "16 2 100"; do
  read -r parts tiles spp <<<"$case"
  declare -A seen=() names=()
  min=$spp max=0
  for ((k = 0; k < parts; k++)); do
    line=$("$pa" "$k" "$parts" "$tiles" "$spp")
    [[ $line =~ ^--tile\ ([0-9]+)/([0-9]+)\ --samples\ ([0-9]+):([0-9]+)$ ]] \
      || { fail "part $k of $case: unexpected '$line'"; continue; }
    t=${BASH_REMATCH[1]} a=${BASH_REMATCH[3]} b=${BASH_REMATCH[4]}
    [ "${BASH_REMATCH[2]}" = "$tiles" ] || fail "part $k of $case: strip count in '$line'"
    [ "$t" -eq $((k % tiles)) ] || fail "part $k of $case: strip $t, expected k % TILES"
    ((a < b)) || fail "part $k of $case: empty range $a:$b"
    ((b - a < min)) && min=$((b - a))
    ((b - a > max)) && max=$((b - a))
    for ((s = a; s < b; s++)); do
      [ -z "${seen[$t:$s]:-}" ] || fail "$case: strip $t sample $s in parts ${seen[$t:$s]} and $k"
      seen[$t:$s]=$k
    done
    n=$("$pa" --name "$k" "$parts" "$tiles" "$spp")
    [ -z "${names[$n]:-}" ] || fail "$case: parts ${names[$n]} and $k are both $n"
    names[$n]=$k
  done
  [ "${#seen[@]}" -eq $((tiles * spp)) ] || fail "$case: ${#seen[@]} (strip, sample) pairs, expected $((tiles * spp))"
  ((max - min <= 1)) || fail "$case: range sizes from $min to $max"
  unset seen names
done

# ---- run_part.sh (what an array task / a pod runs) with a stub obscura.
stub=$work/obscura
cat >"$stub" <<'EOF'
#!/usr/bin/env bash
# A stub obscura: `render ... -o OUT ...` writes its arguments to OUT; `merge --list-missing`
# prints $STUB_MISSING.
if [ "$1" = render ]; then
  out=""; prev=""
  for a in "$@"; do [ "$prev" = -o ] && out=$a; prev=$a; done
  shift
  printf '%s\n' "$*" >"$out"
elif [ "$1 $2" = "merge --list-missing" ]; then
  printf '%s' "${STUB_MISSING:-}"
elif [ "$1" = merge ]; then
  shift
  printf '%s\n' "$*" >"$STUB_MERGE_LOG"
else
  exit 3
fi
EOF
chmod +x "$stub"
outdir=$work/job
dry=$("$farm/slurm/submit.sh" --dry-run --bin "$stub" --scene "$work/scene.gltf" --spp 8 --parts 4 \
      --tiles 2 --outdir "$outdir" -- --width 48 --height "4 8" 2>&1) || fail "slurm submit.sh --dry-run: $dry"
grep -q -- '--array=0-3 ' <<<"$dry" || fail "slurm submit.sh: no --array=0-3 in: $dry"
grep -q -- '--dependency=afterok:ARRAY_JOB_ID' <<<"$dry" || fail "slurm submit.sh: no merge dependency in: $dry"
[ ! -e "$outdir" ] || fail "slurm submit.sh --dry-run created $outdir"
# The job.env submit.sh would write (the dry run prints it), then each task by its array index.
mkdir -p "$outdir"
sed -n '/^# obscura farm job/,/^OBSCURA_RENDER_OPTS=/p' <<<"$dry" >"$outdir/job.env"
for k in 0 1 2 3; do
  SLURM_ARRAY_TASK_ID=$k "$farm/run_part.sh" "$outdir/job.env" >/dev/null \
    || fail "run_part.sh for array task $k failed"
  want="$work/scene.gltf -o $outdir/parts/part-000$k.exr --spp 8 --width 48 --height 4 8 $("$pa" "$k" 4 2 8)"
  [ "$(cat "$outdir/parts/part-000$k.exr" 2>/dev/null)" = "$want" ] \
    || fail "array task $k rendered '$(cat "$outdir/parts/part-000$k.exr" 2>/dev/null)', expected '$want'"
done
# An existing part is not rendered again.
echo keep >"$outdir/parts/part-0002.exr"
SLURM_ARRAY_TASK_ID=2 "$farm/run_part.sh" "$outdir/job.env" >/dev/null
[ "$(cat "$outdir/parts/part-0002.exr")" = keep ] || fail "run_part.sh rendered an existing part again"
# Kubernetes: completion index 1 of a rerun of parts "3,1" (sorted: 1,3) is part 3.
rm "$outdir/parts/part-0003.exr"
JOB_COMPLETION_INDEX=1 OBSCURA_PART_LIST=1,3 "$farm/run_part.sh" "$outdir/job.env" >/dev/null \
  || fail "run_part.sh with OBSCURA_PART_LIST failed"
[ -e "$outdir/parts/part-0003.exr" ] || fail "completion index 1 of list 1,3 did not render part 3"
if JOB_COMPLETION_INDEX=2 OBSCURA_PART_LIST=1,3 "$farm/run_part.sh" "$outdir/job.env" >/dev/null 2>&1; then
  fail "run_part.sh accepted index 2 of a 2-part list"
fi

# A re-render of a part deletes the temporary file a killed render of it left; merge.sh merges
# the job's part files, not the rest of the folder.
rm "$outdir/parts/part-0001.exr"
echo partial >"$outdir/parts/.part-0001.tmp4242.exr"
SLURM_ARRAY_TASK_ID=1 "$farm/run_part.sh" "$outdir/job.env" >/dev/null || fail "run_part.sh for task 1 failed"
[ ! -e "$outdir/parts/.part-0001.tmp4242.exr" ] || fail "run_part.sh left the temporary file of an earlier render"
echo partial >"$outdir/parts/.part-0003.tmp4242.exr"
STUB_MERGE_LOG=$work/merge.log "$farm/merge.sh" "$outdir/job.env" >/dev/null || fail "merge.sh failed"
p=$outdir/parts
[ "$(cat "$work/merge.log")" = "$p/part-0000.exr $p/part-0001.exr $p/part-0002.exr $p/part-0003.exr -o $outdir/frame.exr" ] \
  || fail "merge.sh ran obscura merge $(cat "$work/merge.log")"

# ---- resubmit-missing.sh --dry-run: files missing, and pieces obscura merge --list-missing names.
rm "$outdir/parts/part-0001.exr"
dry=$("$farm/slurm/resubmit-missing.sh" "$outdir" --dry-run 2>&1) || fail "resubmit-missing.sh --dry-run: $dry"
grep -q -- '--array=1 ' <<<"$dry" || fail "resubmit-missing.sh: expected --array=1 in: $dry"
grep -q "^sbatch.* '' " <<<"$dry" && fail "resubmit-missing.sh passes empty arguments to sbatch: $dry"
dry=$(STUB_MISSING=$'--tile 0/2 --samples 0:8\n' "$farm/slurm/resubmit-missing.sh" "$outdir" --dry-run 2>&1) \
  || fail "resubmit-missing.sh --dry-run: $dry"
grep -q -- '--array=0-2 ' <<<"$dry" || fail "resubmit-missing.sh: expected --array=0-2 (strip 0 of both ranges, and part 1) in: $dry"
for k in 0 1 2 3; do echo x >"$outdir/parts/part-000$k.exr"; done
dry=$("$farm/slurm/resubmit-missing.sh" "$outdir" --dry-run 2>&1) || fail "resubmit-missing.sh --dry-run: $dry"
grep -q 'submitting the merge alone' <<<"$dry" || fail "resubmit-missing.sh with all parts: $dry"
grep -q -- '--array' <<<"$dry" && fail "resubmit-missing.sh with all parts submitted parts: $dry"

# ---- Kubernetes manifests: an Indexed Job of P completions running run_part.sh.
k8s=$("$farm/k8s/submit.sh" --dry-run --name t1 --image img --pvc claim --scene /farm/s.gltf --spp 8 \
      --parts 4 --tiles 2 --outdir /farm/out/t1 --manifests "$work/k8s" 2>&1) || fail "k8s/submit.sh --dry-run: $k8s"
grep -q '^  completionMode: Indexed$' <<<"$k8s" || fail "k8s: no completionMode: Indexed"
grep -q '^  completions: 4$' <<<"$k8s" || fail "k8s: completions is not 4"
grep -q 'run_part.sh", "/etc/obscura-farm/job.env"' <<<"$k8s" || fail "k8s: the pods do not run run_part.sh"
! grep -q '@[A-Z_]*@' <<<"$k8s" || fail "k8s: placeholders left: $(grep -o '@[A-Z_]*@' <<<"$k8s" | sort -u | tr '\n' ' ')"
if python3 -c 'import yaml' 2>/dev/null; then
  python3 - "$work/k8s" <<'EOF' || fail "k8s manifests do not parse as the Jobs expected"
import sys, yaml, os
d = sys.argv[1]
docs = {f: yaml.safe_load(open(os.path.join(d, f))) for f in ("configmap.yaml", "parts-job.yaml", "merge-job.yaml")}
cm, parts, merge = docs["configmap.yaml"], docs["parts-job.yaml"], docs["merge-job.yaml"]
assert cm["kind"] == "ConfigMap" and "OBSCURA_PARTS=4" in cm["data"]["job.env"]
assert parts["kind"] == "Job" and parts["spec"]["completionMode"] == "Indexed" and parts["spec"]["completions"] == 4
pod = parts["spec"]["template"]["spec"]
assert pod["restartPolicy"] == "Never" and pod["volumes"][0]["configMap"]["name"] == cm["metadata"]["name"]
assert merge["kind"] == "Job" and merge["spec"]["template"]["spec"]["containers"][0]["command"][0].endswith("/merge.sh")
EOF
fi
rerun=$("$farm/k8s/submit.sh" --dry-run --name t1 --manifests "$work/k8s" --rerun 3,1 2>&1) || fail "k8s --rerun: $rerun"
grep -q '^  completions: 2$' <<<"$rerun" || fail "k8s --rerun 3,1: completions is not 2"
grep -q 'value: "1,3"' <<<"$rerun" || fail "k8s --rerun 3,1: OBSCURA_PART_LIST is not 1,3"
grep -q 'name: t1-parts-r1$' <<<"$rerun" || fail "k8s --rerun: the Job is not t1-parts-r1"

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "farm part numbering: all checks passed"
