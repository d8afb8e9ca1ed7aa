#!/usr/bin/env bash
# The README's animation (docs/images/memo_worlds.gif): three of the memo's worlds side by side,
# blindfold tag twice (the room, and the view "it" that follows whoever is it),
# recorded, drawn with `turtlegas render --frames` and joined into a GIF by ffmpeg
# (docs/recording.md, "The README's animation"). Usage: bash scripts/readme_animation.sh [BUILD_DIR]
set -euo pipefail
bin="${1:-build/release}/turtlegas"
out="docs/images/memo_worlds.gif"
command -v ffmpeg >/dev/null || { echo "readme_animation: needs ffmpeg (apt-get install ffmpeg)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# 120 or 121 frames each: tag and the pen over 20 s at 6 frames/s, the mirror pair over 30 s at 4.
# Tag starts at 0.1 s: the view "it" opens when the programs first run, at the boundary t = 0.
"$bin" run worlds/tag_follow_it.json --until 20 --record "$work/tag.tgrec"
"$bin" run worlds/mirror.json --until 30 --record "$work/mirror.tgrec"
"$bin" run worlds/pen_walls.json --until 20 --record "$work/pen.tgrec"
"$bin" render "$work/tag.tgrec" --frames "$work/tag" --fps 6 --width 300 --from 0.1
"$bin" render "$work/tag.tgrec" --frames "$work/it" --fps 6 --width 300 --from 0.1 --view it
"$bin" render "$work/mirror.tgrec" --frames "$work/mirror" --fps 4 --width 300
"$bin" render "$work/pen.tgrec" --frames "$work/pen" --fps 6 --width 300
ffmpeg -loglevel error -y -framerate 6 -i "$work/tag/frame-%05d.png" -framerate 6 -i "$work/it/frame-%05d.png" \
  -framerate 6 -i "$work/mirror/frame-%05d.png" -framerate 6 -i "$work/pen/frame-%05d.png" -filter_complex \
  "[0]pad=414:354:0:0:white[a];[1]pad=414:354:0:0:white[b];[2]pad=414:354:0:0:white[c];[3]pad=414:354:0:0:white[d];[a][b][c][d]hstack=4,scale=iw*0.66:-1:flags=lanczos,split[x][y];[x]palettegen=max_colors=64:stats_mode=diff[p];[y][p]paletteuse=dither=none:diff_mode=rectangle" \
  "$out"
echo "readme_animation: wrote $out ($(stat -c %s "$out") bytes)"
