"""The leaderboard's stamp: each distinct (commit, data, command) once, with the cards it made
and the date they were written; a card's own stamp says when it was written."""

from __future__ import annotations

from pathlib import Path

from seannet.methods.cards import cards_stamp
from seannet.provenance import ProcessState, provenance_record


def _card(method: str, record: dict, written: str) -> dict:
    return {"method": method, "provenance": record | {"started": written}}


def test_the_stamp_names_each_command_once_with_its_cards(mini_dataset: Path) -> None:
    first = ProcessState("a" * 40, False, "seannet benchmark --methods x,y --out cards", "t0")
    second = ProcessState("b" * 40, True, "seannet benchmark --methods z --out cards2", "t1")
    one = provenance_record(mini_dataset, step="benchmark", process=first)
    two = provenance_record(mini_dataset, step="benchmark", process=second)
    cards = [
        _card("x", one, "2026-12-02 09:16:39 UTC"),
        _card("z", two, "2026-12-03 10:00:00 UTC"),
        _card("y", one, "2026-12-02 09:41:20 UTC"),
    ]
    text = cards_stamp(cards)
    assert "\n" not in text and text.startswith("*Made by ") and text.endswith(".*")
    assert text.count(first.command) == 1 and text.count(second.command) == 1
    assert text.count("manifest sha256") == 2  # once per command, not per card
    assert "2 cards `x`, `y` written 2026-12-02 by commit `aaaaaaaaaa`" in text
    assert "card `z` written 2026-12-03 by commit `bbbbbbbbbb` with uncommitted changes" in text
    assert "started" not in text
    # cards of one command written on two days give the range
    late = _card("w", one, "2026-12-04 08:00:00 UTC")
    assert "written 2026-12-02 to 2026-12-04" in cards_stamp([cards[0], late])
    assert cards_stamp([]) == ""
