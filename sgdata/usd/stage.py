"""Opening and writing USD layers and stages, and checking them with USD's own validators.

Every stage of the project (generated rooms, layouts, user rooms and their tag layers) is read
through :func:`open_stage` (one-line errors, sublayers checked) and written through
:func:`write_usd_file` (atomically); :func:`validate_stage` runs every validator registered in
``pxr.UsdValidation`` (usd-core no longer ships ``usdchecker``; this is its engine).
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from pxr import Sdf, Tf, Usd, UsdValidation

from sgdata.errors import UsdError, one_line
from sgdata.fileio import atomic_write_text

__all__ = [
    "open_layer",
    "open_stage",
    "write_usd_file",
    "validate_stage",
    "check_stage",
    "usd_reason",
]


def write_usd_file(path: Path, text: str) -> None:
    """Write a layer's ``text`` to ``path`` atomically (:func:`sgdata.fileio.atomic_file`) and
    reload the copy of that layer this process holds, if any.

    Raises:
        UsdError: the folder cannot be created or the file cannot be written.
    """
    path = Path(path)
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise UsdError(f"{path}: cannot write USD file ({exc.strerror or exc})") from None
    layer = Sdf.Layer.Find(str(path))
    if layer is not None:  # a layer still open in this process would otherwise be stale
        layer.Reload(force=True)


def open_layer(path: Path, what: str | None = None) -> Sdf.Layer:
    """Open one layer (no composition) from disk, reloading a stale copy this process holds.

    Raises:
        UsdError: the file is missing or is not a readable USD layer.
    """
    what = what or str(path)
    if not Path(path).is_file():
        raise UsdError(f"{what}: USD file not found")
    try:
        layer = Sdf.Layer.Find(str(path))
        if layer is not None:
            layer.Reload()
        else:
            layer = Sdf.Layer.FindOrOpen(str(path))
    except Tf.ErrorException as exc:
        raise UsdError(f"{what}: unreadable USD layer ({usd_reason(exc)})") from None
    if layer is None:
        raise UsdError(f"{what}: unreadable USD layer")
    return layer


def _check_sublayers(layer: Sdf.Layer, where: Path, seen: set[str]) -> None:
    for sub in layer.subLayerPaths:
        resolved = Path(Sdf.ComputeAssetPathRelativeToLayer(layer, sub))
        if str(resolved) in seen:
            continue
        seen.add(str(resolved))
        if not resolved.is_file():
            raise UsdError(f"{where}: sublayer {sub!r} not found (looked for {resolved})")
        _check_sublayers(open_layer(resolved, f"{where}: sublayer {sub!r}"), where, seen)


def open_stage(path: Path, *, strict: bool = True) -> Usd.Stage:
    """Open a USD file as a composed stage, always from the file's current content on disk.

    Args:
        path: a ``room.usda``, a ``layout_<k>.usda`` or any USD file.
        strict: also fail on a missing sublayer or any other composition error.

    Raises:
        UsdError: the file is missing or unreadable, or (strict) composition fails.
    """
    path = Path(path)
    layer = open_layer(path)
    if strict:
        _check_sublayers(layer, path, {str(path.resolve())})
    try:
        stage = Usd.Stage.Open(layer)
    except Tf.ErrorException as exc:
        raise UsdError(f"{path}: cannot compose stage ({usd_reason(exc)})") from None
    errors = stage.GetCompositionErrors() if strict else []
    if errors:
        kinds = sorted({type(e).__name__.removeprefix("Error") for e in errors})
        raise UsdError(f"{path}: {len(errors)} composition error(s): {', '.join(kinds)}")
    return stage


@cache
def _validators() -> tuple[UsdValidation.Validator, ...]:
    registry = UsdValidation.ValidationRegistry()
    names = [m.name for m in registry.GetAllValidatorMetadata() if not m.isSuite]
    return tuple(registry.GetOrLoadValidatorsByName(sorted(names)))


def validate_stage(path: Path) -> list[str]:
    """Run every validator registered with ``pxr.UsdValidation`` on the composed stage.

    Returns:
        one line per problem found (errors, warnings and notes alike); empty when clean.

    Raises:
        UsdError: the file is missing or unreadable (composition errors are reported, not raised).
    """
    stage = open_stage(path, strict=False)
    context = UsdValidation.ValidationContext(list(_validators()))
    errors = context.Validate(stage)
    return [one_line(e.GetErrorAsString()) for e in errors if not e.HasNoError()]


def check_stage(path: Path) -> None:
    """Validate ``path`` like :func:`validate_stage` and raise when anything is reported.

    Raises:
        UsdError: naming the file, the number of problems and the first of them.
    """
    problems = validate_stage(path)
    if problems:
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise UsdError(f"{path}: fails USD validation: {problems[0]}{more}")


def usd_reason(exc: Tf.ErrorException) -> str:
    """The message of a pxr error on one line, without its C++ location."""
    try:
        text = one_line(exc)
    except UnicodeDecodeError:  # pxr quotes the bad bytes of a corrupted file
        return "its text is not valid UTF-8 where USD stopped reading"
    return (text.split(" : ", 1)[-1] if " : " in text else text).strip("' ")
