#!/usr/bin/env bash
# sgdata generate on a GPU machine, in under 5 minutes (16 cores, one H100/H200: ~3 min).
#
#   bash bench/gpu.sh            # from the repository root, sgdata installed in .venv
#   PY=python3 bash bench/gpu.sh # another interpreter that imports sgdata
#
# Prints, in order:
#   1. which EGL device renders (the NVIDIA driver, not llvmpipe, or the figures mean nothing);
#   2. the stage table of one worker on the GPU (bench/stages.py, 2 rooms of `paper`,
#      225 views each): where a worker's time goes once the GPU draws;
#   3. `medium` generated whole (52 rooms, ~13,000 textured views) with all cores as workers
#      and with half of them: views/s end to end and of the render phase.
# The aim (issue 25): >= 1,000 views/s textured on one GPU machine. Each worker keeps its own
# EGL context on GPU 0 (EGL_DEVICE_ID picks another); step 2 says how much of a view is CPU
# work (annotation, PNG, rows) that more workers spread and how much the GL passes take.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PY:-.venv/bin/python}
CORES=$(nproc)
export PYTHONUNBUFFERED=1

echo "== EGL device"
"$PY" - <<'EOF'
from sgdata.render.renderer import Renderer
from OpenGL.GL import GL_RENDERER, GL_VENDOR, glGetString

renderer = Renderer()
renderer._gl._platform.make_current()
print(glGetString(GL_VENDOR).decode(), "|", glGetString(GL_RENDERER).decode())
renderer.close()
EOF

echo "== one worker, stage by stage (bench/stages.py --rooms 2)"
"$PY" bench/stages.py --rooms 2

echo "== medium, whole, local pool (bench/generate.py --preset medium)"
"$PY" bench/generate.py --preset medium --workers "$CORES" $((CORES / 2))
