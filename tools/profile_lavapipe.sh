#!/bin/bash
# profile_lavapipe.sh — where a lavapipe kernel spends its time, instruction by instruction.
#
#   tools/profile_lavapipe.sh OUT WARM_SECONDS SAMPLE_SECONDS ./build/obscura render ... (or bench-rays ...)
#
# Starts the command, waits WARM_SECONDS (scene load, BVH build, kernel compiles), samples the
# process with `perf record` for SAMPLE_SECONDS, then disassembles the hottest 64 KiB of JIT code
# with gdb from the still-running process (lavapipe's code has no symbols, so perf alone shows
# bare addresses) and stops it. Writes:
#   OUT.hot   per instruction address, its share of the samples (perf report)
#   OUT.ann   the disassembly, each instruction prefixed by its share
#   OUT.loops the backward jumps of more than 1 KiB (the kernel's loops) and each 1 KiB block's share
# Give the command enough work (spp, --repeats) to run past WARM + SAMPLE seconds. Needs perf and
# gdb (apt install linux-perf gdb) and permission to ptrace and sample the process (root here).
# A study tool, not a test: docs/BENCHMARKS.md says what it showed.
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n 4,5p "$0" >&2
  exit 2
fi
out=$1 warm=$2 sample=$3
shift 3
"$@" > "$out.log" 2>&1 &
pid=$!
sleep "$warm"
if ! kill -0 "$pid" 2>/dev/null; then
  echo "profile_lavapipe.sh: '$*' ended within $warm s; give it more work" >&2
  exit 1
fi
perf record -o "$out.data" -F 4000 -p "$pid" -- sleep "$sample" > /dev/null 2>&1
perf report -i "$out.data" --no-children --sort sym -g none 2>/dev/null |
  awk '$3 ~ /^0x0000/ {print $1, $3}' > "$out.hot"
# The code around the hottest instruction: from the first to the last instruction with samples
# within 64 KiB of it (one kernel; its out-of-line fetch functions follow it).
read -r lo hi < <(python3 - "$out.hot" <<'PY'
import sys
hot = [(float(l.split()[0].rstrip('%')), int(l.split()[1], 16)) for l in open(sys.argv[1])]
top = hot[0][1]
addresses = [a for p, a in hot if abs(a - top) < 0x10000 and p > 0.02]
print(hex(min(addresses)), hex(max(addresses) + 64))
PY
)
gdb -p "$pid" -batch -ex "disassemble $lo,$hi" 2>/dev/null | grep '^ ' > "$out.asm" || true
kill "$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
python3 - "$out" <<'PY'
import collections, re, sys
out = sys.argv[1]
hot = {int(l.split()[1], 16): float(l.split()[0].rstrip('%')) for l in open(out + '.hot')}
rows = []
for line in open(out + '.asm'):
    m = re.match(r'\s*(0x[0-9a-f]+)[^:]*:\s*(.*)', line)
    if m:
        rows.append((hot.get(int(m.group(1), 16), 0.0), int(m.group(1), 16), m.group(2)))
if not rows:
    sys.exit('profile_lavapipe.sh: gdb disassembled nothing (was the process still running?)')
base = rows[0][1]
with open(out + '.ann', 'w') as f:
    for p, a, t in rows:
        f.write(f'{p:6.2f} {a - base:6x} {t}\n')
blocks = collections.Counter()
with open(out + '.loops', 'w') as f:
    for p, a, t in rows:
        blocks[(a - base) >> 10] += p
        m = re.match(r'(j\w+)\s+(0x[0-9a-f]+)', t)
        if m and base <= int(m.group(2), 16) < a - 1024:
            f.write(f'loop {int(m.group(2), 16) - base:x} .. {a - base:x}: {a - int(m.group(2), 16)} bytes\n')
    for k in sorted(blocks):
        if blocks[k] >= 0.1:
            f.write(f'block {k << 10:6x} {blocks[k]:6.2f} %\n')
print(f'{len(rows)} instructions, {sum(p for p, _, _ in rows):.1f} % of the samples: {out}.ann, {out}.loops')
PY
