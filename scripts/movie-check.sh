#!/usr/bin/env bash
# The movie issue's "done when" check (docs/movies.md), at any scale: an
# orbit of a CT-like head (scripts/make_ct_phantom.py) rendered to MP4
# through --keyframes, then
#   - ffprobe's frame count, size and rate;
#   - decoded frames against `volray render` stills at each frame's
#     interpolated azimuth: PSNR (ffmpeg's psnr filter) >= 40 dB;
#   - the time per frame of the last tenth against the first tenth (the
#     frames' finishing times, from the work folder of a run in parts:
#     frames 0..N-2 with --movie-frames, then the last with --resume);
#   - volray's peak memory for those frames (ffmpeg is not running then).
#
#   [CRF=N] scripts/movie-check.sh VOLRAY [VOXELS=512] [FRAMES=360] [SIZE=1920x1080]
#
# Heavy at the defaults (a 512^3 volume, 360 frames of 1080p): run it on a
# quiet machine. Needs ffmpeg, ffprobe, GNU time and python3 with numpy
# (target/pyenv has it).
set -euo pipefail
volray=$(realpath "$1")
voxels=${2:-512}
frames=${3:-360}
size=${4:-1920x1080}
here=$(cd "$(dirname "$0")" && pwd)
python=${PYTHON:-$here/../target/pyenv/bin/python}
[ -x "$python" ] || python=python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

"$python" "$here/make_ct_phantom.py" "$voxels" head.raw >/dev/null 2>&1
input=(head.raw --dims "$voxels,$voxels,$voxels" --dtype i16 --preset ct-bone --size "$size" --elevation 15)
fps=30
last=$(python3 -c "print(($frames - 1) / $fps)")
cat >orbit.json <<JSON
{"version": 1, "fps": $fps, "keyframes": [
  {"t": 0, "azimuth": 0, "ease": "linear"},
  {"t": $last, "azimuth": 359}]}
JSON

# Every frame but the last, kept with their finishing times; then the last
# and the encoding.
crf=()
[ -n "${CRF:-}" ] && crf=(--crf "$CRF")
/usr/bin/time -v "$volray" render "${input[@]}" --keyframes orbit.json -o orbit.mp4 "${crf[@]}" \
  --movie-frames "0:$((frames - 1))" 2>time.txt >/dev/null
rss=$(awk -F: '/Maximum resident/ {gsub(/ /, "", $2); print $2}' time.txt)
python3 - "$frames" orbit.mp4.frames <<'PY' >tenths.txt
import os, sys
n = int(sys.argv[1]) - 1
t = [os.stat(os.path.join(sys.argv[2], f"{k:06}.png")).st_mtime for k in range(n)]
d = [b - a for a, b in zip(t, t[1:])]
tenth = max(1, len(d) // 10)
first, last = sum(d[:tenth]) / tenth, sum(d[-tenth:]) / tenth
print(f"{first:.3f} {last:.3f} {100 * (last / first - 1):+.1f}")
PY
"$volray" render "${input[@]}" --keyframes orbit.json -o orbit.mp4 "${crf[@]}" --resume 2>/dev/null

probe=$(ffprobe -v error -count_frames -select_streams v:0 \
  -show_entries stream=width,height,r_frame_rate,nb_read_frames -of csv=p=0 orbit.mp4)
echo "ffprobe (width,height,rate,frames): $probe (expected ${size/x/,},$fps/1,$frames)"
read -r first lastt change <tenths.txt
echo "seconds a frame: first tenth $first, last tenth $lastt ($change %)"
echo "peak memory rendering $((frames - 1)) frames: $rss kB"

worst=1000
for k in 0 $((frames / 3)) $((2 * frames / 3)) $((frames - 1)); do
  azimuth=$(python3 -c "print(359 * ($k / $fps) / $last if $last else 0)")
  "$volray" render "${input[@]}" --azimuth "$azimuth" -o "still$k.png" 2>/dev/null
  ffmpeg -v error -i orbit.mp4 -vf "select=eq(n\\,$k)" -frames:v 1 -y "frame$k.png"
  db=$(ffmpeg -i "frame$k.png" -i "still$k.png" -lavfi psnr -f null - 2>&1 |
    sed -n 's/.*average:\([0-9.inf]*\).*/\1/p')
  echo "frame $k (azimuth $azimuth): PSNR $db dB"
  worst=$(python3 -c "print(min($worst, float('$db')))")
done
python3 -c "import sys; sys.exit(0 if $worst >= 40 else 1)" && echo "every checked frame >= 40 dB" ||
  { echo "a frame under 40 dB"; exit 1; }
