"""Seed derivation: every random draw flows from the dataset seed through named child seeds.

This module is the one home of every derivation path, so two stages can never draw from the
same stream by accident and a path never changes without this file changing::

    dataset seed ─┬─ room_seed(type index, room index) ─┬─ layouts_seed(request) ─ layout_seed(k)
                  │                                     ├─ view_seed(layout, i, j, heading)
                  │                                     └─ room_look_seed()  (base looks)
                  ├─ user_room_seed(room id)  (a user's room of [rooms] files; then as above)
                  └─ split_triplets_seed(split) ─ triplet_stream_seed(split, room, tier)
    layout seed ─ appearance_seed()  (the layout's light and looks of its moving objects)
    texture_seed(kind, variant)  (procedural texture images: no dataset seed, shared by all)

The trainer's seeds (training, navigator, navigation test, box noise) live in
:mod:`seannet.seeds`, derived with :func:`derive_seed` and :func:`name_key` from here.
"""

from __future__ import annotations

import hashlib

import numpy as np

__all__ = [
    "derive_seed",
    "rng_for",
    "name_key",
    "room_seed",
    "user_room_seed",
    "layouts_seed",
    "layout_seed",
    "view_seed",
    "split_triplets_seed",
    "triplet_stream_seed",
    "room_look_seed",
    "appearance_seed",
    "texture_seed",
]

_TRIPLETS = "triplets"  # the purpose key of triplet streams
_LOOKS = "looks"  # the purpose key of a room's base looks (texture variants)
_APPEARANCE = "appearance"  # the purpose key of a layout's appearance draw
_TEXTURES = "textures"  # the root key of procedural texture images
# the purpose key of the rooms users bring ([rooms] files); the string predates the "user"
# naming and stays: changing it would move every user room's draws
_USER_ROOMS = "own rooms"


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


def name_key(name: str) -> int:
    """A stable 63-bit key of a string (Python's ``hash()`` is salted per run)."""
    digest = hashlib.blake2b(name.encode("utf-8"), digest_size=8).digest()
    return int.from_bytes(digest, "big") >> 1


def room_seed(dataset_seed: int, type_index: int, index: int) -> int:
    """A room's seed: its type's position in the room-type list and its number in the type."""
    return derive_seed(dataset_seed, type_index, index)


def user_room_seed(dataset_seed: int, room_id: str) -> int:
    """A user room's seed (its layouts and views derive from it), by its room id: adding or
    reordering ``[rooms] files`` entries moves no other room's draws."""
    return derive_seed(dataset_seed, name_key(_USER_ROOMS), name_key(room_id))


def layouts_seed(room: int, request: int) -> int:
    """The seed of one request for layouts of a room (``sgdata layouts --seed``)."""
    return derive_seed(room, request)


def layout_seed(layouts: int, index: int) -> int:
    """Layout ``index``'s own seed, from the seed of its request."""
    return derive_seed(layouts, index)


def view_seed(room: int, layout: int, i: int, j: int, heading: int) -> int:
    """One view's seed (pose noise, light jitter), from its room's seed and its pose key."""
    return derive_seed(room, layout, i, j, heading)


def split_triplets_seed(dataset_seed: int, split_index: int) -> int:
    """The seed of a split's triplets (``split_index`` counts train = 0, val = 1, test = 2)."""
    return derive_seed(dataset_seed, 1 + split_index)


def triplet_stream_seed(split_seed: int, split: str, room_id: str, tier: int) -> int:
    """The stream of one room's triplets of one tier (by names, so adding a room moves none)."""
    return derive_seed(split_seed, name_key(_TRIPLETS), name_key(split), name_key(room_id), tier)


def room_look_seed(room: int) -> int:
    """A room's base looks: the texture variant of its structure and of every object."""
    return derive_seed(room, name_key(_LOOKS))


def appearance_seed(layout: int) -> int:
    """A layout's appearance (light intensity and colour temperature, looks of its low- and
    high-dynamic objects), from the layout's own seed."""
    return derive_seed(layout, name_key(_APPEARANCE))


def texture_seed(kind: str, variant: int) -> int:
    """One procedural texture image, by its kind and variant only: every room and dataset
    shares the same images."""
    return derive_seed(name_key(_TEXTURES), name_key(kind), variant)
