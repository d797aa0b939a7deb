"""A user's class file (``--classes MAP.toml``): classes the catalog lacks, with their dynamics.

One ``Name = "static" | "low" | "high"`` pair a line, at the top level or under ``[classes]``
(``Name = { dynamics = "high" }`` works too)::

    [classes]
    Teapot = "high"
    Radiator = "static"
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from sgdata.errors import ConfigError
from sgdata.world.scene import Dynamics

__all__ = ["load_user_classes"]


def load_user_classes(path: Path | None) -> dict[str, Dynamics]:
    """Class name -> dynamics from a class file; empty for ``None``.

    Raises:
        ConfigError: the file is missing or not TOML, or a class's dynamics is not one of
            static, low, high (the message names the file and the class).
    """
    if path is None:
        return {}
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: class file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read the class file ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from None
    table = raw.get("classes", raw) if isinstance(raw.get("classes"), dict) else raw
    found = {}
    for name, value in table.items():
        dynamics = value.get("dynamics") if isinstance(value, dict) else value
        try:
            found[str(name)] = Dynamics(str(dynamics))
        except ValueError:
            raise ConfigError(
                f'{path}: class {name!r} dynamics is {dynamics!r}; expected "static", "low" or '
                f'"high"'
            ) from None
    return found
