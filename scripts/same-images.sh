#!/usr/bin/env bash
# Renders the same frames with two volray binaries and checks that the
# files are byte-identical: the paper's figures (volray paper), the peers'
# six workloads as 16-bit PNGs, a frame of every fast path (perspective,
# projections, post-classification, iso, gradient opacity, crop, clip,
# jitter), figures (colour bars, scale bar, axes, outline, titles) and
# scenes (overlays) as 16-bit PNGs. For refactorings that must not change
# a pixel.
#
#   scripts/same-images.sh OLD_VOLRAY NEW_VOLRAY [PEERS_VOLUMES_DIR]
#
# PEERS_VOLUMES_DIR holds the peers' volumes (`make_volumes.py` in
# ../shared/peers writes them); without it the peers' workloads are skipped
# with a note. Exit status 0 when every file is identical, 1 otherwise.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 OLD_VOLRAY NEW_VOLRAY [PEERS_VOLUMES_DIR]" >&2
  exit 2
fi
old=$(realpath "$1")
new=$(realpath "$2")
peers=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/old" "$work/new"

# name|arguments of `volray render` (16-bit PNG output added below).
cases=(
  "blobs-default|blobs:64"
  "ml-default|marschner-lobb:41 --size 200"
  "hydrogen-621|hydrogen:6,2,1 --view 150,150,500 --colormap magma --size 160"
  "fractal-129-step|fractal:129,seed=2 --step 0.5 --colormap inferno --size 240"
  "perspective|fractal:65 --perspective 40 --azimuth 30 --elevation 20 --size 200"
  "perspective-inside|blobs:48 --perspective 90 --view 0,0,0 --look-at 1,0.2,0.1 --size 160"
  "mip|marschner-lobb:41 --blend mip --colormap viridis --size 160"
  "minip|hydrogen:4,2,0 --blend minip --size 160"
  "average|fractal:65 --blend average --perspective 30 --size 160"
  "post|marschner-lobb:41 --post-classification --size 160"
  "post-perspective|fractal:65 --post-classification --perspective 50 --step 0.7 --size 160"
  "post-unlit|blobs:48 --post-classification --no-shading --colormap coolwarm --size 160"
  "iso|hydrogen:4,2,0 --iso 2e-6 --view 150,150,500 --size 160"
  "iso-post|hydrogen:4,2,0 --iso 2e-6 --post-classification --size 160"
  "gradient-opacity|fractal:65 --gradient-opacity 0.1,0.6 --size 160"
  "crop-clip-jitter|blobs:64 --crop -1,1,-1,0.2,-1,1 --clip 0,0,0,1,1,0 --jitter --size 160"
  "crop-clip-post|blobs:64 --crop -1,1,-1,0.2,-1,1 --clip 0,0,0,1,1,0 --jitter --post-classification --size 160"
  "lights|torus --light 1,2,3 --light-color 1,0.8,0.6 --ambient 0.2 --diffuse 0.5,0.6,0.7 --specular 0.4 --shininess 7.5 --background 0.1,0.2,0.3 --size 160"
  "log-range|hydrogen:4,2,0 --log --range 1e-9,1e-3 --colormap inferno --size 160"
  "figure|hydrogen:4,2,0 --colormap magma --colorbar --scale-bar --axes --outline --title Orbital --label a --size 200"
  "figure-left-log|hydrogen:4,2,0 --log --colorbar left --units counts --size 200x160"
  "scene-overlay-additive|blobs:48 --overlay sphere:48,radius=0.5:colormap=magma --mix additive --size 160"
  "scene-overlay-perspective|fractal:65 --overlay torus:40:colormap=viridis --perspective 40 --azimuth 20 --size 160"
)

if [ -n "$peers" ]; then
  # The peers' workloads (common.py): view along +x through the centre,
  # step 0.5, their opacity and cool-to-warm colour over [min, max].
  for spec in hydrogen_421:120 hydrogen_632:120 fractal_65:240 fractal_129:480 fractal_257:480 fractal_257:1024; do
    name=${spec%:*}
    window=${spec#*:}
    args=$(python3 - "$peers/$name.json" "$work/$name.tf.json" "$window" <<'PY'
import json, sys
side = json.load(open(sys.argv[1]))
dims, spacing = side["dims"], side.get("spacing", [1, 1, 1])
centre = [(n - 1) * h / 2 for n, h in zip(dims, spacing)]
tf = {
    "domain": [side["min"], side["max"]],
    "opacity": [[0, 0], [0.05, 0], [0.95, 0.95], [1, 0.95]],
    "color": [[0, 0.230, 0.299, 0.754], [0.5, 0.865, 0.865, 0.865], [1, 0.706, 0.016, 0.150]],
}
json.dump(tf, open(sys.argv[2], "w"))
eye = [centre[0] - 1000.0, centre[1], centre[2]]
fmt = lambda v: ",".join(repr(float(x)) for x in v)
print(f"--dims {','.join(map(str, dims))} --dtype f32 --spacing {fmt(spacing)} "
      f"--view {fmt(eye)} --look-at {fmt(centre)} --step 0.5 --tf {sys.argv[2]} --size {sys.argv[3]}")
PY
)
    cases+=("peers-$name-$window|$peers/$name.raw $args")
  done
else
  echo "note: no peers' volumes directory given: their six workloads are skipped"
fi

different=0
for case in "${cases[@]}"; do
  name=${case%%|*}
  args=${case#*|}
  for side in old new; do
    bin=$old
    [ "$side" = new ] && bin=$new
    # shellcheck disable=SC2086
    "$bin" render $args --bit-depth 16 -o "$work/$side/$name.png"
  done
  if cmp -s "$work/old/$name.png" "$work/new/$name.png"; then
    echo "same       $name"
  else
    echo "DIFFERENT  $name"
    different=1
  fi
done

for figure in figure1a figure1b figure1c figure2a figure2b; do
  for side in old new; do
    bin=$old
    [ "$side" = new ] && bin=$new
    "$bin" paper "$figure" --out "$work/$side/paper" >/dev/null
  done
  if cmp -s "$work/old/paper/$figure.png" "$work/new/paper/$figure.png"; then
    echo "same       paper $figure"
  else
    echo "DIFFERENT  paper $figure"
    different=1
  fi
done

if [ "$different" = 0 ]; then
  echo "every image is byte-identical"
else
  echo "some images differ" >&2
fi
exit "$different"
