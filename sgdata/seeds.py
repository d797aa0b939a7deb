"""Seed derivation: every random draw flows from the dataset seed through named child seeds.

This module is the one home of every derivation path, so two stages can never draw from the
same stream by accident and a path never changes without this file changing::

    dataset seed ─┬─ room_seed(type index, room index) ─┬─ layouts_seed(request) ─ layout_seed(k)
                  │                                     ├─ view_seed(layout, i, j, heading)
                  │                                     └─ room_look_seed()  (base looks)
                  ├─ user_room_seed(room id)  (a user's room of [rooms] files; then as above)
                  └─ split_triplets_seed(split) ─ triplet_stream_seed(split, room, tier)
    training seed ─ init_seed() / epoch_order_seed(epoch) / epoch_dropout_seed(epoch)
    navigator seed ─ navigator_init_seed() / navigator_pairs_seed(split, room)
                   ├ navigator_order_seed(epoch)
                   └ navigator_jitter_seed(epoch)
    navigation test seed ─ episode_seed(room, case, index)
    layout seed ─ appearance_seed()  (the layout's light and looks of its moving objects)
    texture_seed(kind, variant)  (procedural texture images: no dataset seed, shared by all)
"""

from __future__ import annotations

import hashlib

import numpy as np

from sgdata.deprecation import moved_names

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
    "init_seed",
    "epoch_order_seed",
    "epoch_dropout_seed",
    "navigator_init_seed",
    "navigator_pairs_seed",
    "navigator_order_seed",
    "navigator_jitter_seed",
    "episode_seed",
    "box_noise_seed",
    "room_look_seed",
    "appearance_seed",
    "texture_seed",
]

_TRIPLETS = "triplets"  # the purpose key of triplet streams
_INIT = 1 << 20  # the initial weights (epochs use 0, 1, 2, ...)
_NAVIGATOR = "navigator"  # the purpose key of the visual navigator's streams
_JITTER = "jitter"  # the navigator's light jitter, under _NAVIGATOR
_EPISODES = "episodes"  # the purpose key of the navigation test's episodes
_BOX_NOISE = "box noise"  # the purpose key of evaluation's labeler / detector noise
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


def init_seed(training_seed: int) -> int:
    """The seed of a model's initial weights."""
    return derive_seed(training_seed, _INIT)


def epoch_order_seed(training_seed: int, epoch: int) -> int:
    """The seed of an epoch's batch order."""
    return derive_seed(training_seed, epoch, 0)


def epoch_dropout_seed(training_seed: int, epoch: int) -> int:
    """The seed of an epoch's dropout masks."""
    return derive_seed(training_seed, epoch, 1)


def navigator_init_seed(training_seed: int) -> int:
    """The seed of the visual navigator's initial weights."""
    return derive_seed(training_seed, name_key(_NAVIGATOR), _INIT)


def navigator_pairs_seed(training_seed: int, split: str, room_id: str) -> int:
    """The stream of (current, goal) training pairs drawn in one room of one split."""
    return derive_seed(training_seed, name_key(_NAVIGATOR), name_key(split), name_key(room_id))


def navigator_order_seed(training_seed: int, epoch: int) -> int:
    """The seed of one navigator epoch's batch order."""
    return derive_seed(training_seed, name_key(_NAVIGATOR), epoch)


def navigator_jitter_seed(training_seed: int, epoch: int) -> int:
    """The seed of one navigator epoch's light jitter (its own stream: turning the jitter on
    moves no batch order)."""
    return derive_seed(training_seed, name_key(_NAVIGATOR), name_key(_JITTER), epoch)


def episode_seed(test_seed: int, room_id: str, case: str, index: int) -> int:
    """One navigation-test episode (its layout, start and goal), by names: every localizer
    run is tested on the same episodes."""
    return derive_seed(test_seed, name_key(_EPISODES), name_key(room_id), name_key(case), index)


def box_noise_seed(noise_seed: int, obs_id: str) -> int:
    """The noise one view's boxes get in an evaluation under box noise (by name: the same
    whatever order or batch the view is read in)."""
    return derive_seed(noise_seed, name_key(_BOX_NOISE), name_key(obs_id))


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


# old names, served with a DeprecationWarning for one release
__getattr__ = moved_names(__name__, {"own_room_seed": "sgdata.seeds:user_room_seed"})
