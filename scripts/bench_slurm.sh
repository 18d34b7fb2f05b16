#!/usr/bin/env bash
# The cost of splitting: `cornell-gi --gi path` at 256 spp rendered by one
# process, then as 4 parts through scripts/cluster/slurm-render.sh on a
# one-node Slurm cluster started here (on ports of its own), from
# submission to the merged image. Prints both wall times, their ratio and
# the difference (the overhead of splitting, queueing and merging), and
# checks that the two images are the same bits. Each round runs the two one
# right after the other; a shared machine's speed drifts between minutes.
#
#   bash scripts/bench_slurm.sh      (ROUNDS=3 for more rounds, default 1;
#                                     SPLIT=samples to split the samples)
#
# Needs root and Debian's slurm-wlm and munge (scripts/cluster/start_local_slurm.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${ROUNDS:-1}
split=${SPLIT:-tiles}
bin=$(readlink -f "${CARGO_TARGET_DIR:-target}/release/pinhole")
[ -x "$bin" ] || { echo "bench_slurm.sh: build first (cargo build --release)" >&2; exit 2; }
work=$(mktemp -d /tmp/bench-slurm.XXXXXX)
chmod 755 "$work"   # munged wants its socket's folders open to all
ports=(SLURM_CTLD_PORT=6937 SLURMD_PORT=6938 SLURM_SRUN_PORTS=63401-63700)
env "${ports[@]}" SLURM_NO_INSTALL=1 SLURM_CPUS=4 scripts/cluster/start_local_slurm.sh "$work/cluster" >/dev/null
trap 'env "${ports[@]}" scripts/cluster/stop_local_slurm.sh "$work/cluster" --purge >/dev/null 2>&1; rm -rf "$work"' EXIT
export SLURM_CONF=$work/cluster/etc/slurm.conf
opts=(--gi path --spp 256)
now() { date +%s.%N; }
for round in $(seq 1 "$rounds"); do
    # With as many threads as the 4 parts run together (each part takes every
    # core): on a machine shared with other work the scheduler shares the
    # cores out per thread, so this is the fair single-process figure there.
    s0=$(now)
    "$bin" render cornell-gi -o "$work/single8.exr" "${opts[@]}" --threads $((4 * $(nproc))) 2>/dev/null
    t0=$(now)
    "$bin" render cornell-gi -o "$work/single.exr" "${opts[@]}" 2>/dev/null
    t1=$(now)
    rm -rf "$work/split.exr" "$work/split.exr.parts"
    said=$(PINHOLE=$bin scripts/cluster/slurm-render.sh cornell-gi "$work/split.exr" --parts 4 --split "$split" "${opts[@]}")
    merge=$(sed -n 's/^merge //p' <<<"$said")
    while [ -n "$(squeue -h -j "$merge" 2>/dev/null)" ]; do sleep 0.2; done
    t2=$(now)
    [ -f "$work/split.exr" ] || { echo "round $round: the merge wrote nothing; logs in $work/split.exr.parts" >&2; cat "$work"/split.exr.parts/*.log >&2; exit 1; }
    same=$("$bin" compare "$work/single.exr" "$work/split.exr" --json | python3 -c 'import json,sys; print("the same pixels" if json.load(sys.stdin)["max_abs"] == 0 else "DIFFERENT pixels")')
    python3 - "$t0" "$t1" "$t2" "$round" "$same" "$work/split.exr.json" "$s0" <<'PY'
import json, sys
t0, t1, t2 = map(float, sys.argv[1:4])
single, split = t1 - t0, t2 - t1
single_many = t0 - float(sys.argv[7])
# The parts' own span (first start to last end) from the merged statistics:
# what Slurm adds is the wait before the first part and after the last.
stats = json.load(open(sys.argv[6]))
before = stats["started_unix_ms"] / 1e3 - t1
after = t2 - stats["finished_unix_ms"] / 1e3
print(f"round {sys.argv[4]}: one process {single:.1f} s, 4 Slurm parts {split:.1f} s (submission to merged image), "
      f"ratio {split / single:.3f}; one process with the parts' thread count {single_many:.1f} s, ratio {split / single_many:.3f}; parts rendering {stats['wall_clock_ms'] / 1e3:.1f} s, "
      f"submission to first part {before:.1f} s, last part to merged image {after:.1f} s; {sys.argv[5]}")
PY
done
