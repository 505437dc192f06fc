#!/usr/bin/env bash
# slurm_test.sh OBSCURA SOURCE_DIR — a farm render on a real one-node Slurm cluster, brought up
# here from Debian's packages (slurm-wlm, munge; tools/setup.sh --tests installs them) as root,
# without systemd, everything in one temporary folder, daemons on 127.0.0.1 only:
#   a) tools/farm/slurm/submit.sh: 4 parts (4 strips) of the Cornell box and the merge job after
#      them; the merged image equals a single-process render of the same frame (rmse 0);
#   b) 4 parts (2 strips x 2 sample ranges); part 2 (held by a wrapper) is cancelled with scancel
#      while it runs (resubmit-missing.sh refuses until then); the merge job is cancelled with it;
#      obscura merge refuses the parts, naming the missing piece, and so does tools/farm/merge.sh
#      (part 2); resubmit-missing.sh submits just task 2 and a merge; the image matches
#      (rmse < 1e-6).
# Stops the daemons it started, by their process ids, and deletes its folder, also on failure.
# Exit 77 (skipped) when Slurm or munge is not installed, or not root.
set -euo pipefail

obscura=${1:?usage: slurm_test.sh OBSCURA SOURCE_DIR}
src=${2:?usage: slurm_test.sh OBSCURA SOURCE_DIR}
farm=$src/tools/farm
scene=$src/scenes/cornell-box/cornell-box.gltf
render_opts=(--width 48 --height 40 --seed 3)
spp=8
test_deadline=150   # seconds for the whole test, bring-up included; each wait is bounded by it

skip() { echo "SKIP: $*"; exit 77; }
for c in slurmctld slurmd munged sbatch squeue sinfo scontrol scancel python3; do
  command -v "$c" >/dev/null || skip "$c not found (Debian: apt-get install slurm-wlm munge, or tools/setup.sh --tests)"
done
[ "$(id -u)" -eq 0 ] || skip "needs root (slurmd starts jobs as their user; SlurmUser=root here)"
[ -x "$obscura" ] || { echo "FAIL: no obscura binary at $obscura"; exit 1; }

# Nothing of an enclosing Slurm job or of the user's Slurm settings (SBATCH_PARTITION ...) applies.
while read -r v; do unset "$v"; done < <(compgen -e | grep -E '^(SLURM|SBATCH|SQUEUE|SINFO|SCONTROL|SCANCEL|SALLOC|SRUN)_' || true)
T=$(mktemp -d /tmp/obscura-slurm-test.XXXXXX)
# munged wants every folder above its socket searchable by all, and none writable by others.
chmod 0711 "$T"
tag=obscura-slurm-test:$T   # in the environment of every process this test starts (see cleanup)
daemon_pids=()              # munged slurmctld slurmd, in start order
failed=0
export SLURM_CONF=$T/slurm.conf

log() { printf '[%3ds] %s\n' "$SECONDS" "$*"; }

diagnostics() {
  echo "---- diagnostics (test folder $T)"
  for f in "$T"/log/*.log "$T"/job-*/logs/*.out; do
    [ -f "$f" ] || continue
    echo "---- $f (last 25 lines)"
    tail -n 25 "$f"
  done
  timeout 5 squeue -a 2>/dev/null || true
}

fail() {
  echo "FAIL: $*"
  failed=1
  diagnostics
  exit 1
}

# Processes with this test's tag in their environment: the daemons, the slurmstepd they fork,
# the jobs (sbatch passes the environment on) and anything those started.
tagged_pids() {
  grep -lzxF "OBSCURA_SLURM_TEST_TAG=$tag" /proc/[0-9]*/environ 2>/dev/null | cut -d/ -f3 | grep -vx "$$" || true
}
# Tagged processes other than the daemons and their children (slurmctld's slurmscriptd): the
# slurmstepd (which detach from slurmd) and the jobs.
job_pids() {
  local p daemons=" ${daemon_pids[*]} "
  for p in $(tagged_pids); do
    [[ $daemons == *" $p "* ]] && continue
    [[ $daemons == *" $(awk '/^PPid:/ { print $2 }' "/proc/$p/status" 2>/dev/null) "* ]] && continue
    echo "$p"
  done
}

# stop_pid PID — SIGTERM, up to 10 s, then SIGKILL; reaps it when it is our child.
stop_pid() {
  local pid=$1 i
  kill -0 "$pid" 2>/dev/null || { wait "$pid" 2>/dev/null || true; return 0; }
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < 100; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    # A child that exited is a zombie until waited for: kill -0 still finds it.
    [ "$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null)" != Z ] || break
    sleep 0.1
  done
  kill -0 "$pid" 2>/dev/null && [ "$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null)" != Z ] \
    && kill -KILL "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null || true
}

cleanup() {
  local status=$? i pids leftovers="" p
  trap - EXIT INT TERM
  # Jobs first (their slurmstepd end with them), while slurmctld is up to cancel them.
  if [ -n "${daemon_pids[1]:-}" ] && kill -0 "${daemon_pids[1]}" 2>/dev/null; then
    timeout 10 scancel --quiet --user=root 2>/dev/null || true
    for ((i = 0; i < 75; i++)); do
      [ -z "$(timeout 5 squeue -h -o %i 2>/dev/null)" ] && [ -z "$(job_pids)" ] && break
      sleep 0.2
    done
  fi
  # The daemons, by the ids we started them with: slurmd, slurmctld, munged.
  for i in $(printf '%s\n' "${!daemon_pids[@]}" | sort -rn); do stop_pid "${daemon_pids[i]}"; done
  # Anything else of ours still running is a leftover: report it, then end it by its id.
  for ((i = 0; i < 30; i++)); do
    pids=$(tagged_pids)
    [ -n "$pids" ] || break
    sleep 0.1
  done
  if [ -n "$pids" ]; then
    for p in $pids; do leftovers+="$p $(tr '\0' ' ' <"/proc/$p/cmdline" 2>/dev/null); "; done
    echo "FAIL: processes left after the daemons stopped: $leftovers"
    for p in $pids; do kill -KILL "$p" 2>/dev/null || true; done
    ((status)) || status=1
  fi
  if ((status && !failed)); then diagnostics; fi
  rm -rf "$T"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# wait_until SECONDS WHAT COMMAND... — polls COMMAND every 0.25 s; fails after SECONDS or at the
# test's deadline.
wait_until() {
  local limit=$1 what=$2 start=$SECONDS
  shift 2
  until "$@"; do
    if ((SECONDS - start >= limit || SECONDS >= test_deadline)); then
      fail "timed out after $((SECONDS - start)) s waiting for $what"
    fi
    sleep 0.25
  done
}

# ---- Bring-up -----------------------------------------------------------------------------------
mkdir -p "$T/munge" "$T/state" "$T/spool/localhost" "$T/log" "$T/run" "$T/bin"
chmod 0700 "$T/munge"
if command -v mungekey >/dev/null; then
  mungekey --create --keyfile="$T/munge/munge.key" --bits=1024
else
  dd if=/dev/urandom of="$T/munge/munge.key" bs=128 count=1 status=none
fi
chmod 0400 "$T/munge/munge.key"
chmod 0711 "$T/munge"   # the socket's folder: searchable by all (munged checks)

env OBSCURA_SLURM_TEST_TAG="$tag" munged --foreground --key-file="$T/munge/munge.key" \
  --socket="$T/munge/munge.sock" --pid-file="$T/run/munged.pid" --seed-file="$T/munge/munged.seed" \
  --log-file="$T/log/munged.log" --num-threads=2 2>>"$T/log/munged.log" &
daemon_pids+=($!)
wait_until 10 "munged's socket" test -S "$T/munge/munge.sock"

# The node as slurmd sees it (CPUs, memory).
node_hw=$(slurmd -C | head -n 1)
cpus=$(grep -o 'CPUs=[0-9]*' <<<"$node_hw" | cut -d= -f2)
mem=$(grep -o 'RealMemory=[0-9]*' <<<"$node_hw" | cut -d= -f2)
[ -n "$cpus" ] && [ -n "$mem" ] || fail "slurmd -C: '$node_hw'"

# free_ports — two free TCP ports on 127.0.0.1 below the ephemeral range (so outgoing connections
# do not take them between this check and the daemons binding them).
free_ports() {
  python3 - <<'EOF'
import random, socket
ports = []
while len(ports) < 2:
    p = random.randrange(20000, 32000)
    s = socket.socket()
    try:
        s.bind(("127.0.0.1", p))
    except OSError:
        continue
    finally:
        s.close()
    if p not in ports:
        ports.append(p)
print(*ports)
EOF
}

write_conf() {
  cat >"$SLURM_CONF" <<EOF
# One-node Slurm of tests/farm/slurm_test.sh: localhost only, no accounting, state in $T.
ClusterName=obscuratest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$1
SlurmdPort=$2
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/munge.sock
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool/%n
SlurmctldPidFile=$T/run/slurmctld.pid
SlurmdPidFile=$T/run/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SwitchType=switch/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MailProg=/bin/true
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=1,sched_min_interval=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=600
KillWait=2
InactiveLimit=0
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=localhost NodeHostname=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
}

ctld_up() { timeout 5 scontrol ping 2>/dev/null | grep -q 'is UP'; }
node_idle() { [ "$(timeout 5 sinfo -h -n localhost -o %T 2>/dev/null)" = idle ]; }
# start_daemons — slurmctld and slurmd in the foreground (-D), in the background; false when one
# exits (a port taken meanwhile: the caller tries other ports).
start_daemons() {
  local i
  env OBSCURA_SLURM_TEST_TAG="$tag" slurmctld -D -i -f "$SLURM_CONF" >>"$T/log/slurmctld.out" 2>&1 &
  daemon_pids[1]=$!
  for ((i = 0; i < 80; i++)); do
    ctld_up && break
    kill -0 "${daemon_pids[1]}" 2>/dev/null || { wait "${daemon_pids[1]}" 2>/dev/null || true; unset 'daemon_pids[1]'; return 1; }
    sleep 0.25
  done
  ctld_up || fail "slurmctld did not answer within 20 s"
  env OBSCURA_SLURM_TEST_TAG="$tag" slurmd -D -N localhost -f "$SLURM_CONF" >>"$T/log/slurmd.out" 2>&1 &
  daemon_pids[2]=$!
  for ((i = 0; i < 80; i++)); do
    node_idle && return 0
    kill -0 "${daemon_pids[2]}" 2>/dev/null || { wait "${daemon_pids[2]}" 2>/dev/null || true; unset 'daemon_pids[2]'; stop_pid "${daemon_pids[1]}"; unset 'daemon_pids[1]'; return 1; }
    sleep 0.25
  done
  fail "node localhost not idle within 20 s (sinfo: $(timeout 5 sinfo -h -o '%T %E' 2>&1))"
}
up=0
for attempt in 1 2 3; do
  write_conf $(free_ports)
  if start_daemons; then up=1; break; fi
  log "slurmctld or slurmd exited at start (attempt $attempt; a port taken?), trying other ports"
done
((up)) || fail "could not start slurmctld and slurmd"
log "one-node Slurm up: slurmctld $(grep -o 'SlurmctldPort=[0-9]*' "$SLURM_CONF"), slurmd $(grep -o 'SlurmdPort=[0-9]*' "$SLURM_CONF"), munged pid ${daemon_pids[0]}"

# ---- Helpers for the farm jobs -----------------------------------------------------------------
# states ID — the states of job ID (of each task of an array job), one a line.
states() { timeout 5 scontrol -o show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2; }
all_in() {  # all_in ID STATE... — every task of ID is in one of STATEs
  local s out
  out=$(states "$1")
  [ -n "$out" ] || return 1
  while read -r s; do
    [[ " ${*:2} " == *" $s "* ]] || return 1
  done <<<"$out"
}
finished() { all_in "$1" COMPLETED FAILED CANCELLED TIMEOUT NODE_FAIL OUT_OF_MEMORY PREEMPTED BOOT_FAIL DEADLINE; }
rmse_of() { "$obscura" compare "$1" "$2" | awk '$1 == "rmse" { print $2 }'; }
# submit OUTDIR ARGS... — tools/farm/slurm/submit.sh; sets array_job and merge_job.
submit() {
  local outdir=$1 out
  shift
  out=$(cd "$T" && env OBSCURA_SLURM_TEST_TAG="$tag" "$farm/slurm/submit.sh" --outdir "$outdir" "$@") \
    || fail "submit.sh failed: $out"
  read -r array_job merge_job <<<"$(tail -n 1 <<<"$out")"
  [[ $array_job =~ ^[0-9]+$ && $merge_job =~ ^[0-9]+$ ]] || fail "submit.sh printed: $out"
}

# The reference: the whole frame in one process.
(cd "$T" && "$obscura" render "$scene" -o "$T/whole.exr" --spp "$spp" "${render_opts[@]}" --samples "0:$spp" \
   >"$T/log/whole.log" 2>&1) || { cat "$T/log/whole.log"; fail "single-process render failed"; }
"$obscura" merge "$T/whole.exr" -o "$T/single.exr" >>"$T/log/whole.log" 2>&1 \
  || { cat "$T/log/whole.log"; fail "obscura merge of the single-process render failed"; }
log "single-process reference rendered"

# ---- a) 4 strips, merged by the dependent merge job -------------------------------------------
A=$T/job-a
submit "$A" --bin "$obscura" --scene "$scene" --spp "$spp" --parts 4 --tiles 4 -- "${render_opts[@]}"
log "a) array job $array_job (4 strips), merge job $merge_job"
wait_until 90 "merge job $merge_job" finished "$merge_job"
all_in "$array_job" COMPLETED || fail "a) array job $array_job: $(states "$array_job" | tr '\n' ' ')"
all_in "$merge_job" COMPLETED || fail "a) merge job $merge_job: $(states "$merge_job")"
[ "$(ls "$A/parts")" = "$(printf 'part-%04d.exr\n' 0 1 2 3)" ] || fail "a) parts: $(ls "$A/parts" | tr '\n' ' ')"
rmse=$(rmse_of "$A/frame.exr" "$T/single.exr")
awk -v r="$rmse" 'BEGIN { exit !(r != "" && r + 0 == 0) }' || fail "a) merged strips differ from the single render: rmse '$rmse'"
log "a) merged 4 strips = single-process render (rmse $rmse)"

# ---- b) 2 strips x 2 sample ranges; part 2 cancelled while it runs, then resubmitted -----------
B=$T/job-b
slow=$T/bin/obscura-slow
cat >"$slow" <<EOF
#!/usr/bin/env bash
# obscura, except that array task 2 waits while $T/hold-part-2 exists (so it can be cancelled).
if [ "\${1:-}" = render ] && [ "\${SLURM_ARRAY_TASK_ID:-}" = 2 ] && [ -e "$T/hold-part-2" ]; then
  touch "$T/part-2-started"
  sleep 120
fi
exec "$obscura" "\$@"
EOF
chmod +x "$slow"
touch "$T/hold-part-2"
submit "$B" --bin "$slow" --scene "$scene" --spp "$spp" --parts 4 --tiles 2 -- "${render_opts[@]}"
log "b) array job $array_job (2 strips x 2 sample ranges), merge job $merge_job"
wait_until 60 "task 2 to start and the others to finish" \
  eval '[ -e "$T/part-2-started" ] && all_in "${array_job}_0" COMPLETED && all_in "${array_job}_1" COMPLETED && all_in "${array_job}_3" COMPLETED'
# While part 2 runs, resubmit-missing.sh refuses (it would render part 2 twice).
if out=$("$farm/slurm/resubmit-missing.sh" "$B" 2>&1); then fail "b) resubmit-missing.sh while part 2 runs: $out"; fi
grep -q "still queued or running" <<<"$out" || fail "b) resubmit-missing.sh while part 2 runs: $out"
timeout 10 scancel "${array_job}_2" || fail "scancel ${array_job}_2"
log "b) cancelled running task ${array_job}_2"
wait_until 30 "task 2 and the merge job to end" eval 'finished "${array_job}_2" && finished "$merge_job"'
all_in "${array_job}_2" CANCELLED || fail "b) task 2: $(states "${array_job}_2")"
all_in "$merge_job" CANCELLED || fail "b) merge job after a cancelled part: $(states "$merge_job"), expected CANCELLED"
[ ! -e "$B/frame.exr" ] || fail "b) a merged image without part 2"
[ ! -e "$B/parts/part-0002.exr" ] || fail "b) a part file of the cancelled task"
# obscura merge refuses the three parts, names the missing piece, writes nothing.
status=0
"$obscura" merge "$B/parts" -o "$T/incomplete.exr" >"$T/log/incomplete.out" 2>"$T/log/incomplete.err" || status=$?
((status != 0)) || fail "b) obscura merge of 3 of 4 parts exited 0"
grep -qF 'tile 0/2 samples 4:8' "$T/log/incomplete.err" \
  || fail "b) obscura merge did not name the missing 'tile 0/2 samples 4:8': $(cat "$T/log/incomplete.err")"
[ ! -e "$T/incomplete.exr" ] || fail "b) obscura merge wrote an image of incomplete parts"
listed=$("$obscura" merge --list-missing "$B/parts") || fail "b) obscura merge --list-missing exited $?"
[ "$listed" = "--tile 0/2 --samples 4:8" ] || fail "b) --list-missing printed '$listed'"
log "b) obscura merge refuses the 3 parts (exit $status):"
sed 's/^/      /' "$T/log/incomplete.err"
# So does the merge job's script, naming the part by its index.
status=0
"$farm/merge.sh" "$B/job.env" >"$T/log/merge-sh.out" 2>"$T/log/merge-sh.err" || status=$?
((status != 0)) || fail "b) merge.sh of 3 of 4 parts exited 0"
grep -qE 'parts missing: 2$' "$T/log/merge-sh.err" || fail "b) merge.sh did not name part 2: $(cat "$T/log/merge-sh.err")"
[ ! -e "$B/frame.exr" ] || fail "b) merge.sh wrote an image of incomplete parts"
log "b) $(grep -F 'parts missing' "$T/log/merge-sh.err")"
rm "$T/hold-part-2"
out=$(cd "$T" && env OBSCURA_SLURM_TEST_TAG="$tag" "$farm/slurm/resubmit-missing.sh" "$B") \
  || fail "resubmit-missing.sh failed: $out"
grep -qx 'resubmit-missing.sh: parts missing: 2' <<<"$out" || fail "b) resubmit-missing.sh: $out"
read -r array_job2 merge_job2 <<<"$(tail -n 1 <<<"$out")"
[[ $array_job2 =~ ^[0-9]+$ && $merge_job2 =~ ^[0-9]+$ ]] || fail "b) resubmit-missing.sh printed: $out"
log "b) resubmitted: array job $array_job2 (part 2), merge job $merge_job2"
wait_until 60 "merge job $merge_job2" finished "$merge_job2"
all_in "$array_job2" COMPLETED || fail "b) resubmitted part: $(states "$array_job2")"
[ "$(timeout 5 scontrol -o show job "$array_job2" | grep -o 'ArrayTaskId=[0-9]*')" = ArrayTaskId=2 ] \
  || fail "b) the resubmission is not task 2 alone: $(timeout 5 scontrol -o show job "$array_job2" | grep -o 'ArrayTaskId=[^ ]*')"
all_in "$merge_job2" COMPLETED || fail "b) merge job $merge_job2: $(states "$merge_job2")"
rmse=$(rmse_of "$B/frame.exr" "$T/single.exr")
awk -v r="$rmse" 'BEGIN { exit !(r != "" && r + 0 < 1e-6) }' || fail "b) merged parts differ from the single render: rmse '$rmse'"
out=$("$farm/slurm/resubmit-missing.sh" "$B") || fail "resubmit-missing.sh on a complete job: $out"
grep -q 'complete: all 4 parts' <<<"$out" || fail "b) resubmit-missing.sh on a complete job: $out"
log "b) after resubmit-missing: merged = single-process render (rmse $rmse)"
log "PASS"
