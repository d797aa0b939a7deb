"""The protocol as units with committed records (``seannet results``): real training on the
mini dataset, tiny budgets. Interrupted runs give the same docs as one run; a killed unit
leaves nothing and is redone alone; another recipe's record is left out; a unit above the
limit is refused with its estimate."""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from seannet.data.box_noise import BoxNoise
from seannet.errors import ModelError
from seannet.evaluation.covisibility_oracle import step_direction
from seannet.navigation.episodes import OUTCOMES
from seannet.protocol.design import (
    AIM,
    COVISIBILITY,
    DESIGN,
    NAVIGATION,
    Design,
    NavigationDesign,
    Row,
    covers,
    diagnostic_unit,
    plan_units,
)
from seannet.protocol.docs import Records, write_docs
from seannet.protocol.records import find_folder, read_records
from seannet.protocol.runner import plan_text, run_for, status
from tests.artefacts import shared_artefact
from tests.cli_runner import run_cli

# 5 units: resnet18 at each lr with seed 0, tiny-image (no training), the covisibility
# oracle, then the chosen lr's seed 1; one batch of one epoch at 64 px, so a unit takes seconds
TINY = Design(
    rows=(Row("resnet18+boxes", seeds=2, noise=True), Row("tiny-image", seeds=1)),
    batches=1,
    epochs=1,
    noise_grid=(BoxNoise(jitter=0.05), AIM),
    diagnostics=(COVISIBILITY,),
    preset="smoke",
)
DOCS = ("results.md", "learning-curve.md", "leaderboard.md")


def _docs(found_root: Path, out: Path) -> dict[str, str]:
    write_docs(Records(TINY, find_folder(found_root, None)), out)
    return {name: (out / name).read_text() for name in DOCS}


@pytest.fixture(scope="session")
def protocol_records(tmp_path_factory: pytest.TempPathFactory, mini_dataset: Path) -> Path:
    """The records root of the tiny protocol run in one uninterrupted call."""

    def build(root: Path) -> None:
        written = run_for(TINY, mini_dataset, root, root.parent / "protocol-work")
        assert len(written) == 5

    return shared_artefact(tmp_path_factory, "protocol_records", build)


def _val_record(val: dict[str, float], noise: tuple[str, ...] = ()) -> dict:
    """What the planner reads of a seed-0 record: its evaluations and val accuracies."""
    return {
        "evaluations": [{"method": m, "noise": list(noise), "full_map": False} for m in val],
        "results": {m: {"val_accuracy": v} for m, v in val.items()},
    }


def test_plan_chooses_the_lr_on_val_then_plans_the_other_seeds() -> None:
    design = Design(rows=(Row("resnet18+boxes", seeds=3), Row("resnet18", seeds=2)))
    first = plan_units(design, {})
    names = [u.name for u in first.todo]
    assert names == ["resnet18-b300-lr0.003-s0", "resnet18-b300-lr0.01-s0"]
    assert first.pending == 2 and first.open_ended  # two specs may choose apart

    # +boxes is best at 0.01, plain resnet18 ties: the smaller lr
    records = {
        "resnet18-b300-lr0.003-s0": _val_record({"resnet18+boxes": 0.70, "resnet18": 0.80}),
        "resnet18-b300-lr0.01-s0": _val_record({"resnet18+boxes": 0.75, "resnet18": 0.80}),
    }
    then = plan_units(design, records)
    assert [u.name for u in then.done] == names
    todo = {u.name: [e.method for e in u.evaluations] for u in then.todo}
    assert todo == {
        "resnet18-b300-lr0.003-s1": ["resnet18"],
        "resnet18-b300-lr0.01-s1": ["resnet18+boxes"],
        "resnet18-b300-lr0.01-s2": ["resnet18+boxes"],
    }
    assert then.pending == 0
    # a record that lacks an evaluation the design asks is run again
    del records["resnet18-b300-lr0.01-s0"]["results"]["resnet18"]
    again = plan_units(design, records)
    assert [u.name for u in again.todo] == ["resnet18-b300-lr0.01-s0"] and again.pending == 2


def test_one_seed_carries_the_noise_grid_and_every_seed_the_aim() -> None:
    design = Design(rows=(Row("resnet18+boxes", seeds=3, noise=True, full_map=True),))
    records = {
        f"resnet18-b300-lr{lr:g}-s0": _val_record({"resnet18+boxes": 0.5}, (AIM.label(),))
        for lr in design.lrs
    }
    units = {u.seed: u.evaluations[0] for u in plan_units(design, records).todo}
    assert units[1].noise == design.noise_grid and units[1].full_map
    assert units[2].noise == (design.aim,) and not units[2].full_map
    zero = plan_units(design, {}).todo[0].evaluations[0]
    assert zero.noise == (design.aim,) and not zero.full_map  # before the lr is chosen


def test_an_interrupted_protocol_gives_the_docs_of_one_run(
    protocol_records: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    whole = _docs(protocol_records, tmp_path / "whole")
    assert "**Complete**: all 5 units" in whole["results.md"]
    records = tmp_path / "records"
    first = run_for(TINY, mini_dataset, records, tmp_path / "work", units=2)
    assert len(first) == 2
    part = _docs(records, tmp_path / "part")
    assert "**2 of 5 units measured**" in part["results.md"]
    second = run_for(TINY, mini_dataset, records, tmp_path / "work")
    assert len(second) == 3
    assert _docs(records, tmp_path / "again") == whole


def test_a_doc_of_one_unit_says_so_and_leaves_the_others_cells_empty(
    protocol_records: Path, tmp_path: Path
) -> None:
    records = tmp_path / "records"
    shutil.copytree(protocol_records, records)
    folder = next(p for p in records.iterdir() if p.is_dir())
    for path in folder.glob("*.json"):
        if path.stem != "tiny-image-s0":
            path.unlink()
    text = _docs(records, tmp_path / "docs")["results.md"]
    assert "**1 of 5 units measured**" in text
    row = next(line for line in text.splitlines() if line.startswith("| `resnet18+boxes` | 0 of 2"))
    assert row.replace(" ", "").endswith("|" * 9)  # every figure cell empty
    assert "| `tiny-image` | 1 |" in text


def test_a_record_of_another_recipe_is_left_out_and_the_doc_says_so(
    protocol_records: Path, tmp_path: Path
) -> None:
    records = tmp_path / "records"
    shutil.copytree(protocol_records, records)
    folder = next(p for p in records.iterdir() if p.is_dir())
    alien = json.loads((folder / "tiny-image-s0.json").read_text())
    alien["dataset"]["recipe"] = "f" * 64
    alien["results"]["tiny-image"]["accuracy"] = 0.0  # would show if it were read
    (folder / "tiny-image-s9.json").write_text(json.dumps(alien))
    found = find_folder(records, None)
    assert list(found.left_out) == [
        f"tiny-image-s9.json: another dataset recipe ({'f' * 16}…, not {found.recipe[:16]}…)"
    ]
    text = _docs(records, tmp_path / "docs")["results.md"]
    said = [line for line in text.splitlines() if line.startswith("- Left out")]
    assert said == [f"- Left out: 1 file(s) of the folder: {found.left_out[0]}."]
    clean = _docs(protocol_records, tmp_path / "clean")["results.md"]
    assert [line for line in text.splitlines() if line not in said] == clean.splitlines()


def test_the_planner_refuses_a_unit_above_the_limit_naming_its_estimate(
    mini_dataset: Path, tmp_path: Path
) -> None:
    design = Design(rows=(Row("resnet18", seeds=1),), budget_s=3000.0, batches=1, epochs=1)
    text = plan_text(status(design, mini_dataset, tmp_path / "records"))
    assert "refused resnet18-b3000-lr0.003-s0: estimated 52 min (prior), above the 45 min" in text
    said: list[str] = []
    assert run_for(design, mini_dataset, tmp_path / "records", tmp_path / "work",
                   say=said.append) == []  # fmt: skip
    assert any(line.startswith("refused resnet18-b3000-lr0.003-s0") for line in said)


def test_run_for_never_starts_a_unit_that_cannot_finish(mini_dataset: Path, tmp_path: Path) -> None:
    said: list[str] = []
    got = run_for(TINY, mini_dataset, tmp_path / "records", tmp_path / "work", seconds=60,
                  say=said.append)  # fmt: skip
    assert got == []  # the prior says 5 min for tiny-image, 2 min and more for each training
    # the time left is read as the run goes (60 s, or 59 by then)
    assert any(line.startswith("not starting tiny-image-s0: ~5 min needed, ") for line in said)
    assert all(line.endswith(" s left") for line in said)


def test_a_unit_killed_half_way_leaves_nothing_and_its_rerun_redoes_it_alone(
    protocol_records: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    records = tmp_path / "records"
    shutil.copytree(protocol_records, records)
    folder = next(p for p in records.iterdir() if p.is_dir())
    (folder / "resnet18-b300-lr0.003-s0.json").unlink()
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    work = tmp_path / "work"
    script = (
        "import sys; from pathlib import Path; from tests.seannet.test_protocol import TINY; "
        "from seannet.protocol.runner import run_for; "
        "run_for(TINY, Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3]))"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", script, str(mini_dataset), str(records), str(work)],
        cwd=Path(__file__).resolve().parents[2], start_new_session=True,
    )  # fmt: skip
    history = work / "resnet18-b300-lr0.003-s0" / "runs"
    deadline = time.monotonic() + 120
    while not history.exists() and time.monotonic() < deadline and child.poll() is None:
        time.sleep(0.05)
    assert history.exists(), "the unit never started"
    os.killpg(child.pid, signal.SIGKILL)
    child.wait()
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before  # no record, no temp
    redone = run_for(TINY, mini_dataset, records, work)
    assert [p.name for p in redone] == ["resnet18-b300-lr0.003-s0.json"]
    whole = json.loads((protocol_records / folder.name / redone[0].name).read_text())
    again = json.loads(redone[0].read_text())
    assert _figures(again) == _figures(whole)  # the same figures as an unbroken unit


def _figures(record: dict) -> str:
    """A unit record's figures as text (NaN included), without the timings of ``cost``."""
    results = {m: {k: v for k, v in r.items() if k != "cost"} for m, r in record["results"].items()}
    return json.dumps(results, sort_keys=True)


def test_the_results_commands_plan_and_refuse_bad_input(
    protocol_records: Path, mini_dataset: Path, tmp_path: Path
) -> None:
    done = run_cli("seannet", "results", "run", "--data", str(mini_dataset), "--for", "5x")
    assert done.returncode != 0 and "'5x': expected a duration such as 50m" in done.stderr
    assert "Traceback" not in done.stderr
    done = run_cli("seannet", "results", "doc", "--records", str(tmp_path / "none"))
    assert done.returncode != 0 and "0 recipe folders (none); pass --data" in done.stderr
    done = run_cli("seannet", "results", "plan", "--data", str(mini_dataset), "--records",
                   str(protocol_records))  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert (
        "units recorded" in done.stdout and "to run  seannet-fc512-b300-lr0.003-s0" in done.stdout
    )


def test_records_are_small_and_name_what_made_them(protocol_records: Path) -> None:
    folder = next(p for p in protocol_records.iterdir() if p.is_dir())
    found = read_records(folder, find_folder(protocol_records, None).recipe)
    assert len(found.units) == 5 and not found.left_out
    for name, record in found.units.items():
        size = (folder / f"{name}.json").stat().st_size
        assert size < 64_000, f"{name}: {size} bytes"
        assert record["provenance"]["commit"] and record["machine"]["cores"]
        assert record["dataset"]["content_sha256"] in found.content_sha256s
        assert record["unit"] == name
    trained = found.units["resnet18-b300-lr0.01-s0"]
    assert trained["training"]["batches_per_epoch"] == 1
    assert trained["training"]["calibration"] == {"handed_in": 1}


def test_step_direction_reads_the_step_against_the_anchors_heading() -> None:
    east = (1.0, 1.0, 0.0)  # heading +x
    assert step_direction(east, (1.0, 1.0)) == "s"
    assert step_direction(east, (1.5, 1.0)) == "a" and step_direction(east, (0.5, 1.0)) == "a"
    assert step_direction(east, (1.0, 1.75)) == "c"
    assert step_direction(east, (1.25, 1.5)) == "m"
    north = (1.0, 1.0, math.pi / 2)
    assert step_direction(north, (1.0, 1.75)) == "a" and step_direction(north, (1.5, 1.0)) == "c"


def test_the_covisibility_oracle_is_recorded_and_shown_beside_the_methods(
    protocol_records: Path, tmp_path: Path
) -> None:
    found = find_folder(protocol_records, None)
    oracle = found.units[diagnostic_unit(COVISIBILITY).name]["results"][COVISIBILITY]
    n = oracle["triplets"]
    assert len(oracle["tier"]) == len(oracle["direction"]) == len(oracle["correct"]) == n > 0
    for tier, direction in zip(oracle["tier"], oracle["direction"], strict=True):
        # tier 0's positive is the anchor's own cell in another layout; every other tier moves
        assert (direction == "s") == (tier == "0"), (tier, direction)
    assert oracle["accuracy"] > 0.5  # the views decide more triplets than a coin would
    docs = tmp_path / "docs"
    text = _docs(protocol_records, docs)["results.md"]
    section = text.split("## What the views can decide")[1].split("\n## ")[0]
    assert "| all |  | " + str(n) + " | " in section
    assert "`tiny-image` %" in section and "`resnet18+boxes` %" in section
    aim = section.split("What this says of the 90 % aim:")[1]
    assert "On the triplets the views decide" in aim and "The aim stays 90 %" in aim
    assert (docs / "images" / "covisibility-disagreements.png").is_file()


def test_the_committed_docs_are_what_the_committed_records_say(tmp_path: Path) -> None:
    root = Path(__file__).resolve().parents[2]
    found = find_folder(root / "results" / "records", None)
    write_docs(Records(DESIGN, found), tmp_path)
    for name in DOCS:
        assert (tmp_path / name).read_text() == (root / "docs" / name).read_text(), (
            f"docs/{name} is not what the records say: run `seannet results doc`"
        )


def test_navigation_units_add_to_the_plan_and_re_run_nothing() -> None:
    rows = (Row("seannet-fc512", seeds=3), Row("seannet-fc512+box-kernel", seeds=3),
            Row("tiny-image", seeds=1))  # fmt: skip
    plain = Design(rows=rows)
    nav = NavigationDesign(methods=("seannet-fc512", "seannet-fc512+box-kernel", "tiny-image"))
    design = Design(rows=rows, navigation=nav)
    # before seed 0 chooses the lr: tiny-image's one unit (it fits nothing: one seed), and
    # each spec's three wait on the choice
    first = plan_units(design, {})
    assert [u.name for u in first.todo if u.purpose] == ["tiny-image-s0-nav"]
    assert first.pending == plan_units(plain, {}).pending + 6
    val = {"seannet-fc512": 0.8, "seannet-fc512+box-kernel": 0.85}
    records = {f"seannet-fc512-b300-lr{lr:g}-s0": _val_record(val) for lr in design.lrs}
    then = plan_units(design, records)
    navigation = [u for u in then.todo if u.purpose == NAVIGATION]
    # both specs chose 0.003 (ties: the smaller lr); a unit tests one method on its network
    assert [u.name for u in navigation] == [
        "seannet-fc512-b300-lr0.003-s0-nav",
        "seannet-fc512-b300-lr0.003-s0-nav-seannet-fc512+box-kernel", "tiny-image-s0-nav",
        "seannet-fc512-b300-lr0.003-s1-nav",
        "seannet-fc512-b300-lr0.003-s1-nav-seannet-fc512+box-kernel",
        "seannet-fc512-b300-lr0.003-s2-nav",
        "seannet-fc512-b300-lr0.003-s2-nav-seannet-fc512+box-kernel",
    ]  # fmt: skip
    assert [[e.method for e in u.evaluations] for u in navigation[:2]] == [
        [m] for m in nav.methods[:2]
    ]
    assert all(e.navigation for u in navigation for e in u.evaluations)
    # the headline's units are the plain design's: asking the test re-runs none of them
    others = [u.name for u in then.todo + then.done if not u.purpose]
    assert others == [u.name for u in plan_units(plain, records).todo + then.done]
    # a navigation record without the test (an older one) is run again
    nav_record = _val_record({"tiny-image": 0.6})
    assert not covers(nav_record, navigation[2])
    nav_record["evaluations"][0]["navigation"] = True
    assert covers(nav_record, navigation[2])
    with pytest.raises(ModelError, match=r"navigation methods \['resnet18'\] have no row"):
        Design(rows=rows, navigation=NavigationDesign(methods=("resnet18",)))


def test_a_navigation_unit_records_both_rules_and_the_doc_shows_them(
    mini_dataset: Path, tmp_path: Path
) -> None:
    nav = NavigationDesign(methods=("tiny-image",), seeds=1, episodes=1, val_episodes=1)
    design = Design(rows=(Row("tiny-image", seeds=1),), navigation=nav)
    records = tmp_path / "records"
    written = run_for(design, mini_dataset, records, tmp_path / "work")
    assert [p.stem for p in written] == ["tiny-image-s0", "tiny-image-s0-nav"]
    record = json.loads(written[1].read_text())
    got = record["results"]["tiny-image"]["navigation"]
    assert got["navigator"] == "oracle" and got["stop_rule"]["val_episodes"] == 1
    for rule in ("paper", "chosen"):
        for case in ("N", "A"):
            rates = got["rates"][rule][case]
            assert rates["episodes"] >= 1
            assert math.isclose(sum(rates[o]["percent"] for o in OUTCOMES), 100.0)
            assert (
                rates["success"]["low"] <= rates["success"]["percent"] <= rates["success"]["high"]
            )
    assert not (tmp_path / "work").exists() or not any((tmp_path / "work").rglob("*.pt"))
    docs = tmp_path / "docs"
    write_docs(Records(design, find_folder(records, None)), docs)
    section = (docs / "results.md").read_text().split("## Navigation (paper Table II)")[1]
    success = got["rates"]["chosen"]["A"]["success"]
    cell = f"{success['percent']:.1f} [{success['low']:.0f}, {success['high']:.0f}]"
    assert "| `tiny-image` | 1 | " in section and cell in section.split("\n## ")[0]
    assert got["stop_rule"]["label"] in section
    # where the failed episodes ended, and what holds the A aim back
    missed = got["rates"]["chosen"]["A"]["localization"]
    row = next(
        line for line in section.splitlines() if line.startswith("| `tiny-image` | chosen |")
    )
    assert (
        row.split(" | ")[3]
        == f"{missed['percent']:.1f} [{missed['low']:.0f}, {missed['high']:.0f}]"
    )
    hit = got["rates"]["chosen"]["A"]["collision"]["percent"]
    assert f"would succeed in at most {100 - hit:.1f} % of A episodes" in section
    assert "Collisions under the paper's rule, the worst localizer: N " in section
    # the leaderboard's navigation cell: paper rule, then the chosen one
    paper, chosen = (got["rates"][rule] for rule in ("paper", "chosen"))
    cell = (f"{paper['N']['success']['percent']:.1f} / {paper['A']['success']['percent']:.1f}"
            f" · chosen {chosen['N']['success']['percent']:.1f}")  # fmt: skip
    assert cell in (docs / "leaderboard.md").read_text()
    assert "Navigation with each network as localizer" not in (docs / "results.md").read_text()
