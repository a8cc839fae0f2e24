#!/bin/sh
# animate.sh RUN_DIR [FPS] -- the frames of a run (output.frames_every) as
# RUN_DIR/animation.mp4 (H.264, yuv420p: plays in browsers and players).
# Needs ffmpeg: `make deps-animation` installs it.
set -eu
# the tools' words are matched below (a full disk is the machine's: exit 1)
export LC_ALL=C
# a closed standard stream would fail the checks below (awk cannot close
# it) or be the first file opened: /dev/null stands in
(exec 9>&1) 2>/dev/null || exec >/dev/null
(exec 9>&2) || exec 2>/dev/null
usage="usage: ${0##*/} RUN_DIR [FPS]   writes RUN_DIR/animation.mp4 from RUN_DIR/frames"
case ${1:-} in
-h | --help) echo "$usage"; exit 0 ;;
"") echo "$usage" >&2; exit 2 ;;
esac
if [ $# -gt 2 ]; then
  echo "${0##*/}: expected a run directory and an optional FPS, got $# arguments" >&2
  echo "$usage" >&2
  exit 2
fi
dir=$1
fps=${2:-25}
# a frame rate ffmpeg cannot parse reached it, and only its own message said so
if ! printf '%s\n' "$fps" | grep -Eq '^([0-9]+\.?[0-9]*|\.[0-9]+)$' || ! awk -v f="$fps" 'BEGIN { exit !(f > 0) }'; then
  echo "${0##*/}: FPS: expected a number above 0, got '$fps'" >&2
  echo "$usage" >&2
  exit 2
fi
# a directory named "-x" must not read as an option of ls or cd
case $dir in -*) dir=./$dir ;; esac
if [ ! -d "$dir" ]; then
  echo "${0##*/}: $dir: no such directory (expected a run directory)" >&2
  exit 2
fi
# (another user's run this one may not read: "has no frames" pointed the
# wrong way)
if { [ -d "$dir/frames" ] && { [ ! -r "$dir/frames" ] || [ ! -x "$dir/frames" ]; }; } || [ ! -x "$dir" ]; then
  echo "${0##*/}: $dir/frames: cannot read: Permission denied" >&2
  exit 2
fi
if [ ! -d "$dir/frames" ] || [ -z "$(ls -- "$dir/frames" 2>/dev/null | grep '^frame-[0-9]*\.png$')" ]; then
  echo "${0##*/}: $dir/frames has no frames (set output.frames_every in the scene)" >&2
  exit 2
fi
command -v ffmpeg >/dev/null 2>&1 || { echo "${0##*/}: ffmpeg not found (make deps-animation)" >&2; exit 2; }
# The frames are numbered by sweep, not consecutively.  ffmpeg's glob would
# read RUN_DIR itself as a pattern ("run[1]" took run1's frames), so they
# are linked as 1, 2, 3, ... in a directory of our own, in sweep order.
abs=$(CDPATH= cd -P -- "$dir" >/dev/null && pwd -P) # CDPATH would make cd print the directory
# beside the video: its rename is whole; a run this user may only read is
# said so (mktemp's own words, exit 1, before)
if ! tmp=$(mktemp -d "$abs/.animate.XXXXXX" 2>&1); then
  why=${tmp##*: }
  case $why in
  'No space left on device' | 'Disk quota exceeded' | 'Input/output error')
    echo "${0##*/}: $dir: cannot write animation.mp4 there: $why" >&2
    exit 1 ;;
  esac
  echo "${0##*/}: $dir: cannot write animation.mp4 there: $why (copy the run's frames to a folder of your own)" >&2
  exit 2
fi
# dash runs no EXIT trap when a signal ends it: the signals exit through it
trap 'rm -rf "$tmp"' EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM
n=0
for f in $(ls -- "$abs/frames" | grep '^frame-[0-9]*\.png$' | sort -t- -k2n); do
  n=$((n + 1))
  # (a FIFO held ffmpeg, and this script, for ever)
  if [ ! -f "$abs/frames/$f" ]; then
    echo "${0##*/}: $dir/frames/$f: not a regular file" >&2
    exit 2
  fi
  # (ffmpeg said only "Could find no file" of frames it may not read)
  if [ ! -r "$abs/frames/$f" ]; then
    echo "${0##*/}: $dir/frames/$f: cannot read: Permission denied" >&2
    exit 2
  fi
  ln -s "$abs/frames/$f" "$tmp/$(printf %08d "$n").png"
done
# written beside the links and moved into place whole: a signal left a
# 48-byte animation.mp4 that no player opens
# (-nostdin: ffmpeg reads its input for keys, and ate the rest of a
# `while read` loop's list of runs)
(cd "$tmp" && ffmpeg -nostdin -loglevel error -y -framerate "$fps" -i %08d.png \
  -vf "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white" -c:v libx264 -pix_fmt yuv420p animation.mp4 </dev/null)
mv -f "$tmp/animation.mp4" "$abs/animation.mp4"
echo "$dir/animation.mp4"
