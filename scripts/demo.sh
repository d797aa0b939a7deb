#!/usr/bin/env bash
# The main job on the small embedded default: one room of each type as USD, five layouts of
# each as USD layers, and top-down previews.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
sgdata=.venv/bin/sgdata
for type in kitchen living_room bedroom bathroom; do
  room="$out/scenes/${type}_000"
  $sgdata rooms "$out/scenes" --type "$type" --count 1 --seed 0
  $sgdata layouts "$room" --count 5 --seed 0
  $sgdata preview "$room/room.usda" -o "$out/previews/${type}_000.png"
  $sgdata preview "$room/layout_1.usda" --compare -o "$out/previews/${type}_000_layout_1.png"
done
echo "demo: USD rooms and layouts in $out/scenes, top-down previews in $out/previews"
