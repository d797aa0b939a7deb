"""The built wheel holds every package and data file of the source tree (a wheel once lacked
``seannet/layers/``, so ``import seannet`` failed for anyone who installed it)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# source folder -> the package name it installs as (pyproject.toml's package-dir)
INSTALLED_AS = {
    "sgdata": "sgdata",
    "seannet": "seannet",
    "cli": "sgdata_cli",
    "assets": "sgdata_assets",
    "configs": "sgdata_configs",
    "schemas": "sgdata_schemas",
}
DATA = ("*.toml", "*.json")


def _expected() -> set[str]:
    files = set()
    for folder, name in INSTALLED_AS.items():
        base = ROOT / folder
        for pattern in ("*.py", *DATA):
            for path in base.rglob(pattern):
                if "__pycache__" not in path.parts:
                    files.add(f"{name}/{path.relative_to(base).as_posix()}")
    return files


def test_wheel_holds_every_module_and_data_file(tmp_path: Path) -> None:
    # build from a clean copy: a stale build/ of the checkout would leak deleted modules in
    source = tmp_path / "src"
    skip = shutil.ignore_patterns(
        ".git", ".venv", "build", "dist", "*.egg-info", "out", "__pycache__"
    )
    shutil.copytree(ROOT, source, ignore=skip)
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "--no-build-isolation",
            "-q",
            "-w",
            str(tmp_path),
            str(source),
        ],
        check=True,
        capture_output=True,
    )
    (wheel,) = tmp_path.glob("sgdata-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    assert _expected() - names == set()
    assert not any(n.split("/")[0] in ("cli", "tests", "bench") for n in names)
    version = wheel.name.split("-")[1]
    from sgdata import __version__

    assert version == __version__
