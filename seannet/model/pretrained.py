"""Loading ``--pretrained PATH``: a local torchvision state_dict file, checked by SHA-256.

Nothing here downloads. The file is accepted when its SHA-256 equals (or, for a short hex
prefix of at least 8 digits, starts with) the digest the user gave, or — when none is given —
when it starts with the digest prefix torchvision publishes in the file name of its ImageNet
weights for that architecture (the same check ``torch.hub`` makes with ``check_hash=True``).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

import torch
from torch import Tensor, nn

from seannet.errors import ModelError
from seannet.weights import NETWORKS
from sgdata.fileio import sha256_file

__all__ = [
    "check_pretrained_request",
    "load_state_dict_file",
    "load_pretrained",
]

_HEX = re.compile(r"[0-9a-f]{8,64}")


def check_pretrained_request(path: Path | None, sha256: str | None) -> None:
    """Refuse an expected SHA-256 that cannot be used, before any work starts.

    Raises:
        ModelError: ``sha256`` is given without a weights file, or is not 64 hex digits.
    """
    if sha256 is None:
        return
    if path is None:
        raise ModelError(
            f"--pretrained-sha256 {sha256}: given without --pretrained PATH; "
            "pass the weights file it checks, or drop it"
        )
    if not _HEX.fullmatch(sha256.strip().lower()):
        raise ModelError(
            f"--pretrained-sha256 {sha256!r}: expected 8 to 64 hex digits of the file's "
            f"sha256 (`sha256sum {path}`)"
        )


def _check_hash(path: Path, actual: str, arch: str, sha256: str | None) -> None:
    if sha256 is not None:
        expected = sha256.strip().lower()
        if not _HEX.fullmatch(expected):
            raise ModelError(
                f"pretrained sha256 {sha256!r} is not 8 to 64 hex digits; give the file's "
                f"sha256 (`sha256sum {path}`)"
            )
        if not actual.startswith(expected):
            raise ModelError(
                f"pretrained weights {path}: sha256 mismatch: expected {expected}, actual "
                f"{actual}; the file is corrupt or not the one meant"
            )
        return
    record = NETWORKS.get(arch)
    if record is not None and record.known_digest(actual):
        return
    names = ", ".join(record.files) if record else "none"
    raise ModelError(
        f"pretrained weights {path}: sha256 {actual} matches no known {arch} weights "
        f"(known: {names}); pass its sha256 explicitly if you trust the file"
    )


def load_state_dict_file(path: Path, *, arch: str, sha256: str | None = None) -> dict[str, Tensor]:
    """Read a torchvision-format state_dict after checking its SHA-256.

    Args:
        path: a local ``.pth`` file holding a ``{name: tensor}`` mapping.
        arch: a network of :data:`seannet.weights.NETWORKS`, used when ``sha256`` is ``None``.
        sha256: the expected digest (64 hex digits, or a prefix of at least 8).

    Raises:
        ModelError: missing file, hash mismatch or unknown hash, or not a state_dict.
    """
    path = Path(path)
    if not path.is_file():
        raise ModelError(f"pretrained weights {path}: no such file")
    _check_hash(path, sha256_file(path)[0], arch, sha256)
    try:
        # weights_only: never unpickle arbitrary objects from a weights file
        obj = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - any load failure means "not a state_dict"
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ModelError(
            f"pretrained weights {path}: not a torch state_dict file ({first[:200]})"
        ) from None
    if (
        not isinstance(obj, Mapping)
        or not obj
        or not all(isinstance(k, str) and isinstance(v, Tensor) for k, v in obj.items())
    ):
        raise ModelError(
            f"pretrained weights {path}: holds a {type(obj).__name__}, not a state_dict "
            f"(a non-empty mapping of parameter names to tensors)"
        )
    return dict(obj)


def load_pretrained(
    model: nn.Module, path: Path, *, arch: str, sha256: str | None = None
) -> nn.Module:
    """Load a checked torchvision state_dict into ``model`` (strictly) and return it.

    Raises:
        ModelError: as :func:`load_state_dict_file`, or keys / shapes that do not fit.
    """
    state = load_state_dict_file(path, arch=arch, sha256=sha256)
    own = model.state_dict()
    missing = sorted(set(own) - set(state))
    unexpected = sorted(set(state) - set(own))
    wrong = sorted(k for k in set(own) & set(state) if own[k].shape != state[k].shape)
    if missing or unexpected or wrong:
        parts = []
        for label, keys in (("missing", missing), ("unexpected", unexpected), ("shape", wrong)):
            if keys:
                parts.append(f"{len(keys)} {label} (e.g. {keys[0]})")
        raise ModelError(
            f"pretrained weights {path} do not fit {arch}: {', '.join(parts)}; "
            f"give the torchvision {arch} weights"
        )
    model.load_state_dict(state, strict=True)
    return model
