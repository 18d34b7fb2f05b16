#!/usr/bin/env bash
# `--gi path` at 16 spp against Mitsuba 3's `path` integrator at 16 spp, on
# cornell_gi and bunny_ground. Each round renders with Mitsuba, then with
# each pinhole binary, one right after the other: each side's best of three
# warm renders after a first one (Mitsuba's `--time 3`; `pinhole bench
# --frames 3`). A shared machine's speed can change by tens of percent from
# one minute to the next, so a single pair of timings says little; the
# ratio of each round's pair is printed, then per scene the median ratio
# over the rounds and its range.
#
#   bash scripts/bench_gi.sh        (ROUNDS=5 for more rounds, default 3;
#                                    BASE_BIN=older/pinhole adds its figures)
#
# Needs Mitsuba 3 in a Python venv at /tmp/peers (or PEERS_PYTHON); see
# scripts/bench_peers.sh for the install lines.
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
py=${PEERS_PYTHON:-/tmp/peers/bin/python}
rounds=${ROUNDS:-3}
bin=target/release/pinhole
cargo build --release --quiet
bins=("$bin")
[ -n "${BASE_BIN:-}" ] && bins=("$BASE_BIN" "$bin")
ratios=$(mktemp)
trap 'rm -f "$ratios"' EXIT
for name in cornell_gi bunny_ground; do
    scene="$shared/references/$name.toml"
    for round in $(seq 1 "$rounds"); do
        mitsuba=$("$py" "$shared/tools/reference.py" "$scene" /tmp/bench_gi_mitsuba.exr --integrator path --max-depth -1 --spp 16 --time 3 2>&1 | sed -nE 's/.*render_ms=([0-9.]+).*/\1/p')
        for b in "${bins[@]}"; do
            best=$("$b" bench "$scene" --gi path --spp 16 --frames 3 2>/dev/null | python3 -c "import json,sys; print(json.load(sys.stdin)['render_ms_min'])")
            python3 -c "print(f'$name round $round: $b {float($best):.0f} ms, mitsuba 3 path {float($mitsuba):.0f} ms = {float($best)/float($mitsuba):.2f}x')"
            echo "$name $b $best $mitsuba" >> "$ratios"
        done
    done
done
python3 - "$ratios" <<'EOF'
import sys, statistics, collections
runs = collections.defaultdict(list)
for line in open(sys.argv[1]):
    name, b, ours, theirs = line.split()
    runs[(name, b)].append(float(ours) / float(theirs))
for (name, b), r in runs.items():
    print(f"{name}: {b} median {statistics.median(r):.2f}x mitsuba 3 path over {len(r)} rounds (range {min(r):.2f}-{max(r):.2f}x)")
EOF
