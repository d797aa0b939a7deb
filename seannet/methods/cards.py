"""Benchmark cards (one per method: ``card.json``, ``card.md``, ``sweep.png``) and the
leaderboard that merges them (``seannet leaderboard DIR...``).

A card is stamped with the commit, the data fingerprint (manifest sha256), the command
(:mod:`seannet.provenance`) and the date it was written; the leaderboard never mixes cards of
different data in one table, and its stamp names each distinct (commit, data, command) once,
with the cards it made (:func:`cards_stamp`).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PIL import Image, ImageDraw, ImageFont

from seannet.errors import MethodError
from seannet.markdown import pct, table
from seannet.provenance import provenance_record
from sgdata.fileio import atomic_write_text, save_png

if TYPE_CHECKING:
    from sgdata.dataset import Dataset

__all__ = [
    "CARD",
    "card_dir",
    "cards_stamp",
    "leaderboard",
    "method_label",
    "read_cards",
    "write_card",
]

CARD = "card.json"  # with card.md and sweep.png beside it
_SAFE = re.compile(r"[^A-Za-z0-9_.+@-]+")


def method_label(name: str) -> str:
    """Method ``name`` made a file name (an import path: ``path/file.py:make`` ->
    ``file.py__make``): its card's directory, its maps' and navigation parts' label."""
    where, colon, attr = name.rpartition(":")
    if colon and where.endswith(".py"):
        name = f"{Path(where).name}:{attr}"
    return _SAFE.sub("_", name.replace(":", "__")).strip("_")


def card_dir(out: Path, name: str) -> Path:
    """Where the card of method ``name`` goes under ``out`` (:func:`method_label`)."""
    return out / method_label(name)


def cards_stamp(cards: list[dict[str, Any]]) -> str:
    """A markdown line naming what made ``cards``: each distinct (commit, data, command) once,
    with the cards it made and the date they were written. Empty for no card."""
    made: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for card in cards:
        p = card["provenance"]
        key = (p.get("commit"), bool(p.get("dirty")), p.get("manifest_sha256"), p.get("command"))
        made.setdefault(key, []).append(card)
    parts = []
    for (commit, dirty, digest, command), group in made.items():
        first = group[0]["provenance"]
        data = ""
        if digest:
            seed = first.get("dataset_seed")
            seed = f"dataset seed {seed}, " if seed is not None else ""
            data = (
                f" on `{first.get('data')}` ({seed}format {first.get('format_version')}, "
                f"manifest sha256 `{digest[:16]}…`)"
            )
        # a card's provenance is recorded as it is written (write_card): its "started"
        days = sorted({str(c["provenance"].get("started", "?"))[:10] for c in group})
        when = days[0] if len(days) == 1 else f"{days[0]} to {days[-1]}"
        names = ", ".join(f"`{c['method']}`" for c in group)
        what = "card" if len(group) == 1 else f"{len(group)} cards"
        changes = " with uncommitted changes" if dirty else ""
        parts.append(
            f"{what} {names} written {when} by commit `{str(commit)[:10]}`{changes}{data}: "
            f"`{command}`"
        )
    return f"*Made by {'; '.join(parts)}.*" if parts else ""


def _interval(entry: dict[str, float]) -> str:
    if "low" in entry:
        return f"{pct(entry['mean'])} [{pct(entry['low'])}, {pct(entry['high'])}]"
    half = entry.get("ci95", float("nan"))
    return pct(entry["mean"]) + (f" ± {pct(half)}" if not math.isnan(half) else "")


def _breaks(summary: dict[str, Any], measure: str) -> str:
    """Where the method breaks along ``measure``, or "never" with its accuracy in the sweep's
    last bin that holds triplets (how far the data's change reached, and what it cost)."""
    at = summary["breaks_at"].get(measure)
    if at:
        return str(at)
    held = [(b, v) for b, v in summary["change"][measure].items() if v["triplets"]]
    return f"never ({held[-1][0]}: {pct(held[-1][1]['accuracy'])} %)" if held else "never"


def _spec_line(card: dict[str, Any]) -> list[str]:
    """What ``seannet benchmark --methods`` took, when the card's title differs from it, with
    a plug-in file's sha256 (the code that made the card)."""
    spec = card.get("spec", card["method"])
    if spec == card["method"]:
        return []
    where, _, attr = spec.rpartition(":")
    if where.endswith(".py"):
        spec = f"{Path(where).name}:{attr}"  # the file, not the folders of the machine
    source = card["provenance"].get("method_source")
    code = f", sha256 `{source['sha256'][:16]}…`" if source else ""
    return [f"Loaded from `{spec}`{code}.", ""]


def _markdown(card: dict[str, Any]) -> str:
    s = card["summary"]
    kind = f"trained, {s['seeds']} seeds" if card["trained"] else "no training"
    lines = [
        f"# Benchmark card: {card['method']}",
        "",
        cards_stamp([card]),
        "",
        *_spec_line(card),
        f"- {kind}; test read once; every choice on val (epsilon {s['epsilon']:.3f})",
        f"- triplet accuracy: **{_interval(s['accuracy_rooms_seeds'])} %** (rooms x seeds, "
        f"95 %) over {s['triplets']} test triplets",
        f"- recall@1 / @5 in the full layout-0 map: {_interval(s['recall1'])} / "
        f"{_interval(s['recall5'])} % over {s['queries']} queries",
        f"- cost: {s['ms_per_view']:.2f} ms per view embedded, {s['bytes_per_map_entry']} bytes "
        "per map entry",
        "- breaks at (first bin below halfway from its no-change accuracy to chance): "
        + ", ".join(f"{m.replace('_', ' ')} {_breaks(s, m)}" for m in s["breaks_at"]),
        "",
        *_small_data_warning(s),
        "Accuracy per tier (%, triplets):",
        "",
        *table(
            list(s["per_tier"]),
            [
                [
                    f"{pct(v)} ({s.get('per_tier_triplets', {}).get(t, '?')})"
                    for t, v in s["per_tier"].items()
                ]
            ],
        ),  # fmt: skip
    ]
    for measure, bins in s["change"].items():
        lines += ["", f"The change sweep, {measure.replace('_', ' ')} (accuracy %, triplets):", ""]
        lines += table(
            list(bins), [[f"{pct(v['accuracy'])} ({v['triplets']})" for v in bins.values()]]
        )
    for measure, bins in s.get("change_recall", {}).items():
        lines += [
            "",
            f"Recall@1 by {measure.replace('_', ' ')} (query vs its map view; %, queries):",
            "",
        ]
        lines += table(
            list(bins), [[f"{pct(v['accuracy'])} ({v['triplets']})" for v in bins.values()]]
        )
    if "covisibility" in s:
        lines += _covisibility_lines(s["covisibility"])
    if "box_noise" in s:
        levels = s["box_noise"]
        recall = all("recall1" in n for n in levels)  # cards made before it lack it
        shown = "accuracy and recall@1" if recall else "accuracy"
        lines += ["", f"Box noise (S jitter, P drop, Q spurious; {shown} %):", ""]
        lines += table(
            ["noise", "accuracy", *(["recall@1"] if recall else [])],
            [
                [n["label"], pct(n["accuracy"]), *([pct(n["recall1"])] if recall else [])]
                for n in levels
            ],
        )
    if "navigation" in s:
        lines += _navigation_lines(s["navigation"])
    return "\n".join(lines) + "\n"


# Below these, a card's figures rest on too little to rank methods by (DESIGN §12)
FEW_ROOMS, FEW_TRIPLETS = 5, 200


def _small_data_warning(s: dict[str, Any]) -> list[str]:
    """A warning line when the test split is small: the intervals are wide and a bin of a
    sweep may hold a handful of triplets."""
    rooms = s.get("rooms")
    if (rooms is None or rooms >= FEW_ROOMS) and s["triplets"] >= FEW_TRIPLETS:
        return [""]
    held = f"{rooms} test rooms and " if rooms is not None else ""
    return [
        "",
        f"**Warning: small test split** ({held}{s['triplets']} triplets; fewer than "
        f"{FEW_ROOMS} rooms or {FEW_TRIPLETS} triplets): read the figures as a smoke test, "
        "not a ranking; a bin's count is beside its accuracy.",
        "",
    ]


def _covisibility_lines(c: dict[str, Any]) -> list[str]:
    """Accuracy on the triplets the views decide (the covisibility oracle agrees with the
    label) beside all of them and the others, overall and per tier."""

    def cell(value: float) -> str:
        return "-" if math.isnan(value) else pct(value)

    rows = [
        [tier, str(t["triplets"]), str(t["decidable_triplets"]), cell(t["oracle_accuracy"]),
         cell(t["accuracy"]), cell(t["decidable"]), cell(t["not_decidable"])]
        for tier, t in [*c["per_tier"].items(), ("all", c)]
    ]  # fmt: skip
    return [
        "",
        f"What the views decide (`--covisibility`): the covisibility oracle orders "
        f"{c['decidable_triplets']} of {c['triplets']} test triplets as their label does "
        f"({cell(c['oracle_accuracy'])} %); this method gets **{cell(c['decidable'])} %** of "
        f"those and {cell(c['not_decidable'])} % of the others (chance: 50 %). The oracle "
        "reads depth and poses: a diagnostic, not a method.",
        "",
        *table(
            [
                "tier",
                "triplets",
                "decidable",
                "oracle %",
                "accuracy %",
                "decidable %",
                "not decidable %",
            ],
            rows,
        ),  # fmt: skip
    ]


def _navigation_lines(nav: dict[str, Any]) -> list[str]:
    """The navigation test's rates per rule and case, % with the 95 % interval by rooms."""
    chosen = nav.get("stop_rule")
    how = (
        f"; `chosen`: the stop rule chosen on {chosen['val_episodes']} val episodes per case and "
        f"room for navigation success, {chosen['label']}"
        if chosen
        else ""
    )
    lines = [
        "",
        f"Navigation test with this method as localizer ({nav['split']} rooms, "
        f"{nav['episodes_per_case_and_room']} episodes per case and room, navigator "
        f"`{Path(nav['navigator']).name}`, epsilon {nav['epsilon']:.3f} from val{how}; % [95 % "
        f"interval by rooms]; [{nav['results']}]({nav['results']})):",
        "",
    ]
    rows = []
    for rule, cases in nav["rates"].items():
        for case, rates in cases.items():
            outcomes = [k for k in rates if k != "episodes"]
            rows.append([rule, case, str(rates["episodes"]),
                         *(_rate(rates[k]) for k in outcomes)])  # fmt: skip
    return lines + table(["rule", "case", "episodes", *outcomes], rows)


def _rate(rate: dict[str, float]) -> str:
    return f"{rate['percent']:.1f} [{rate['low']:.0f}, {rate['high']:.0f}]"


def _navigation_cell(card: dict[str, Any]) -> str:
    """Success % N / A under the paper's rule, and under the chosen stop rule where the card
    has one; "-" without a navigation test."""
    nav = card["summary"].get("navigation")
    if not nav:
        return "-"
    cells = []
    for rule in ("paper", "chosen"):
        if rule in nav["rates"]:
            rates = nav["rates"][rule]
            cells.append(" / ".join(f"{rates[c]['success']['percent']:.1f}" for c in rates))
    return " · chosen ".join(cells)


def _plot(card: dict[str, Any]) -> Image.Image:
    """The change sweep as small bar panels: accuracy per bin on a 0-100 % axis (the chance
    line at 50 %), each bin's triplet count under its name, and an empty bin drawn as a gap
    that says so (never as a bar of 0 %)."""
    change = card["summary"]["change"]
    font = ImageFont.load_default(size=11)
    width, height, pad, axis = 240, 180, 30, 34
    panel = axis + width + pad
    image = Image.new("RGB", (pad + len(change) * panel, height + 4 * pad), "white")
    draw = ImageDraw.Draw(image)
    draw.text((pad, 6), f"{card['method']}: accuracy by change", fill="black", font=font)
    for k, (measure, bins) in enumerate(change.items()):
        x0, y0 = pad + axis + k * panel, 2 * pad
        draw.rectangle([x0, y0, x0 + width, y0 + height], outline="black")
        for tick in (0, 25, 50, 75, 100):
            y = y0 + height * (1 - tick / 100)
            draw.line([x0 - 4, y, x0, y], fill="black")
            draw.text((x0 - axis, y - 6), f"{tick} %", fill="black", font=font)
        chance = y0 + height * 0.5
        draw.line([x0, chance, x0 + width, chance], fill=(200, 200, 200))
        step = width / max(len(bins), 1)
        for j, (name, value) in enumerate(bins.items()):
            acc, count = value["accuracy"], value["triplets"]
            left = x0 + j * step + 4
            if count and not math.isnan(acc):
                top = y0 + height * (1 - acc)
                draw.rectangle([left, top, left + step - 8, y0 + height], fill=(70, 110, 200))
            else:
                draw.text((left, y0 + height - 16), "empty", fill=(150, 150, 150), font=font)
            draw.text((left, y0 + height + 4), name, fill="black", font=font)
            draw.text((left, y0 + height + 18), f"n={count}", fill=(90, 90, 90), font=font)
        draw.text((x0, y0 - 16), measure.replace("_", " "), fill="black", font=font)
    return image


def write_card(
    directory: Path,
    name: str,
    data: Path | Dataset,
    config: Any,
    runs: list[dict[str, Any]],
    summary: dict[str, Any],
    *,
    trained: bool,
    title: str | None = None,
    source: dict[str, str] | None = None,
) -> Path:
    """Write ``card.json``, ``card.md`` and ``sweep.png`` (each atomically); the JSON path.
    ``data`` (opened, or its root) is stamped in the card's provenance. The card calls the
    method ``title`` (default ``name``) and keeps ``name`` as its ``spec``, what
    ``seannet benchmark --methods`` takes; ``source`` (a plug-in's file and sha256,
    :func:`~seannet.methods.registry.method_source`) goes into the provenance."""
    provenance = provenance_record(data, step="benchmark")
    if source is not None:
        provenance["method_source"] = source
    card = {
        "card": 1,
        "method": title or name,
        "spec": name,
        "trained": trained,
        "provenance": provenance,
        "config": {k: v for k, v in asdict(config).items() if k != "noise"}
        | {"noise": [n.label() for n in config.noise]},
        "summary": summary,
        "runs": runs,
    }
    directory.mkdir(parents=True, exist_ok=True)
    save_png(_plot(card), directory / "sweep.png")
    atomic_write_text(directory / "card.md", _markdown(card))
    atomic_write_text(directory / CARD, json.dumps(card, indent=2, default=str))
    return directory / CARD


def read_cards(paths: list[Path]) -> list[dict[str, Any]]:
    """Every card under the given directories (or card files), sorted by method.

    Raises:
        MethodError: a path holds no card, or a card is not JSON.
    """
    files: list[Path] = []
    for path in paths:
        found = [path] if path.is_file() else sorted(path.rglob(CARD))
        if not found:
            raise MethodError(f"leaderboard: {path} holds no {CARD}; run seannet benchmark first")
        files += found
    cards = []
    for f in files:
        try:
            cards.append(json.loads(f.read_text()))
        except (OSError, ValueError) as exc:
            raise MethodError(f"leaderboard: {f}: not a card ({exc})") from None
    return sorted(cards, key=lambda c: c["method"])


def leaderboard_rows(cards: list[dict[str, Any]], *, timing: bool = True) -> list[str]:
    """The leaderboard's table of ``cards``, best accuracy first (``timing``: with the ms per
    view each card measured, a figure of the machine that ran it)."""
    views = any("covisibility" in c["summary"] for c in cards)  # a --covisibility run
    header = ["method", "seeds", "accuracy % (rooms x seeds, 95 %)",
              *(["decidable %"] if views else []), "recall@1 %", "recall@5 %",
              "breaks at (moved objects)", *(["ms / view"] if timing else []), "bytes / entry",
              "navigation success % N / A"]  # fmt: skip
    titles = [c["method"] for c in cards]
    rows = [
        [
            _board_name(c, titles.count(c["method"]) > 1),
            str(c["summary"]["seeds"]) if c["trained"] else "- (no training)",
            _interval(c["summary"]["accuracy_rooms_seeds"]),
            *([_decidable_cell(c)] if views else []),
            _interval(c["summary"]["recall1"]),
            _interval(c["summary"]["recall5"]),
            _breaks(c["summary"], "moved_objects"),
            *([f"{c['summary']['ms_per_view']:.2f}"] if timing else []),
            str(c["summary"]["bytes_per_map_entry"]),
            _navigation_cell(c),
        ]
        for c in sorted(cards, key=lambda c: -c["summary"]["accuracy"]["mean"])
    ]
    return table(header, rows)


def _decidable_cell(card: dict[str, Any]) -> str:
    """Accuracy % on the test triplets the views decide, or "-" for a card without it."""
    c = card["summary"].get("covisibility")
    return "-" if c is None or math.isnan(c["decidable"]) else pct(c["decidable"])


def _board_name(card: dict[str, Any], shared: bool) -> str:
    """A card's method as the leaderboard says it; a title two cards share (two plug-ins'
    classes of one name) gets the label of the spec that made it."""
    name = f"`{card['method']}`"
    return f"{name} ({method_label(card['spec'])})" if shared and "spec" in card else name


def leaderboard(cards: list[dict[str, Any]]) -> str:
    """One markdown table per dataset fingerprint, best accuracy first, with intervals."""
    by_data: dict[str, list[dict[str, Any]]] = {}
    for card in cards:
        by_data.setdefault(card["provenance"].get("manifest_sha256", "?"), []).append(card)
    lines = ["# Leaderboard", ""]
    for fingerprint, group in by_data.items():
        group.sort(key=lambda c: -c["summary"]["accuracy"]["mean"])  # the stamp's order too
        lines += [f"Data: manifest sha256 `{fingerprint[:16]}…`", "", *leaderboard_rows(group), ""]
        lines += [cards_stamp(group), ""]
    return "\n".join(lines)
