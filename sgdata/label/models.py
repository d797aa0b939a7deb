"""The labels of one photo as the page sends and the store keeps them (pydantic, no extras)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_serializer, model_validator

from sgdata.world.room_recipes import ROOM_TYPES

__all__ = ["Pose", "LabeledObject", "Decision", "PhotoLabels", "ROOM_ID_PATTERN"]

# A room id becomes a file name (observations/<split>/<room_id>.parquet): no '/', '\' or '..'.
ROOM_ID_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_-]*(?:\.[A-Za-z0-9_-]+)*$"
_STRICT = ConfigDict(extra="forbid", strict=True)

RoomType = Literal[ROOM_TYPES]  # type: ignore[valid-type]  # kitchen | living_room | ...


class Pose(BaseModel):
    """Where the photo was taken on the room's pose grid (DESIGN §6)."""

    model_config = _STRICT
    layout: Annotated[int, Field(ge=0, le=32767)] = 0  # arrangement of the room's objects
    i: Annotated[int, Field(ge=-32768, le=32767)]  # grid cell along x
    j: Annotated[int, Field(ge=-32768, le=32767)]  # grid cell along y
    heading: Annotated[int, Field(ge=0, le=3)]  # 0/90/180/270 degrees


class LabeledObject(BaseModel):
    """One box: an id stable within the photo (and carried over between photos), a class."""

    model_config = _STRICT
    id: Annotated[int, Field(ge=0, le=2**31 - 1)]
    class_name: Annotated[str, Field(max_length=100)]  # a catalog class or a mapped name; "" unset
    # [u1, v1, u2, v2] pixels, u2 and v2 exclusive
    box: Annotated[list[int], Field(min_length=4, max_length=4)]
    # a detector's box no one has accepted yet: its score (None: drawn or accepted by a person)
    proposed: Annotated[float, Field(ge=0, le=1)] | None = None

    @model_validator(mode="after")
    def _box_order(self) -> LabeledObject:
        u1, v1, u2, v2 = self.box
        if not (0 <= u1 < u2 and 0 <= v1 < v2):
            raise ValueError(f"box {list(self.box)}: expected 0 <= u1 < u2 and 0 <= v1 < v2")
        return self

    @model_serializer(mode="wrap")
    def _proposed_only_when_so(self, handler):  # noqa: ANN001, ANN202
        # a box a person drew is written as before: label files and the API gain no null field
        data = handler(self)
        if self.proposed is None:
            data.pop("proposed", None)
        return data


class Decision(BaseModel):
    """A relation the labeler decided: accepted as a type, or ``disjoint`` (rejected)."""

    model_config = _STRICT
    src: int
    dst: int
    type: Literal["on", "in", "proximity", "disjoint"]


class PhotoLabels(BaseModel):
    """Everything labeled on one photo; ``revision`` counts the saves (for conflicts)."""

    model_config = _STRICT
    revision: Annotated[int, Field(ge=0)] = 0  # the revision the sender last saw
    room_id: Annotated[str, Field(pattern=ROOM_ID_PATTERN, max_length=64)] | None = None
    room_type: RoomType | None = None
    pose: Pose | None = None
    objects: Annotated[list[LabeledObject], Field(max_length=1000)] = []
    relations: Annotated[list[Decision], Field(max_length=20000)] = []

    @model_validator(mode="after")
    def _consistent(self) -> PhotoLabels:
        ids = [o.id for o in self.objects]
        if len(set(ids)) != len(ids):
            raise ValueError("object ids repeat")
        known = set(ids)
        pairs = set()
        for r in self.relations:
            if r.src == r.dst or r.src not in known or r.dst not in known:
                raise ValueError(f"relation {r.src}->{r.dst}: expected two distinct object ids")
            pair = (min(r.src, r.dst), max(r.src, r.dst))
            if pair in pairs:
                raise ValueError(f"pair {pair}: more than one relation decided")
            pairs.add(pair)
        return self
