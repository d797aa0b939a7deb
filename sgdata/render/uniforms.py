"""pyrender's uniform setter with each location looked up once per shader program.

pyrender's ``ShaderProgram.set_uniform`` asks GL for the uniform's location on every call;
the RGB pass sets ~19 uniforms per primitive (camera, material, each light), ~285 a view, and
through PyOpenGL the lookups alone cost ~2 ms of a ~18 ms view on llvmpipe. A location does
not change while its program lives, so :func:`cache_uniform_locations` makes one renderer's
programs remember them; the values set, their types and the GL calls that set them are
pyrender's (the pixels are the same bytes, tests/sgdata/render/test_target.py).
"""

from __future__ import annotations

from typing import Any

__all__ = ["cache_uniform_locations"]


def cache_uniform_locations(renderer: Any) -> None:
    """Every shader program of pyrender ``renderer`` (its ``_program_cache``) remembers the
    locations of its uniforms."""
    cache = renderer._program_cache
    get_program = cache.get_program

    def get_remembering(*args: Any, **kwargs: Any) -> Any:
        program = get_program(*args, **kwargs)
        if "set_uniform" not in vars(program):
            program.set_uniform = _remembering_setter(program)
        return program

    cache.get_program = get_remembering


def _remembering_setter(program: Any) -> Any:
    """``program.set_uniform`` with the location lookup cached: pyrender's own setter, run
    with ``glGetUniformLocation`` answering from a dict for this program's id."""
    import pyrender.shader_program as module

    set_uniform = type(program).set_uniform
    locations: dict[str, int] = {}
    lookup = module.glGetUniformLocation

    def location(program_id: int, name: str) -> int:
        if program_id != program._program_id:  # not this program: ask GL
            return lookup(program_id, name)
        if name not in locations:
            locations[name] = lookup(program_id, name)
        return locations[name]

    def remembering(name: str, value: Any, unsigned: bool = False) -> None:
        module.glGetUniformLocation = location
        try:
            set_uniform(program, name, value, unsigned)
        finally:
            module.glGetUniformLocation = lookup

    return remembering
