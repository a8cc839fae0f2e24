#!/bin/sh
# animate.sh RUN_DIR [FPS] -- the frames of a run (output.frames_every) as
# RUN_DIR/animation.mp4 (H.264, yuv420p: plays in browsers and players).
# Needs ffmpeg: `make deps-animation` installs it.
set -eu
usage="usage: ${0##*/} RUN_DIR [FPS]   writes RUN_DIR/animation.mp4 from RUN_DIR/frames"
case ${1:-} in
-h | --help) echo "$usage"; exit 0 ;;
"") echo "$usage" >&2; exit 2 ;;
esac
dir=$1
fps=${2:-25}
if [ ! -d "$dir/frames" ] || [ -z "$(ls "$dir/frames" 2>/dev/null | grep '^frame-.*\.png$')" ]; then
  echo "${0##*/}: $dir/frames has no frames (set output.frames_every in the scene)" >&2
  exit 2
fi
command -v ffmpeg >/dev/null 2>&1 || { echo "${0##*/}: ffmpeg not found (make deps-animation)" >&2; exit 2; }
# the frames are numbered by sweep, not consecutively: a glob, in order
ffmpeg -loglevel error -y -framerate "$fps" -pattern_type glob -i "$dir/frames/frame-*.png" \
  -vf "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white" -c:v libx264 -pix_fmt yuv420p "$dir/animation.mp4"
echo "$dir/animation.mp4"
