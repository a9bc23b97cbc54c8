#!/usr/bin/env bash
# Time and peak RSS of volray on a chunked, multiscale OME-Zarr volume against
# the same volume mapped from raw (docs/performance.md, "Chunked, multiscale
# volumes (OME-Zarr)"). Each case runs RUNS times under scripts/rss_peak.py;
# the JSON line of each run and the volray stderr notes go to OUTDIR/log.txt,
# and a median summary is printed at the end.
#
#   scripts/zarr_bench.sh RAW DIMS ZARR [RUNS] [OUTDIR]
#   e.g. scripts/zarr_bench.sh /tmp/bigvol/ct1024.raw 1024,1024,1024 /tmp/bigvol/ct1024.ome.zarr 3
#
# RAW is u16 (HU + 1024, scripts/make_ct_phantom.py --dtype u16), so the CT
# preset is given as a --tf with ct-bone's points and its domain shifted by
# +1024 (-1000..2000 HU -> 24..3024); `--preset ct-bone` itself would read the
# u16 values as Hounsfield units.
set -euo pipefail
RAW=$1; DIMS=$2; ZARR=$3; RUNS=${4:-3}; OUT=${5:-/tmp/bigvol/bench}
V=${VOLRAY:-target/release/volray}
PY=${PYTHON:-target/pyenv/bin/python}  # needs numpy and PIL for the image check (target/pyenv/bin/python)
mkdir -p "$OUT"
TF=$OUT/ct-bone-u16.json
cat > "$TF" <<'JSON'
{"domain": [24, 3024],
 "opacity": [[0.38333333, 0.0], [0.46666667, 0.3], [0.66666667, 0.8], [1.0, 0.95]],
 "color": [[0.38333333, 0.85, 0.72, 0.55], [0.56666667, 0.95, 0.9, 0.8], [1.0, 1.0, 1.0, 1.0]]}
JSON
LOG=$OUT/log.txt; : > "$LOG"
run() {  # NAME ARGS...
  local name=$1; shift
  for i in $(seq "$RUNS"); do
    echo "== $name run $i: $*" >> "$LOG"
    "$PY" scripts/rss_peak.py -- "$@" > /dev/null 2>> "$LOG.tmp" || true
    cat "$LOG.tmp" | grep -v '^\s*\[' >> "$LOG"; rm -f "$LOG.tmp"
  done
}
R="--tf $TF --size 1024"
run info            "$V" info "$ZARR"
run info-level4     "$V" info "$ZARR" --level 4
run auto-1024       "$V" render "$ZARR" --level auto $R -o "$OUT/auto.png"
run auto-512        "$V" render "$ZARR" --level auto --tf "$TF" --size 512 -o "$OUT/auto512.png"
run level0-whole    "$V" render "$ZARR" --level 0 $R -o "$OUT/level0.png"
run level0-pieces   "$V" render "$ZARR" --level 0 --max-memory 1.5G $R -o "$OUT/level0-pieces.png"
run level1          "$V" render "$ZARR" --level 1 $R -o "$OUT/level1.png"
# Under --max-memory a raw file is read whole into memory; over it, mapped.
run raw-read-whole  "$V" render "$RAW" --dims "$DIMS" --dtype u16 $R -o "$OUT/raw.png"
run raw-mapped      "$V" render "$RAW" --dims "$DIMS" --dtype u16 --max-memory 1.5G $R -o "$OUT/raw-mapped.png"
"$PY" - "$LOG" <<'PYEOF'
import json, statistics, sys
cur, rows = None, {}
for line in open(sys.argv[1]):
    if line.startswith("== "):
        cur = line[3:].split(" run ")[0]
    elif line.startswith("{"):
        rows.setdefault(cur, []).append(json.loads(line))
for name, rs in rows.items():
    med = lambda k: statistics.median(r[k] for r in rs)
    print(f"{name:15s} n={len(rs)} wall_s={med('wall_s'):.2f} (all {[r['wall_s'] for r in rs]}) "
          f"anon={med('peak_anon_gib'):.2f} file={med('peak_file_gib'):.2f} hwm={med('vm_hwm_gib'):.2f} GiB "
          f"exit={[r['exit'] for r in rs]}")
PYEOF
# The level-0 images (whole, in pieces, --level auto when it picks 0) against the raw ones.
"$PY" - "$OUT" <<'PYEOF'
import os, sys
import numpy as np
from PIL import Image
d = sys.argv[1]
ref = np.asarray(Image.open(os.path.join(d, "level0.png"))).astype(int)
for name in ("level0-pieces", "auto", "raw", "raw-mapped"):
    img = np.asarray(Image.open(os.path.join(d, name + ".png"))).astype(int)
    diff = np.abs(ref - img)
    print(f"level0 vs {name}: max channel difference {diff.max()}, "
          f"{int((diff.max(axis=-1) > 0).sum())} pixels differ")
PYEOF
