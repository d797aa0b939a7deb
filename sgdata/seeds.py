"""Seed derivation: every random draw flows from the dataset seed through named child seeds."""

from __future__ import annotations

import numpy as np

__all__ = ["derive_seed", "rng_for"]


def derive_seed(parent: int, *keys: int) -> int:
    """A 63-bit child seed of ``parent`` for the path ``keys`` (room index, layout, view ...).

    Uses numpy's SeedSequence spawn keys, so children are independent streams and the same
    path always gives the same seed, whatever order they are asked for in.
    """
    sequence = np.random.SeedSequence(entropy=parent, spawn_key=tuple(int(k) for k in keys))
    return int(sequence.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))


def rng_for(seed: int) -> np.random.Generator:
    """The generator all draws of one unit of work (a room, a layout, a view) come from."""
    return np.random.default_rng(seed)
