#!/usr/bin/env bash
# Regenerates the binary and generated seeds of fuzz/corpus (map file, vocabulary, run.json,
# settings) with the built `detslam` command; the hand-written text seeds stay as they are.
# Usage: fuzz/make_corpus.sh [path/to/detslam [path/to/make_bag_seeds]]
# (make_bag_seeds is built with the fuzz targets: scripts/fuzz.sh, build-asan/fuzz/.)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bin="${1:-$(dirname "$here")/build/bin/detslam}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$bin" synth --preset static --seed 1 --frames 3 --out "$work/seq" >/dev/null
# Few features, so that the seeds stay small (the fuzzer mutates every byte): 800 is about the
# fewest with which the first frame still initialises a map (one keyframe); with 100 nothing
# initialises and the map file holds an empty atlas.
for n in 800 100; do
  sed -e "s/^ORBextractor.nFeatures:.*/ORBextractor.nFeatures: $n/" "$work/seq/settings.yaml" \
    >"$work/small$n.yaml"
  grep -q "ORBextractor.nFeatures: $n" "$work/small$n.yaml"
done
"$bin" vocab train --images "$work/seq/rgb.txt" --out "$work/v.dslvoc" --k 3 --levels 2 \
  --features 100 >/dev/null
"$bin" run --dataset "$work/seq" --config "$work/small800.yaml" --out "$work/run" --segmenter none \
  --no-progress --vocabulary "$work/v.dslvoc" --save-map "$work/m.dslmap" --max-frames 1 >/dev/null
"$bin" run --dataset "$work/seq" --config "$work/small100.yaml" --out "$work/run0" \
  --segmenter none --no-progress --vocabulary "$work/v.dslvoc" --save-map "$work/empty.dslmap" \
  >/dev/null
rm -f "$here"/corpus/map_file/*.bin
{ printf '\x00'; cat "$work/empty.dslmap"; } >"$here/corpus/map_file/empty_atlas.bin"
cp "$work/v.dslvoc" "$here/corpus/vocabulary/tiny.dslvoc"
# The map and vocabulary targets read a mode byte first (bit 0: recompute the checksum).
{ printf '\x00'; cat "$work/m.dslmap"; } >"$here/corpus/map_file/one_keyframe.bin"
{ printf '\x00'; cat "$work/v.dslvoc"; } >"$here/corpus/vocabulary/tiny.bin"
rm -f "$here/corpus/vocabulary/tiny.dslvoc"
cp "$work/run0/run.json" "$here/corpus/run_log/three_frames.json"
{ cat "$work/small800.yaml"; printf '\n===\nDynamic.Alpha=0.2\nTracking.KeyFrameFarPoints=40\n'; } \
  >"$here/corpus/settings/synth_v1.yaml"
seeds="${2:-$(dirname "$here")/build-asan/fuzz/make_bag_seeds}"
if [ -x "$seeds" ]; then
  rm -f "$here"/corpus/rosbag/*.bag
  "$seeds" "$here/corpus/rosbag"
else
  echo "note: $seeds is not built; corpus/rosbag left as it is"
fi
ls -l "$here"/corpus/*/
