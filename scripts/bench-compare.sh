#!/usr/bin/env bash
# Times two volray binaries on the peers' six workloads in one run,
# alternating them round by round (so that both see the same machine),
# and prints each workload's median frame time per binary and their ratio.
#
#   scripts/bench-compare.sh OLD_VOLRAY NEW_VOLRAY PEERS_VOLUMES_DIR [ROUNDS] [THREADS]
#
# Each round runs `volray bench --peers DIR --json` once per binary (one
# warm-up and 5 timed frames per workload); the table gives the median over
# the rounds of those medians. ROUNDS defaults to 3, THREADS to 2.
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 OLD_VOLRAY NEW_VOLRAY PEERS_VOLUMES_DIR [ROUNDS] [THREADS]" >&2
  exit 2
fi
old=$(realpath "$1")
new=$(realpath "$2")
dir=$3
rounds=${4:-3}
threads=${5:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

for round in $(seq 1 "$rounds"); do
  for side in old new; do
    bin=$old
    [ "$side" = new ] && bin=$new
    "$bin" bench --peers "$dir" --threads "$threads" --json "$work/$side-$round.json" >/dev/null
  done
  echo "round $round of $rounds done" >&2
done

python3 - "$work" "$rounds" <<'PY'
import json, statistics, sys
work, rounds = sys.argv[1], int(sys.argv[2])
times = {}
for side in ("old", "new"):
    for r in range(1, rounds + 1):
        for row in json.load(open(f"{work}/{side}-{r}.json")):
            key = (row["dataset"], row["window"])
            times.setdefault(key, {}).setdefault(side, []).append(row["median_s"])
print(f"| workload | old (ms) | new (ms) | new / old |")
print(f"|---|---|---|---|")
for (dataset, window), t in times.items():
    old, new = statistics.median(t["old"]), statistics.median(t["new"])
    print(f"| {dataset} @{window} | {old * 1e3:.2f} | {new * 1e3:.2f} | {new / old:.3f} |")
PY
