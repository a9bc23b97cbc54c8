#!/usr/bin/env bash
# Renders the gallery's figures with annotations (docs/options.md,
# "Figures"): |psi_621|^2 under --log with a colour bar in decades, a
# scale bar and the axes; a
# fractal cloud with its outline; a CT-like head (scripts/make_ct_phantom.py
# at 256^3, 1 mm voxels) with a colour bar in HU and a scale bar; and the
# head and the cloud without and with --shadows (docs/options.md,
# "Shadows"); blobs and the cloud's isosurface without and with
# --ambient-occlusion ("Ambient occlusion").
#
#     docs/gallery/figures.sh docs/gallery [path/to/volray]
set -euo pipefail
out=${1:?"the folder to write into"}
volray=${2:-target/release/volray}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$volray" render hydrogen:6,2,1 --view 150,150,500 --size 420 \
  --log --range 1e-8,3e-5 --colormap viridis \
  --colorbar --scale-bar --axes --title "hydrogen 6,2,1, log" --label a \
  -o "$out/figure-hydrogen.png"
"$volray" render fractal:129 --colormap inferno --size 420 --azimuth 30 --elevation 20 \
  --colorbar --scale-bar --outline --label b \
  -o "$out/figure-cloud.png"
python3 scripts/make_ct_phantom.py 256 "$tmp/head.raw" >/dev/null
"$volray" render "$tmp/head.raw" --dims 256,256,256 --dtype i16 --spacing 1,1,1 \
  --preset ct-bone --size 420 --azimuth 30 --elevation 15 \
  --colorbar --scale-bar --axes --label c \
  -o "$out/figure-ct.png"

# Depth cues: the same frames without and with shadows, the camera's key
# light in both (given as --light, so that the pair differs only in the
# shadows).
"$volray" render "$tmp/head.raw" --dims 256,256,256 --dtype i16 --spacing 1,1,1 \
  --preset ct-bone --size 420 --azimuth 30 --elevation 15 --light 0.6,-0.1,0.8 \
  --label "without shadows" -o "$out/shadows-ct-off.png"
"$volray" render "$tmp/head.raw" --dims 256,256,256 --dtype i16 --spacing 1,1,1 \
  --preset ct-bone --size 420 --azimuth 30 --elevation 15 --light 0.6,-0.1,0.8 \
  --shadows --label "with shadows" -o "$out/shadows-ct-on.png"
"$volray" render fractal:129 --size 420 --azimuth 30 --elevation 20 \
  --light 0.6,-0.1,0.8 --label "without shadows" -o "$out/shadows-cloud-off.png"
"$volray" render fractal:129 --size 420 --azimuth 30 --elevation 20 \
  --light 0.6,-0.1,0.8 --shadows --label "with shadows" -o "$out/shadows-cloud-on.png"

# Ambient occlusion: the same frames without and with it, the ambient
# light raised to half of the light so that it shows.
for ao in off on; do
  flag=(); [ "$ao" = on ] && flag=(--ambient-occlusion)
  label="without ambient occlusion"; [ "$ao" = on ] && label="with ambient occlusion"
  "$volray" render blobs:128 --blend iso --iso 0.3 --size 420 --azimuth 30 --elevation 30 \
    --ambient 0.5 --diffuse 0.45 --specular 0.05 "${flag[@]}" --label "$label" \
    -o "$out/ao-blobs-$ao.png"
  "$volray" render fractal:129 --blend iso --iso 0.12 --size 420 --azimuth 30 --elevation 20 \
    --ambient 0.5 --diffuse 0.45 --specular 0.05 "${flag[@]}" --label "$label" \
    -o "$out/ao-cloud-$ao.png"
done
