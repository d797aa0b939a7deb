"""``sgdata report``: histograms, a contact sheet of random triplets and ``summary.md``.

Pictures are drawn with Pillow only (horizontal bar charts with labelled values; views with
their 2D boxes and class names; a small scene graph per view: classes on a circle, edges
coloured by relation type).
"""

from __future__ import annotations

import io
import math
from collections import Counter
from pathlib import Path

import numpy as np
import pyarrow as pa
from PIL import Image, ImageDraw, ImageFont

from sgdata import markdown
from sgdata.dataset import Dataset
from sgdata.world.poses import HEADINGS_DEG

__all__ = ["write_report", "bar_chart", "channel_sheet", "contact_sheet"]

EDGE_COLOURS = {0: (214, 39, 40), 1: (31, 119, 180), 2: (44, 160, 44)}  # on, in, proximity
BAR = (70, 110, 170)
_FONT_SIZE = 13


def _font(size: int = _FONT_SIZE) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1 has no sized default font
        return ImageFont.load_default()


def bar_chart(title: str, labels: list[str], values: list[float], *, xlabel: str) -> Image.Image:
    """A horizontal bar chart: one labelled bar per value, the value written at its end."""
    font, big = _font(), _font(16)
    row, left, right, top = 20, 12 + max([len(s) for s in labels] + [4]) * 7, 90, 40
    width = left + 420 + right
    height = top + row * max(len(labels), 1) + 44
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    draw.text((10, 8), title, fill="black", font=big)
    top_value = max(values + [1])
    for k, (label, value) in enumerate(zip(labels, values, strict=True)):
        y = top + k * row
        length = int(420 * value / top_value)
        draw.rectangle([left, y + 3, left + max(length, 1), y + row - 3], fill=BAR)
        draw.text((left - 6, y + row / 2), label, fill="black", font=font, anchor="rm")
        shown = (
            f"{value:.2f}" if isinstance(value, float) and not value.is_integer() else f"{value:g}"
        )
        draw.text((left + length + 5, y + row / 2), shown, fill="black", font=font, anchor="lm")
    axis_y = top + row * len(labels) + 2
    draw.line([left, top - 2, left, axis_y], fill="black")
    draw.line([left, axis_y, left + 420, axis_y], fill="black")
    draw.text((left + 210, axis_y + 16), xlabel, fill="black", font=font, anchor="mm")
    return image


def _view_panel(row: dict, scale: int = 2) -> Image.Image:
    with Image.open(io.BytesIO(row["image"])) as decoded:
        image = decoded.convert("RGB")
    image = image.resize((image.width * scale, image.height * scale), Image.NEAREST)
    draw = ImageDraw.Draw(image)
    font = _font(11)
    for obj in row["objects"]:
        u1, v1, u2, v2 = (c * scale for c in obj["box2d"])
        draw.rectangle([u1, v1, u2 - 1, v2 - 1], outline=(255, 230, 0), width=2)
        text = obj["class_name"]
        box = draw.textbbox((u1 + 2, v1 + 1), text, font=font)
        draw.rectangle(box, fill=(0, 0, 0))
        draw.text((u1 + 2, v1 + 1), text, fill=(255, 230, 0), font=font)
    return image


def _graph_panel(row: dict, size: int) -> Image.Image:
    """Scene graph of a view: its objects on a circle, on/in/proximity edges in colour."""
    image = Image.new("RGB", (size, size), (250, 250, 250))
    draw = ImageDraw.Draw(image)
    font = _font(10)
    objects = row["objects"]
    n = len(objects)
    centre, radius = size / 2, size / 2 - 34
    where = {}
    for k, obj in enumerate(objects):
        angle = 2 * math.pi * k / max(n, 1) - math.pi / 2
        where[obj["instance"]] = (
            centre + radius * math.cos(angle),
            centre + radius * math.sin(angle),
        )
    for edge in row["relations"]:
        colour = EDGE_COLOURS.get(edge["type"])
        if colour is None or edge["src"] not in where or edge["dst"] not in where:
            continue  # disjoint edges are not drawn
        if edge["type"] == 2 and edge["src"] > edge["dst"]:
            continue  # proximity: one line per pair
        (x1, y1), (x2, y2) = where[edge["src"]], where[edge["dst"]]
        draw.line([x1, y1, x2, y2], fill=colour, width=2)
        if edge["type"] != 2:  # arrow head at the destination
            angle = math.atan2(y2 - y1, x2 - x1)
            tip = (x2 - 6 * math.cos(angle), y2 - 6 * math.sin(angle))
            for turn in (2.6, -2.6):
                draw.line(
                    [
                        tip,
                        (tip[0] + 8 * math.cos(angle + turn), tip[1] + 8 * math.sin(angle + turn)),
                    ],
                    fill=colour,
                    width=2,
                )
    for obj in objects:
        x, y = where[obj["instance"]]
        draw.ellipse([x - 5, y - 5, x + 5, y + 5], fill=(60, 60, 60))
        draw.text(
            (x, y + 13 if y >= centre else y - 13),
            obj["class_name"],
            fill="black",
            font=font,
            anchor="mm",
        )
    legend = [("on", 0), ("in", 1), ("proximity", 2)]
    for k, (name, code) in enumerate(legend):
        x = 6 + 64 * k
        draw.line([x, size - 9, x + 16, size - 9], fill=EDGE_COLOURS[code], width=3)
        draw.text((x + 20, size - 9), name, fill="black", font=font, anchor="lm")
    return image


def contact_sheet(ds: Dataset, *, triplets: int = 6, seed: int = 0) -> Image.Image:
    """Random triplets (seeded), one per line: anchor | positive | negative, each a view ×2
    with its 2D boxes and class names above its scene graph."""
    rng = np.random.default_rng(seed)
    pool = [(s, i) for s in ds.splits for i in range(ds.triplets(s).num_rows)]
    picks = [
        pool[k] for k in sorted(rng.choice(len(pool), min(triplets, len(pool)), replace=False))
    ]
    tables: dict[str, tuple[pa.Table, dict[str, int]]] = {}
    lines = []
    for split, index in picks:
        if split not in tables:
            obs = ds.observations(split)
            tables[split] = (obs, {o: k for k, o in enumerate(obs.column("obs_id").to_pylist())})
        obs, at = tables[split]
        tri = ds.triplets(split).slice(index, 1).to_pylist()[0]
        panels = []
        for role in ("anchor", "positive", "negative"):
            row = obs.slice(at[tri[role]], 1).to_pylist()[0]
            view = _view_panel(row)
            graph = _graph_panel(row, view.width)
            panel = Image.new("RGB", (view.width, view.height + graph.height + 20), "white")
            ImageDraw.Draw(panel).text((4, 3), f"{role}: {tri[role]}", fill="black", font=_font(12))
            panel.paste(view, (0, 20))
            panel.paste(graph, (0, 20 + view.height))
            panels.append(panel)
        header = (
            f"{split} triplet {tri['triplet_id']}  tier {tri['tier']}  "
            f"positive offset {tri['positive_offset']}  negative offset {tri['negative_offset']}"
        )
        w = sum(p.width for p in panels) + 10 * (len(panels) - 1)
        line = Image.new("RGB", (w, panels[0].height + 24), "white")
        ImageDraw.Draw(line).text((4, 4), header, fill="black", font=_font(14))
        x = 0
        for p in panels:
            line.paste(p, (x, 24))
            x += p.width + 10
        lines.append(line)
    if not lines:
        return Image.new("RGB", (200, 40), "white")
    sheet = Image.new(
        "RGB", (max(im.width for im in lines), sum(im.height + 12 for im in lines)), (225, 225, 225)
    )
    y = 0
    for im in lines:
        sheet.paste(im, (0, y))
        y += im.height + 12
    return sheet


def channel_sheet(ds: Dataset, *, views: int = 3) -> Image.Image | None:
    """The first ``views`` views of the first split that stores channels, each as its strip
    RGB | depth | instances | classes (:func:`sgdata.pictures.channels.channel_strip`); None
    when the dataset stores no channel."""
    from sgdata.dataset.channels import CHANNELS, decode_channel, depth_metres, stored_channels
    from sgdata.pictures.channels import channel_strip

    if not stored_channels(ds.manifest.config, ds.manifest.format_version):
        return None
    n_classes = len(ds.manifest.classes)
    stored = stored_channels(ds.manifest.config, ds.manifest.format_version)
    columns = ["image", *stored, "objects"]
    rows = ds.observations(ds.splits[0], columns=columns).slice(0, views).to_pylist()
    strips = []
    for row in rows:
        with Image.open(io.BytesIO(row["image"])) as decoded:
            rgb = np.asarray(decoded.convert("RGB"))
        cells = {c: row.get(c) for c in CHANNELS}
        depth = None if cells["depth"] is None else depth_metres(decode_channel(cells["depth"]))
        mask, parts = (None if cells[c] is None else decode_channel(cells[c]) for c in CHANNELS[1:])
        ids = np.array([o["class_id"] for o in row["objects"]], dtype=np.int64)
        strip = channel_strip(
            rgb, depth=depth, instances=mask, class_ids=ids, structure=parts, n_classes=n_classes
        )
        strips.append(strip)
    if not strips:
        return None
    sheet = Image.new("RGB", (strips[0].width, sum(s.height + 6 for s in strips)), "white")
    for k, strip in enumerate(strips):
        sheet.paste(strip, (0, k * (strip.height + 6)))
    return sheet


def _summary(ds: Dataset, obs: dict[str, pa.Table]) -> str:
    m = ds.manifest
    lines = [
        f"# {m.name} {m.version}",
        "",
        f"format {m.format_version}, seed {m.seed}, "
        f"images {m.image.format} {m.image.width}x{m.image.height}",
        "",
        "## Per split",
        "",
        *markdown.table(
            ("split", "rooms", "observations", "triplets", "tier 0..4"),
            [
                [
                    split,
                    len(ds.rooms(split)),
                    obs[split].num_rows,
                    m.counts.triplets[split],
                    " / ".join(map(str, m.counts.tiers[split])),
                ]
                for split in ds.splits
            ],
        ),
    ]
    by_type_rooms: Counter = Counter()
    by_type_obs: Counter = Counter()
    for split in ds.splits:
        types = obs[split].column("room_type").to_pylist()
        by_type_obs.update(types)
        by_type_rooms.update(
            {(t, r) for t, r in zip(types, obs[split].column("room_id").to_pylist(), strict=True)}
        )
    rooms_per_type = Counter(t for t, _ in by_type_rooms)
    lines += [
        "",
        "## Per room type",
        "",
        *markdown.table(
            ("room type", "rooms", "observations"),
            [[t, rooms_per_type[t], by_type_obs[t]] for t in sorted(by_type_obs)],
        ),
    ]
    tiers = [[m.counts.tiers[s][k] for s in ds.splits] for k in range(5)]
    lines += [
        "",
        "## Per tier",
        "",
        *markdown.table(
            ("tier", *ds.splits, "all"), [[k, *per, sum(per)] for k, per in enumerate(tiers)]
        ),
    ]
    per_view = []
    for split in ds.splits:
        t = obs[split]
        n = max(t.num_rows, 1)
        objects = sum(len(o) for o in t.column("objects").to_pylist())
        rels = [e["type"] for r in t.column("relations").to_pylist() for e in r]
        kinds = Counter(rels)
        per_view.append(
            [
                split,
                f"{objects / n:.2f}",
                f"{len(rels) / n:.2f}",
                f"{kinds[0] / n:.2f} / {kinds[1] / n:.2f} / {kinds[2] / n:.2f}",
            ]
        )
    header = ("split", "mean objects", "mean relations (all)", "mean on / in / proximity")
    lines += ["", "## Per view", "", *markdown.table(header, per_view)]
    return "\n".join(lines) + "\n"


def write_report(
    root: str | Path, out: str | Path, *, triplets: int = 6, seed: int = 0
) -> list[Path]:
    """Write the report of the dataset at ``root`` into ``out``; returns the files written.

    Raises:
        DatasetError: ``root`` is not a readable dataset.
    """
    ds = Dataset.open(root)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    columns = ["obs_id", "room_id", "room_type", "heading", "objects", "relations"]
    obs = {s: ds.observations(s, columns=columns) for s in ds.splits}
    classes: Counter = Counter()
    relations: Counter = Counter()
    headings: Counter = Counter()
    visible: Counter = Counter()
    for t in obs.values():
        for objs in t.column("objects").to_pylist():
            classes.update(o["class_name"] for o in objs)
            visible[len(objs)] += 1
        for rels in t.column("relations").to_pylist():
            relations.update(ds.relation_types[e["type"]] for e in rels)
        headings.update(h for h in t.column("heading").to_pylist() if h is not None)
    top = classes.most_common()
    counts = max(visible) + 1 if visible else 1
    charts = {
        "classes.png": bar_chart(
            "Objects per class (all views)",
            [c for c, _ in top],
            [n for _, n in top],
            xlabel="objects",
        ),
        "relations.png": bar_chart(
            "Relations by type (directed edges)",
            list(ds.relation_types),
            [relations[r] for r in ds.relation_types],
            xlabel="edges",
        ),
        "tiers.png": bar_chart(
            "Triplets per tier and split",
            [f"{s} tier {k}" for s in ds.splits for k in range(5)],
            [ds.manifest.counts.tiers[s][k] for s in ds.splits for k in range(5)],
            xlabel="triplets",
        ),
        "headings.png": bar_chart(
            "Views per heading",
            [f"{degrees} deg" for degrees in HEADINGS_DEG],
            [headings[h] for h in range(len(HEADINGS_DEG))],
            xlabel="views",
        ),
        "visible_objects.png": bar_chart(
            "Visible objects per view",
            [str(k) for k in range(counts)],
            [visible[k] for k in range(counts)],
            xlabel="views",
        ),
    }
    written = []
    for name, image in charts.items():
        image.save(out / name)
        written.append(out / name)
    contact_sheet(ds, triplets=triplets, seed=seed).save(out / "contact_sheet.png")
    written.append(out / "contact_sheet.png")
    sheet = channel_sheet(ds)
    if sheet is not None:
        sheet.save(out / "channels.png")
        written.append(out / "channels.png")
    (out / "summary.md").write_text(_summary(ds, obs), encoding="utf-8")
    written.append(out / "summary.md")
    return written
