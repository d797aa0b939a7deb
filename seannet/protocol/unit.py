"""One unit, end to end: the batches its budget buys (a calibration record, made once per
network and budget and shared by every machine), the training, every evaluation its
:class:`~seannet.protocol.design.Evaluation` list asks, and its record, written last.

The unit's working files (runs, checkpoints, maps) live in a gitignored folder that is
emptied when the unit starts: a unit killed half-way leaves no record, and its rerun starts
from nothing, so it gives what an unbroken unit gives.
"""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from seannet.data.opening import open_dataset
from seannet.methods.benchmark import BenchmarkConfig, run_seed
from seannet.methods.cards import method_label
from seannet.methods.registry import load_method
from seannet.protocol.design import COVISIBILITY, Design, Evaluation, Unit
from seannet.protocol.records import (
    CALIBRATION,
    dataset_identity,
    machine,
    provenance,
    write_record,
)
from sgdata.dataset import Dataset
from sgdata.fileio import save_png

__all__ = ["budget_batches", "calibration_name", "run_unit"]


def calibration_name(network: str, budget_s: float) -> str:
    return f"{CALIBRATION}-{method_label(network)}-b{budget_s:g}"


def budget_batches(
    design: Design,
    network: str,
    budget_s: float,
    ds: Dataset,
    folder: Path,
    say: Callable[[str], None],
) -> tuple[int, dict[str, Any] | None]:
    """Batches per epoch ``budget_s`` buys ``network``: the design's batches at its budget
    when handed in, else the network's calibration at the design's budget (read from its
    record, or timed now and recorded), scaled by ``budget_s`` over it. Every budget of the
    curve scales one calibration, so the curve is not bent by a second timing on a busier
    machine. Returns the batches and the calibration record (None when handed in)."""
    scale = budget_s / design.budget_s
    if design.batches is not None:
        return max(1, round(design.batches * scale)), None
    name = calibration_name(network, design.budget_s)
    path = folder / f"{name}.json"
    if path.is_file():
        record = json.loads(path.read_text())
    else:
        from seannet.evaluation.compare import model_spec
        from seannet.training.budget import calibrate
        from seannet.training.config import preset

        say(f"{network}: calibrating {design.budget_s:g} s of one thread")
        config = model_spec(network, preset(design.preset)).config
        got = calibrate(config, ds, design.budget_s)
        record = {
            "calibration": got.to_dict(),
            "network": network,
            "dataset": dataset_identity(ds),
            "provenance": provenance(),
            "machine": machine(),
        }
        write_record(folder, name, record)
    return max(1, round(record["calibration"]["batches"] * scale)), record


def run_unit(
    unit: Unit,
    design: Design,
    data: Path,
    folder: Path,
    work: Path,
    say: Callable[[str], None] = lambda _text: None,
) -> Path:
    """Run ``unit`` on the dataset at ``data`` and write its record into ``folder`` (the
    dataset recipe's records folder); ``work`` is emptied first and holds its runs. Returns
    the record's path."""
    started = provenance()
    where = machine()  # the load before the unit adds its own
    wall, cpu = time.perf_counter(), time.process_time()
    shutil.rmtree(work, ignore_errors=True)
    ds = open_dataset(data)
    if unit.trains == COVISIBILITY:
        return _diagnostic(unit, ds, folder, started, where, wall, cpu, say)
    batches, calibration = None, None
    if unit.network:
        assert unit.budget_s is not None
        batches, calibration = budget_batches(design, unit.trains, unit.budget_s, ds, folder, say)
    results: dict[str, Any] = {}
    seconds: dict[str, float] = {}
    training: dict[str, Any] = {}
    for evaluation in unit.evaluations:
        clock = time.perf_counter()
        result, method = _evaluate(unit, design, evaluation, ds, batches, work, say)
        if evaluation.full_map:
            say(f"{evaluation.method}: full map of the test rooms, seed {unit.seed}")
            result["full_map"] = _full_map(evaluation.method, method, result, ds, work, design)
        if evaluation.navigation:
            say(f"{evaluation.method}: the navigation test, seed {unit.seed}")
            result["navigation"] = _navigation(evaluation.method, method, result, ds, work, design)
        results[evaluation.method] = result
        seconds[evaluation.method] = round(time.perf_counter() - clock, 1)
        training = training or _training(method, batches)
    record = {
        "unit": unit.name,
        **unit.to_dict(),
        "dataset": dataset_identity(ds),
        "provenance": started,
        "machine": where,
        "training": {**training, "calibration": _calibration_ref(unit, design, calibration)},
        "seconds": {
            "wall": round(time.perf_counter() - wall, 1),
            "cpu": round(time.process_time() - cpu, 1),
            "by_method": seconds,
        },
        "results": results,
    }
    path = write_record(folder, unit.name, record)
    shutil.rmtree(work, ignore_errors=True)  # the record holds what any doc needs
    return path


def _evaluate(
    unit: Unit,
    design: Design,
    evaluation: Evaluation,
    ds: Dataset,
    batches: int | None,
    work: Path,
    say: Callable[[str], None],
) -> tuple[dict[str, Any], Any]:
    """The benchmark harness's protocol for one seed of one method: fit (at the unit's lr;
    specs on one network share its training), every choice on val, test once, the noise."""
    factory, _ = load_method(evaluation.method)
    config = BenchmarkConfig(
        seeds=(unit.seed,),
        preset=design.preset,
        batches=batches,
        epochs=design.epochs,
        lrs=(unit.lr,) if unit.lr is not None else (),
        noise=evaluation.noise,
    )
    result, method = run_seed(evaluation.method, factory, ds, config, unit.seed, work / "runs", say)
    choices = dict(result.get("choices", {}))
    choices.pop("run", None)  # a path of this machine's work folder, gone with the unit
    result["choices"] = choices
    return result, method


def _training(method: Any, batches: int | None) -> dict[str, Any]:
    """What the training got: batches per epoch, epochs, triplets (a bundled network)."""
    config = getattr(method, "config", None)
    if config is None or batches is None:
        return {"batches_per_epoch": None}
    return {
        "batches_per_epoch": batches,
        "epochs": config.epochs,
        "batch_size": config.batch_size,
        "examples": batches * config.epochs * config.batch_size,
    }


def _calibration_ref(
    unit: Unit, design: Design, calibration: dict[str, Any] | None
) -> dict[str, Any] | None:
    if calibration is None:
        return None if design.batches is None else {"handed_in": design.batches}
    got = calibration["calibration"]
    return {
        "record": calibration_name(unit.trains, design.budget_s),
        "budget_s": got["budget_s"],
        "batches": got["batches"],
        "step_s": got["step_s"],
        "clock": got.get("clock"),
    }


def _full_map(
    name: str, method: Any, result: dict[str, Any], ds: Dataset, work: Path, design: Design
) -> dict[str, Any]:
    """Recall of the true pose among every sub-node of each test room's map (layout 0, every
    reachable cell x 4 headings at the design's spacing, rendered live), queries from the
    other layouts."""
    from seannet.methods.localizer import save_method
    from seannet.navigation.localizer import open_localizer
    from seannet.navigation.map_localization import run_localize
    from seannet.navigation.maps import build_maps

    clock = time.perf_counter()
    directory = work / "fullmap" / method_label(name)
    directory.mkdir(parents=True, exist_ok=True)
    save_method(directory, name, method, epsilon=result["threshold"]["epsilon"],
                epsilon_source="val (protocol unit)", data=ds)  # fmt: skip
    localizer = open_localizer(directory, ds, require_epsilon=False)
    rooms = list(ds.rooms("test"))
    build_maps(localizer, ds, rooms, directory / "maps", spacing=design.map_spacing)
    got = run_localize(directory, directory / "maps", ds, split="test", out=directory)
    return {
        "spacing": design.map_spacing,
        "rooms": len(rooms),
        "queries": got["queries"],
        "recall@1": got["recall@1"],
        "recall@5": got["recall@5"],
        "by_moved": {
            b: {"queries": v["queries"], "recall@1": v["recall@1"]}
            for b, v in got["by_moved"].items()
        },  # fmt: skip
        "seconds": round(time.perf_counter() - clock, 1),
    }


def _navigation(
    name: str, method: Any, result: dict[str, Any], ds: Dataset, work: Path, design: Design
) -> dict[str, Any]:
    """The navigation test with the method as localizer (the benchmark card's: its epsilon
    chosen on val by the harness, its stop rule chosen on val episodes, the test episodes
    read once by the paper's rule and by the chosen one), and its seconds."""
    from seannet.methods.localizer import save_method
    from seannet.navigation.config import NavigationTestConfig
    from seannet.navigation.method_navigation import navigation_test

    nav = design.navigation
    assert nav is not None
    clock = time.perf_counter()
    directory = work / "navigation" / method_label(name)
    directory.mkdir(parents=True, exist_ok=True)
    save_method(directory, name, method, epsilon=result["threshold"]["epsilon"],
                epsilon_source="val (protocol unit)", data=ds)  # fmt: skip
    got = navigation_test(
        directory,
        navigator=None if nav.navigator is None else Path(nav.navigator),
        data=ds,
        config=NavigationTestConfig(episodes=nav.episodes),
        stop_policy=True,
        val_episodes=nav.val_episodes,
    )
    got.pop("results")  # a path of this machine's work folder, gone with the unit
    return {**got, "seconds": round(time.perf_counter() - clock, 1)}


def _diagnostic(
    unit: Unit,
    ds: Dataset,
    folder: Path,
    started: dict[str, Any],
    where: dict[str, Any],
    wall: float,
    cpu: float,
    say: Callable[[str], None],
) -> Path:
    """The covisibility oracle on the test triplets, its record, and beside it the contact
    sheet of triplets where covisibility disagrees with the label."""
    from seannet.evaluation.covisibility_oracle import oracle

    result = oracle(ds, "test", say)
    sheet = folder / f"{unit.name}.png"
    save_png(contact_sheet(ds, result["disagreements"]), sheet)
    record = {
        "unit": unit.name,
        **unit.to_dict(),
        "dataset": dataset_identity(ds),
        "provenance": started,
        "machine": where,
        "seconds": {
            "wall": round(time.perf_counter() - wall, 1),
            "cpu": round(time.process_time() - cpu, 1),
        },
        "results": {COVISIBILITY: {**result, "contact_sheet": sheet.name}},
    }
    return write_record(folder, unit.name, record)


def contact_sheet(ds: Dataset, triplets: list[dict[str, Any]], size: int = 112) -> Any:
    """Anchor, positive and negative of each triplet side by side, two triplets a row, each
    captioned with its tier, direction and both covisibilities."""
    from PIL import Image, ImageDraw, ImageFont

    from sgdata.dataset import decode_image

    wanted = {t[k] for t in triplets for k in ("anchor", "positive", "negative")}
    table = ds.observations("test", columns=["obs_id", "image"]).to_pylist()
    images = {r["obs_id"]: decode_image(r["image"]) for r in table if r["obs_id"] in wanted}
    caption, per_row = 16, 2
    rows = max(1, -(-len(triplets) // per_row))
    sheet = Image.new("RGB", (per_row * 3 * size + (per_row - 1) * 8, rows * (size + caption)),
                      "white")  # fmt: skip
    draw, font = ImageDraw.Draw(sheet), ImageFont.load_default(size=11)
    for k, t in enumerate(triplets):
        x0 = (k % per_row) * (3 * size + 8)
        y0 = (k // per_row) * (size + caption)
        for j, role in enumerate(("anchor", "positive", "negative")):
            thumb = Image.fromarray(images[t[role]]).resize((size, size))
            sheet.paste(thumb, (x0 + j * size, y0 + caption))
        draw.text(
            (x0 + 2, y0 + 2),
            f"tier {t['tier']} {t['direction']}: cov A-P {t['anchor_positive']:.2f}, "
            f"A-N {t['anchor_negative']:.2f}",
            fill="black",
            font=font,
        )
    return sheet
