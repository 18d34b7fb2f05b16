#!/usr/bin/env bash
# Indirect light, error against time, with Mitsuba 3's own curve on the chart:
# Mitsuba's `path` integrator at several spp (best of warm renders, independent
# seed) measured against the 4096-spp reference, then `pinhole chart --sweep gi`
# on the same scene with those points as `--peer`. Both in ONE run, so the
# times compare.
#
#   bash scripts/gi_chart.sh [OUT.png]        (default: screenshots/chart-gi-cornell.png)
#
# Needs Mitsuba 3 in a Python venv at /tmp/peers (or PEERS_PYTHON); see
# scripts/bench_peers.sh for the install lines. SPP_LIST=1,4,16 shortens it.
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
py=${PEERS_PYTHON:-/tmp/peers/bin/python}
out=${1:-screenshots/chart-gi-cornell.png}
spp_list=${SPP_LIST:-1,4,16,64}
bin=target/release/pinhole
cargo build --release --quiet
scene="$shared/references/cornell_gi.toml"
reference="$shared/references/cornell_gi.exr"
peer=$(mktemp --suffix .csv)
trap 'rm -f "$peer" "$peer.exr"' EXIT
echo "series,label,ms,rel_rmse" > "$peer"
for spp in ${spp_list//,/ }; do
    line=$("$py" "$shared/tools/reference.py" "$scene" "$peer.exr" --integrator path --max-depth -1 --spp "$spp" --seed 7 --time 3 2>&1 | grep render_ms)
    ms=$(sed -E 's/.*render_ms=([0-9.]+).*/\1/' <<< "$line")
    err=$("$bin" compare "$peer.exr" "$reference" --json | python3 -c "import json,sys; m=json.load(sys.stdin); print(m['rmse']/m['reference_mean'])")
    echo "mitsuba 3 path (llvm),$spp spp,$ms,$err" | tee -a "$peer"
done
"$bin" chart "$scene" --sweep gi --spp-list "$spp_list" --reference "$reference" --peer "$peer" -o "$out"
