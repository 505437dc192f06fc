#!/bin/bash
# run_fuzzer.sh FUZZER CORPUS_DIR [SECONDS] [FINDINGS_DIR]
# Runs the glTF loader fuzzer for SECONDS (default 30) on a COPY of CORPUS_DIR in a fresh temp
# folder (the checked-in corpus never grows), single process, at most 2 GiB RSS, 10 s per input.
# Exit 0: no finding. Otherwise libFuzzer's report is on stderr and the input is copied to
# FINDINGS_DIR (default: the current folder) as crash-*/leak-*/timeout-*/oom-*; once fixed, add
# it to tests/fuzz/regressions/.
# libFuzzer's -timeout is wall-clock time: on a loaded machine (the suite runs niced beside a
# benchmark) a process can be starved for longer than that. A timeout is therefore replayed alone
# and is a finding only if the input again takes more than 10 s; otherwise fuzzing resumes for
# the rest of the time.
set -u
fuzzer=$1
corpus=$2
seconds=${3:-30}
findings=${4:-$PWD}
dict=$(dirname "$0")/gltf.dict
work=$(mktemp -d "${TMPDIR:-/tmp}/obscura_fuzz_run_XXXXXX") || exit 2
trap 'rm -rf "$work"' EXIT
mkdir "$work/corpus" "$work/artifacts"
cp "$corpus"/* "$work/corpus/" || exit 2
# The fuzzer's scratch folder (fs::temp_directory_path) goes inside $work too: libFuzzer ends with
# _Exit on a finding or a time-out, so the fuzzer's own atexit clean-up does not run then.
export TMPDIR="$work"
deadline=$((SECONDS + seconds))
while [ $SECONDS -lt $deadline ]; do
  "$fuzzer" -max_total_time=$((deadline - SECONDS)) -rss_limit_mb=2048 -timeout=10 -dict="$dict" \
    -artifact_prefix="$work/artifacts/" -print_final_stats=1 "$work/corpus"
  status=$?
  unconfirmed=0
  for t in "$work"/artifacts/timeout-*; do
    [ -e "$t" ] || continue
    if "$fuzzer" -timeout=10 -rss_limit_mb=2048 "$t" >/dev/null 2>&1; then
      echo "run_fuzzer.sh: $(basename "$t") ran in time when replayed alone (machine load); resuming" >&2
      rm -f "$t"
      unconfirmed=1
    fi
  done
  if [ -n "$(ls -A "$work/artifacts")" ] || { [ $status -ne 0 ] && [ $unconfirmed -eq 0 ]; }; then
    mkdir -p "$findings"
    cp "$work/artifacts"/* "$findings/" 2>/dev/null
    echo "run_fuzzer.sh: FINDING (libFuzzer exit $status); inputs copied to $findings:" >&2
    ls "$work/artifacts" >&2
    exit 1
  fi
  [ $unconfirmed -eq 1 ] || break
done
echo "run_fuzzer.sh: no finding in ${seconds} s" >&2
