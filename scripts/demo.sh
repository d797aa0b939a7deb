#!/usr/bin/env bash
# The main job on the small embedded default: the `tiny` preset (kitchens and bathrooms, one
# room per split each) generated into out/demo, then a look at one room and one view.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
sgdata=.venv/bin/sgdata
$sgdata generate tiny "$out" --force
$sgdata validate "$out"
room="$out/scenes/kitchen_000"
$sgdata preview "$room/layout_1.usda" --compare -o "$out/previews/kitchen_000_layout_1.png"
$sgdata render "$room" --layout 1 -o "$out/previews/kitchen_000_view.png"
echo "demo: dataset in $out (dataset.json, observations/, triplets/, scenes/), pictures in $out/previews"
