"""The step table bench/train_step.py prints and docs/benchmarks.md shows: one layout."""

from __future__ import annotations

from seannet.training.step_table import step_table


def test_each_network_is_a_row_against_the_first() -> None:
    networks = [
        {"network": "resnet18", "step_s": 1.23456, "step_ratio": 1.0, "spread": 0.031,
         "busy": 0.12, "batches": 40},
        {"network": "seannet", "step_s": 2.5, "step_ratio": 2.025, "spread": 0.2,
         "busy": 0.5, "batches": 20},
    ]  # fmt: skip
    assert step_table(networks) == [
        "| network | step s | x resnet18 | spread | busy | batches per epoch |",
        "|---|---|---|---|---|---|",
        "| `resnet18` | 1.235 | 1.00x | 3 % | 12 % | 40 |",
        "| `seannet` | 2.500 | 2.02x | 20 % | 50 % | 20 |",
    ]
