"""User catalogs of ``[catalog] files``: read, checked and hashed before a run writes anything.

:func:`resolve_user_assets` runs in the main process before the output directory is touched:
the user's catalog files are merged with the shipped one and every mesh file their classes
name is read, checked and measured (:mod:`sgdata.world.mesh_assets`), so a bad asset stops the
run in one line with nothing of the dataset written. It records in ``[catalog] assets`` each
file read (the catalog files, meshes and textures) with its SHA-256, so the ledger and the
manifest name exactly the bytes the dataset was made from and ``validate --sources`` can name
one changed since.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from sgdata.errors import ConfigError
from sgdata.fileio import sha256_file
from sgdata.pipeline.config import AssetFile, GenerateConfig

__all__ = ["resolve_user_assets"]


def resolve_user_assets(config: GenerateConfig) -> GenerateConfig:
    """``config`` with its user catalog loaded and every file it reads hashed.

    Raises:
        ConfigError: a catalog file is missing, or a pinned sha256 differs.
        CatalogError: a catalog is malformed or a mesh file is bad (naming the file).
    """
    section = config.catalog
    if not section.files:
        return config
    base = Path(section.base_dir or ".").resolve()
    section = dataclasses.replace(section, base_dir=str(base))
    for k, path in enumerate(section.paths()):
        if not path.is_file():
            raise ConfigError(
                f"catalog.files[{k}] {section.files[k]!r}: no such file {path} (paths are "
                "relative to the config file's folder)"
            )
    from sgdata.world.mesh_assets import asset_files  # late: reads the mesh files

    catalog = section.load()
    pinned = {a.path: a.sha256 for a in section.assets if a.sha256}
    read = [(str(p.resolve()), sha256_file(p)[0]) for p in section.paths()]
    read += asset_files(catalog)
    assets = []
    for path, digest in read:
        rel = _relative(Path(path), base)
        if rel in pinned and pinned[rel] != digest:
            raise ConfigError(
                f"catalog.assets {rel!r}: the file's sha256 is {digest}, not the "
                f"{pinned[rel]} the config pins"
            )
        assets.append(AssetFile(rel, digest))
    return dataclasses.replace(config, catalog=dataclasses.replace(section, assets=tuple(assets)))


def _relative(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` (POSIX), or absolute when on another drive."""
    try:
        return Path(os.path.relpath(path, base)).as_posix()
    except ValueError:
        return path.as_posix()
