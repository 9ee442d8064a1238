#!/usr/bin/env bash
# Usage: scripts/measure-observer.sh [with-first|without-first]   (build the binaries first)
# One long ARMAR-4 walk (kinematic sim, 500 Hz real time); walkd's deadline misses over a 60 s
# window with `walkctl record` attached (its own process, measured by /usr/bin/time) and over a
# 60 s window without, read from walkd's status at the window boundaries.
cd "$(dirname "$0")/.."
B=target/release
P=walk-measure2/$$
order=${1:-with-first}
$B/walkctl demo --robot armar4 --distance 2.5 --json --service-prefix $P > ${TMPDIR:-/tmp}/observer-cost-demo-$order.json 2>/dev/null &
DEMO=$!
for i in $(seq 100); do $B/walkctl status --service-prefix $P >/dev/null 2>&1 && break; sleep 0.2; done
sleep 3
misses() { $B/walkctl status --service-prefix $P --json | python3 -c "import json,sys; print(json.load(sys.stdin)['deadline_misses'])"; }
windows=(with without); [[ $order == without-first ]] && windows=(without with)
for w in "${windows[@]}"; do
  m0=$(misses)
  if [[ $w == with ]]; then
    /usr/bin/time -f "cpu_user_s=%U cpu_sys_s=%S cpu_pct=%P max_rss_kb=%M wall_s=%e" $B/walkctl record --config configs/armar4.toml --service-prefix $P -o ${TMPDIR:-/tmp}/observer-cost.mcap --duration 60 --json > ${TMPDIR:-/tmp}/observer-cost-record-$order.json 2> ${TMPDIR:-/tmp}/observer-cost-time-$order.txt
  else
    sleep 60
  fi
  m1=$(misses)
  echo "$order $w deadline_misses=$((m1 - m0))"
done
wait $DEMO
