"""Write the demo mesh files and their user catalog (``configs/assets.toml`` reads them).

    python scripts/make_demo_assets.py [FOLDER]      # default: configs/demo_assets

Four kitchen classes made of files trimesh writes here, one per format and each in other units
and up axis: a glTF table (metres, Y up), an OBJ + MTL + PNG mug (cm, Y up), a PLY bowl (mm,
Z up) and an STL plate (metres, Z up). They are made by this script (no third-party meshes, so
no licence to check); the same call writes the same bytes.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.asset_meshes import write_demo_assets  # noqa: E402


def main() -> int:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "configs" / "demo_assets"
    for path in write_demo_assets(folder):
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
