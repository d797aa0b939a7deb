"""What a photo's labels still lack before export, and the relations proposed for its boxes."""

from __future__ import annotations

from sgdata.label.classes import ClassNames
from sgdata.label.models import PhotoLabels
from sgdata.label.proposals import Proposal, ProposalRules, propose_relations

__all__ = ["accepted_only", "proposals_for", "undecided", "problems", "room_instances"]


def proposals_for(labels: PhotoLabels, classes: ClassNames, rules: ProposalRules) -> list[Proposal]:
    """The proposals for the boxes of ``labels``, knowing which boxes are containers."""
    boxes = {o.id: o.box for o in labels.objects}
    containers = {
        o.id for o in labels.objects if classes.resolve(o.class_name) in classes.containers
    }
    return propose_relations(boxes, rules, containers=containers)


def undecided(labels: PhotoLabels, proposals: list[Proposal]) -> list[Proposal]:
    """The proposals whose pair the labeler has not decided (export stores them as disjoint)."""
    decided = {frozenset((r.src, r.dst)) for r in labels.relations}
    return [p for p in proposals if frozenset((p.src, p.dst)) not in decided]


def accepted_only(labels: PhotoLabels) -> PhotoLabels:
    """``labels`` without the detector's boxes no one accepted, and their relations: what an
    export writes (a guess is not a label)."""
    guessed = {o.id for o in labels.objects if o.proposed is not None}
    if not guessed:
        return labels
    return labels.model_copy(
        update={
            "objects": [o for o in labels.objects if o.id not in guessed],
            "relations": [
                r for r in labels.relations if r.src not in guessed and r.dst not in guessed
            ],
        }
    )


def room_instances(
    saved: dict[str, PhotoLabels], room_id: str | None, photo: str
) -> dict[int, tuple[str, str]]:
    """Box ids used in the other photos of ``room_id``: id -> (class name, first photo).

    A box id is one object of the room (carry over keeps ids), so a new box takes an id no
    photo of the room uses, and an id keeps one class across the room's photos.
    """
    out: dict[int, tuple[str, str]] = {}
    if room_id is None:
        return out
    for name, other in sorted(saved.items()):
        if name != photo and other.room_id == room_id:
            for o in other.objects:
                out.setdefault(o.id, (o.class_name, name))
    return out


def problems(
    labels: PhotoLabels,
    classes: ClassNames,
    rules: ProposalRules,
    room: dict[int, tuple[str, str]] | None = None,
) -> list[str]:
    """Why the photo is not ready to export, one short line each; empty when it is ready.

    ``room``: :func:`room_instances` of the photo, to check one class per box id in a room.
    """
    out = []
    room = room or {}
    if labels.room_id is None:
        out.append("no room id")
    if labels.room_type is None:
        out.append("no room type")
    for o in labels.objects:
        if not o.class_name:
            out.append(f"box {o.id} has no class")
        elif classes.resolve(o.class_name) is None:
            out.append(f"box {o.id}: {classes.unknown(o.class_name)}")
        elif o.id in room and classes.resolve(room[o.id][0]) not in (
            None,
            classes.resolve(o.class_name),
        ):
            other, where = room[o.id]
            out.append(
                f"box {o.id} is {o.class_name} here but {other} in {where} (same room); "
                "one id is one object: delete and redraw it, or fix the class"
            )
    guessed = sum(o.proposed is not None for o in labels.objects)
    if guessed:
        out.append(f"{guessed} proposed box(es) to accept (Enter) or delete")
    pending = len(undecided(labels, proposals_for(labels, classes, rules)))
    if pending:
        out.append(f"{pending} undecided proposal(s)")
    return out
