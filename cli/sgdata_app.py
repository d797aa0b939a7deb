"""The ``sgdata`` command: thin typer front end over the sgdata library."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table
from sgdata_cli.errors import run_app

from sgdata.dataset.paths import MANIFEST
from sgdata.dataset.tolerance import Tolerance
from sgdata.label.box_proposer import DEFAULT_MIN_SCORE

app = typer.Typer(
    rich_markup_mode=None,  # help text as written: a config's [catalog] stays
    name="sgdata",
    help="Generate, validate and serve scene-graph datasets of rooms whose objects move.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
console = Console()
DATASET_ROOT = f"Dataset root (holding {MANIFEST})."  # the help of every DATASET argument


@app.command()
def rooms(
    out: Annotated[Path, typer.Argument(help="Directory to write <room_id>/room.usda into.")],
    room_type: Annotated[
        str, typer.Option("--type", help="kitchen | living_room | bedroom | bathroom")
    ] = "kitchen",
    count: Annotated[int, typer.Option(help="How many rooms.")] = 1,
    seed: Annotated[int, typer.Option(help="Dataset seed; each room derives its own.")] = 0,
    first_index: Annotated[int, typer.Option(help="Index of the first room.")] = 0,
    catalog: Annotated[
        Path | None, typer.Option(help="An object catalog TOML (default: the shipped one).")
    ] = None,
    textures: Annotated[
        bool,
        typer.Option(help="Procedural textures (shared in OUT/textures/); --no-textures: flat."),
    ] = True,
) -> None:
    """Generate procedural rooms and write them as USD stages."""
    from sgdata.usd.mesh_files import register_usd_mesh_reader
    from sgdata.usd.scene_dirs import write_rooms
    from sgdata.world.appearance import AppearanceConfig
    from sgdata.world.catalog import load_catalog
    from sgdata.world.rooms import room_stats

    register_usd_mesh_reader()  # a catalog's mesh classes may name USD / USDZ files
    classes = load_catalog(catalog)
    made = write_rooms(
        out,
        room_type,
        count=count,
        seed=seed,
        first_index=first_index,
        catalog=classes,
        appearance=AppearanceConfig(textures=textures),
    )
    table = Table(title=f"{len(made)} {room_type} room(s) in {out}")
    for column in ("room", "size (m)", "objects", "static", "low", "high", "classes"):
        table.add_column(column, justify="left" if column == "room" else "right")
    for room in made:
        stats = room_stats(room)
        table.add_row(
            room.room_id,
            f"{room.width:.2f} x {room.depth:.2f} x {room.height:.2f}",
            str(stats.objects),
            str(stats.by_dynamics["static"]),
            str(stats.by_dynamics["low"]),
            str(stats.by_dynamics["high"]),
            str(stats.classes),
        )
    console.print(table)


@app.command()
def layouts(
    room_dir: Annotated[Path, typer.Argument(help="A room directory holding room.usda.")],
    count: Annotated[int, typer.Option(help="Layouts to write, layout 0 being the base.")] = 5,
    seed: Annotated[int, typer.Option(help="Seed of the layouts (mixed with the room's).")] = 0,
    appearance: Annotated[
        bool,
        typer.Option(help="Each layout draws its light and moving objects' looks ([appearance])."),
    ] = True,
) -> None:
    """Sample layouts of a room under the dynamics rules and write them as USD layers."""
    from sgdata.usd.scene_dirs import write_layouts
    from sgdata.world.appearance import AppearanceConfig
    from sgdata.world.dynamics import summarize_layouts

    made = write_layouts(
        room_dir, count=count, seed=seed, appearance=AppearanceConfig() if appearance else None
    )
    table = Table(title=f"{len(made)} layout(s) of {room_dir}")
    for column in ("layout", "moved", "carried", "stayed put", "seed"):
        table.add_column(column, justify="right")
    for layout in made:
        rules = [m.rule for m in layout.moves if m.moved]
        table.add_row(
            str(layout.index),
            str(sum(r != "carried" for r in rules)),
            str(rules.count("carried")),
            str(sum(not m.moved for m in layout.moves)),
            str(layout.seed),
        )
    console.print(table)
    for line in summarize_layouts(made).lines():
        console.print(line)


@app.command()
def preview(
    stage: Annotated[Path, typer.Argument(help="A room.usda or layout_<k>.usda file.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="PNG to write.")] = Path("top.png"),
    compare: Annotated[
        bool, typer.Option(help="For a layout: draw it beside the base room, moves in red.")
    ] = False,
) -> None:
    """Write a top-down picture of a room or layout with class labels."""
    from sgdata.fileio import save_png
    from sgdata.pictures.preview import draw_layout_pair, draw_room
    from sgdata.usd.room_io import read_room

    room = read_room(stage)
    if compare:
        base = read_room(stage.parent / "room.usda")
        image = draw_layout_pair(base, room, title=stage.stem)
    else:
        image = draw_room(room)
    save_png(image, output)
    console.print(f"wrote {output} ({image.width}x{image.height})")


@app.command()
def tag(
    stage: Annotated[Path, typer.Argument(help="Your own USD room (never modified).")],
    classes: Annotated[
        Path | None,
        typer.Option(
            "--classes", help="TOML of non-catalog classes: a dynamics, or a catalog class."
        ),
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "-o", "--output", help="Tag layer to write (default: <stem>_sgdata/room.usda)."
        ),
    ] = None,
) -> None:
    """Write the sgdata:* attributes your own USD room lacks as a layer over it."""
    from sgdata.usd.tagging import tag_stage

    report = tag_stage(stage, classes=classes, output=output)
    room = report.room
    console.print(
        f"wrote {report.output} over {report.source}: {room.width:.2f} x {room.depth:.2f} x "
        f"{room.height:.2f} m, {len(room.objects)} objects, door on the {room.door.wall} wall",
        markup=False,
    )
    for line in report.inferred:
        console.print(f"  inferred {line}", markup=False)
    for line in (*report.problems, *report.usd_problems):
        console.print(f"  warning: {line}", markup=False)


@app.command()
def generate(
    config: Annotated[
        str, typer.Argument(help="Config TOML file, or a preset: tiny | small | medium | paper.")
    ],
    out: Annotated[Path, typer.Argument(help="Dataset root directory.")],
    workers: Annotated[
        int, typer.Option(help="Worker processes, one renderer each (default: one per core).")
    ] = 0,
    executor: Annotated[
        str, typer.Option(help="local (spawned processes) | ray (a Ray cluster or local instance).")
    ] = "local",
    address: Annotated[
        str | None,
        typer.Option(help="With --executor ray: the cluster to join (default: start one locally)."),
    ] = None,
    resume: Annotated[bool, typer.Option(help="Continue an interrupted run in OUT.")] = False,
    force: Annotated[bool, typer.Option(help="Overwrite what a previous run left in OUT.")] = False,
    profile: Annotated[
        bool,
        typer.Option(help="Time every stage of the room tasks and print where the time went."),
    ] = False,
) -> None:
    """Generate a dataset: rooms, layouts, rendered views, cascaded triplets, Parquet."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from sgdata.pipeline.config import load_config
    from sgdata.pipeline.generate import generate_dataset
    from sgdata.stage_clock import StageClock

    settings = load_config(config)
    if settings.catalog.files and settings.rooms.procedural_types:
        from sgdata.world.room_recipes import never_placed

        for name in never_placed(settings.catalog.load()):
            console.print(
                f"warning: class {name} is in your catalog but no room recipe places it, so "
                f"it can appear only in your own rooms ([rooms] files): give its entry rooms "
                f"= {{kitchen = [1, 2]}} (or sgdata assets add --rooms kitchen:1-2)",
                markup=False,
                highlight=False,
            )
    clock = StageClock() if profile else None
    workers = workers or os.cpu_count() or 1
    columns = (
        TextColumn("{task.description:<7}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("rooms  {task.fields[rate]}"),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=console, transient=False) as bar:
        phases: dict[str, int] = {}

        def show(step) -> None:  # noqa: ANN001
            if step.phase not in phases:
                phases[step.phase] = bar.add_task(step.phase, total=step.total, rate="")
            rate = f"{step.views / step.elapsed:.1f} views/s" if step.views else ""
            bar.update(phases[step.phase], completed=step.done, rate=rate)

        manifest = generate_dataset(
            settings,
            out,
            workers=workers,
            executor=executor,
            address=address,
            resume=resume,
            force=force,
            progress=show,
            clock=clock,
        )
    counts = manifest["counts"]
    table = Table(title=f"{manifest['name']} {manifest['version']} in {out}")
    for column in ("split", "rooms", "observations", "triplets"):
        table.add_column(column, justify="left" if column == "split" else "right")
    for split, rooms in manifest["splits"].items():
        table.add_row(
            split,
            str(len(rooms)),
            str(counts["observations"][split]),
            str(counts["triplets"][split]),
        )
    console.print(table)
    if clock is not None:
        _print_stages(clock)


def _print_stages(clock) -> None:  # noqa: ANN001
    """The stage table of a profiled run: the command's wall time by step, then each task
    phase's worker time (summed over its workers) by stage; share per phase."""
    from sgdata.pipeline.room_tasks import stage_order

    table = Table(title="where the time went: the command's wall, then each phase's workers")
    for column in ("phase", "stage", "calls", "seconds", "share"):
        table.add_column(column, justify="left" if column in ("phase", "stage") else "right")
    for row in clock.rows(stage_order()):
        table.add_row(
            row["phase"],
            row["stage"],
            str(row["calls"]),
            f"{row['seconds']:.2f}",
            f"{100 * row['share']:.1f} %",
        )
    console.print(table)


@app.command()
def render(
    room_dir: Annotated[Path, typer.Argument(help="A room directory with its layouts.")],
    layout: Annotated[int, typer.Option(help="Layout index.")] = 0,
    pose: Annotated[
        str, typer.Option(help="Grid cell and heading: I,J,H (H in 0..3); default: a middle cell.")
    ] = "",
    output: Annotated[Path, typer.Option("-o", "--output", help="PNG of the view.")] = Path(
        "view.png"
    ),
    textures: Annotated[
        bool, typer.Option(help="Draw the room's textures; --no-textures: flat colours.")
    ] = True,
    config: Annotated[
        str | None,
        typer.Option(
            help="A generation config (TOML or preset) whose [camera], [poses], [annotation] "
            "and [catalog] the view follows (default: the defaults of sgdata generate)."
        ),
    ] = None,
) -> None:
    """Render one annotated view; also writes <output>.overlay.png with boxes and relations and
    <output>.channels.png with the view's colourised depth, instance and class masks."""
    from PIL import Image

    from sgdata.dataset.vocabulary import class_vocabulary
    from sgdata.errors import ConfigError
    from sgdata.fileio import save_png
    from sgdata.pictures.channels import channel_strip
    from sgdata.pictures.overlay import draw_overlay
    from sgdata.pipeline.config import GenerateConfig, load_config
    from sgdata.pipeline.snapshot import render_snapshot

    cell, heading = None, 0
    if pose:
        try:
            i, j, heading = (int(v) for v in pose.split(","))
        except ValueError:
            raise ConfigError(f"--pose {pose!r}: expected I,J,H such as 4,6,1") from None
        cell = (i, j)
    settings = load_config(config) if config is not None else GenerateConfig()
    catalog = settings.catalog.load()  # a config's [catalog] files: its mesh and new classes
    record = render_snapshot(
        room_dir,
        layout=layout,
        cell=cell,
        heading=heading,
        camera=settings.camera,
        poses=settings.poses,
        annotation=settings.annotation,
        catalog=catalog,
        textures=textures,
    )
    overlay_path = output.with_suffix(".overlay.png")
    save_png(Image.fromarray(record.rgb), output)
    save_png(draw_overlay(record), overlay_path)
    vocabulary = class_vocabulary(catalog)[1]
    class_ids = {c.name: c.id for c in vocabulary}
    channels_path = output.with_suffix(".channels.png")
    strip = channel_strip(
        record.rgb,
        depth=record.depth,
        instances=record.instances,
        class_ids=np.array([class_ids[c] for c in record.obj_class], dtype=np.int64),
        structure=record.structure,
        n_classes=len(vocabulary),
    )
    save_png(strip, channels_path)
    counts = np.bincount(record.rel_type, minlength=4) if len(record.rel_type) else [0] * 4
    console.print(
        f"wrote {output}, {overlay_path} and {channels_path}: {record.num_objects} visible "
        "objects, "
        f"relations on {counts[0]}, in {counts[1]}, proximity {counts[2]}, disjoint {counts[3]}"
    )


@app.command()
def validate(
    root: Annotated[Path, typer.Argument(help=DATASET_ROOT)],
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the report as JSON on stdout.")
    ] = False,
    quick: Annotated[bool, typer.Option(help="Skip decoding the images.")] = False,
    usd: Annotated[bool, typer.Option(help="Also run USD's validators on the scenes.")] = False,
    sources: Annotated[
        Path | None,
        typer.Option(help="Folder of the generating config: check its [rooms] files unchanged."),
    ] = None,
    against: Annotated[
        Path | None,
        typer.Option(
            help="A reference dataset: fail when this one differs beyond sgdata diff's "
            "tolerance (another CPU's edge pixels pass, and are reported)."
        ),
    ] = None,
    show: Annotated[int, typer.Option(help="Problems to list in the summary.")] = 20,
) -> None:
    """Check a dataset against its format; exit 0 only when every check passes."""
    from sgdata.validate import validate_dataset

    report = validate_dataset(root, quick=quick, usd=usd, sources=sources, against=against)
    if json_out:
        print(report.to_json())
    else:
        table = Table(title=f"sgdata validate {root} ({report.elapsed:.1f} s)")
        for column in ("check", "checked", "failures"):
            table.add_column(column, justify="left" if column == "check" else "right")
        for name, failures in report.failures().items():
            style = "red" if failures else None
            table.add_row(name, str(report.checked.get(name, 0)), str(failures), style=style)
        for name in report.skipped:
            table.add_row(name, "skipped", "-", style="dim")
        console.print(table)
        for problem in report.problems[:show]:
            console.print(
                f"{problem.location()}: [{problem.check}] {problem.message}", markup=False
            )
        if len(report.problems) > show:
            console.print(f"... and {len(report.problems) - show} more (--json lists all)")
        for note in report.notes:
            console.print(note, markup=False, soft_wrap=True)
        console.print("clean" if report.ok else f"{len(report.problems)} problem(s)")
    if not report.ok:
        raise typer.Exit(1)


@app.command()
def diff(
    first: Annotated[Path, typer.Argument(help="A dataset directory (holding dataset.json).")],
    second: Annotated[Path, typer.Argument(help="The dataset to compare it with.")],
    pixel_share: Annotated[
        float,
        typer.Option(
            min=0.0,
            max=1.0,
            help="Share of one view's pixels that may differ, per channel (also bounds an "
            "object's visible-pixel count).",
        ),
    ] = Tolerance.pixel_share,
    min_iou: Annotated[
        float, typer.Option(min=0.0, max=1.0, help="Lowest IoU of a 2D box with its counterpart.")
    ] = Tolerance.min_iou,
) -> None:
    """Tell how two datasets differ: manifest, rows, annotations, pixels per channel. Exit 0
    when identical, 1 when they differ within the tolerance, 2 beyond it."""
    from sgdata.dataset.diff import diff_datasets

    report = diff_datasets(first, second, Tolerance(pixel_share=pixel_share, min_iou=min_iou))
    for line in report.lines():
        console.print(line, markup=False, soft_wrap=True)
    raise typer.Exit(report.verdict)


@app.command()
def migrate(
    root: Annotated[Path, typer.Argument(help=DATASET_ROOT)],
) -> None:
    """Rewrite a dataset of an older format in the current format, in place (card and
    croissant.json included; structure masks drawn for one that stores instance masks)."""
    from sgdata.dataset import migrate_dataset
    from sgdata.pipeline.structure_masks import structure_column

    manifest = migrate_dataset(root, draw_structure=structure_column)
    console.print(f"{root}: format {manifest.format_version}, {len(manifest.files)} files")


@app.command()
def report(
    root: Annotated[Path, typer.Argument(help=DATASET_ROOT)],
    output: Annotated[Path, typer.Option("-o", "--output", help="Directory to write into.")] = Path(
        "report"
    ),
    triplets: Annotated[int, typer.Option(help="Random triplets on the contact sheet.")] = 6,
    seed: Annotated[int, typer.Option(help="Seed of the triplet draw.")] = 0,
) -> None:
    """Write histograms, a contact sheet of random triplets and summary.md for a dataset."""
    from sgdata.pictures.report import write_report

    written = write_report(root, output, triplets=triplets, seed=seed)
    for path in written:
        console.print(f"wrote {path}")


@app.command()
def label(
    photos: Annotated[Path, typer.Argument(help="Directory of PNG / JPEG photos to label.")],
    out: Annotated[Path, typer.Option("--out", help="Dataset directory (labels/ is kept there).")],
    port: Annotated[int, typer.Option(help="Port of the labeling page.")] = 8765,
    host: Annotated[
        str, typer.Option(help="Address to bind; anything but loopback exposes your photos.")
    ] = "127.0.0.1",
    classes: Annotated[
        Path | None,
        typer.Option("--classes", help="TOML mapping extra class names to catalog classes."),
    ] = None,
    export: Annotated[
        bool, typer.Option("--export", help="Write the labels as a real dataset and exit.")
    ] = False,
    split: Annotated[str, typer.Option(help="Split of the exported rooms.")] = "test",
    max_pixels: Annotated[
        int | None,
        typer.Option(
            "--max-pixels",
            help="Largest photo to open, in pixels (default: Pillow's decompression-bomb guard).",
        ),
    ] = None,
    detector: Annotated[
        Path | None,
        typer.Option(
            "--detector",
            help="A detector run (seannet detector train --out RUN): its boxes pre-fill each "
            "photo never saved, marked as proposed until accepted.",
        ),
    ] = None,
    min_score: Annotated[
        float, typer.Option("--min-score", help="The --detector's boxes of at least this score.")
    ] = DEFAULT_MIN_SCORE,
) -> None:
    """Label real photos in a local web page (boxes, classes, relations), or --export them.

    A --classes map is remembered beside the labels: later runs and --export use it.
    """
    from sgdata.errors import ConfigError
    from sgdata.label.photos import DEFAULT_MAX_PIXELS

    pixels = max_pixels or DEFAULT_MAX_PIXELS
    if export and detector is not None:
        raise ConfigError(
            "--detector proposes boxes in the page; --export writes the saved labels: give one"
        )
    if export:
        from sgdata.label.export import export_dataset

        done = export_dataset(photos, out, class_map=classes, split=split, max_pixels=pixels)
        console.print(
            f"wrote {done.observations} observation(s) of {done.rooms} room(s) and "
            f"{done.triplets} triplet(s) to {done.root} (split {done.split})"
        )
        if done.unlabeled:
            console.print(
                f"left out {len(done.unlabeled)} photo(s) without a room id: "
                + ", ".join(done.unlabeled),
                markup=False,
            )
        if done.never_labeled:
            console.print(
                f"left out {len(done.never_labeled)} photo(s) never labeled: "
                + ", ".join(done.never_labeled),
                markup=False,
            )
        if done.guessed:
            where = ", ".join(f"{name} ({n})" for name, n in done.guessed.items())
            console.print(
                f"left out {sum(done.guessed.values())} proposed box(es) never accepted: "
                f"{where}; accept (Enter) or delete them in the page",
                markup=False,
            )
        if done.pending:
            where = ", ".join(f"{name} ({n})" for name, n in done.pending.items())
            console.print(
                f"{sum(done.pending.values())} undecided proposal(s) stored as disjoint: "
                f"{where}; decide them in the page (Tab, then Enter / O / I / P / D)",
                markup=False,
            )
        for note in done.notes:
            console.print(note, markup=False)
        return
    from sgdata.label.server import serve

    serve(
        photos,
        out,
        host=host,
        port=port,
        class_map=classes,
        max_pixels=pixels,
        detector=detector,
        min_score=min_score,
        on_ready=lambda url: console.print(f"labeling {photos} at {url} (Ctrl-C stops)"),
    )


@app.command(name="import")
def import_(
    fmt: Annotated[str, typer.Argument(metavar="FORMAT", help="coco | labelme | labelstudio")],
    annotations: Annotated[
        Path, typer.Argument(metavar="FILE", help="The annotation file (LabelMe: or a folder).")
    ],
    images: Annotated[Path, typer.Option("--images", help="Directory of the annotated photos.")],
    out: Annotated[Path, typer.Option("--out", help="Dataset directory (labels/ is kept there).")],
    classes: Annotated[
        Path | None,
        typer.Option("--classes", help="TOML mapping names to catalog classes (+ [relations])."),
    ] = None,
    room: Annotated[
        str | None,
        typer.Option(help="Room id of photos the file gives none (default: FILE's name)."),
    ] = None,
    room_type: Annotated[
        str | None,
        typer.Option(
            help="kitchen | living_room | bedroom | bathroom (default: from the room id)."
        ),
    ] = None,
    split: Annotated[str, typer.Option(help="Split of the imported rooms.")] = "test",
) -> None:
    """Import COCO, LabelMe or Label Studio boxes (and relations) as labels and a real dataset."""
    from sgdata.label.importers import import_labels

    done = import_labels(
        fmt,
        annotations,
        images,
        out,
        class_map=classes,
        room=room,
        room_type=room_type,
        split=split,
    )
    ex = done.export
    console.print(
        f"imported {done.boxes} box(es) and {done.relations} relation(s) of {done.photos} "
        f"photo(s); wrote {ex.observations} observation(s) of {ex.rooms} room(s) and "
        f"{ex.triplets} triplet(s) to {ex.root} (split {ex.split})"
    )
    for note in [*done.notes, *ex.notes]:
        console.print(note, markup=False)


@app.command(name="export")
def export(
    fmt: Annotated[str, typer.Argument(metavar="FORMAT", help="coco | labelstudio | yolo")],
    dataset: Annotated[Path, typer.Argument(help=DATASET_ROOT)],
    output: Annotated[
        Path,
        typer.Option(
            "-o", "--output", help="coco, yolo: the folder to write; labelstudio: the JSON file."
        ),
    ],
    images: Annotated[
        Path | None,
        typer.Option(
            "--images", help="labelstudio: where the images go (default: <output stem>_images/)."
        ),
    ] = None,
    split: Annotated[
        str | None, typer.Option("--split", help="coco, yolo: export this split only.")
    ] = None,
    masks: Annotated[
        bool,
        typer.Option("--masks", help="coco: RLE segmentations from the instance masks."),
    ] = False,
    force: Annotated[
        bool, typer.Option("--force", help="coco, yolo: replace a non-empty output folder.")
    ] = False,
) -> None:
    """Write a dataset for other tools: COCO or YOLO (detector trainers: boxes, masks and
    image files) or Label Studio JSON (boxes and relations)."""
    from sgdata.errors import ConfigError
    from sgdata.label.detector_files import check_format

    check_format(fmt)
    if fmt == "labelstudio":
        from sgdata.label.labelstudio import export_labelstudio

        if split or masks or force:
            raise ConfigError("--split, --masks and --force are for coco and yolo exports")
        done = export_labelstudio(dataset, output, images_dir=images)
        console.print(
            f"wrote {done.tasks} task(s), {done.boxes} box(es) and {done.relations} relation(s) "
            f"to {done.path}; images in {done.images}"
        )
        return
    if images is not None:
        raise ConfigError(f"--images is for labelstudio; {fmt} writes images under -o")
    if fmt == "coco":
        from sgdata.label.coco_export import export_coco

        coco = export_coco(dataset, output, split=split, masks=masks, force=force)
        console.print(
            f"wrote {coco.images} image(s) and {coco.annotations} annotation(s)"
            f"{' with RLE masks' if coco.masks else ''} to {coco.root} "
            f"({', '.join(f.name for f in coco.files)})"
        )
        return
    if masks:
        raise ConfigError("--masks is for coco; YOLO detection labels hold boxes")
    from sgdata.label.yolo_export import export_yolo

    yolo = export_yolo(dataset, output, split=split, force=force)
    console.print(
        f"wrote {yolo.images} image(s) and {yolo.boxes} box(es) to {yolo.root} (data.yaml)"
    )


assets_app = typer.Typer(
    rich_markup_mode=None,  # help text as written: a config's [catalog] stays
    help="Objects you bring: mesh files as catalog classes (docs/rooms.md).",
    no_args_is_help=True,
)
app.add_typer(assets_app, name="assets")


@assets_app.command("add")
def assets_add(
    folder: Annotated[Path, typer.Argument(help="Folder of mesh files: one variant each.")],
    class_name: Annotated[str, typer.Option("--class", help="Catalog class, e.g. Mug.")],
    catalog: Annotated[
        Path, typer.Option(help="User catalog file to write ([catalog] files of a config).")
    ] = Path("catalog.toml"),
    dynamics: Annotated[str | None, typer.Option(help="static | low | high")] = None,
    placement: Annotated[
        str | None, typer.Option(help="floor | wall_floor | wall | surface | part")
    ] = None,
    on: Annotated[
        list[str] | None, typer.Option(help="Receptacle class it rests on (repeatable).")
    ] = None,
    inside: Annotated[
        list[str] | None, typer.Option(help="Container class it rests in (repeatable).")
    ] = None,
    up: Annotated[
        str | None, typer.Option(help="The files' up axis: y | z (default: measured).")
    ] = None,
    units: Annotated[
        str | None, typer.Option(help="The files' unit: m | cm | mm (default: measured).")
    ] = None,
    scale: Annotated[
        str | None, typer.Option(help="keep (true size, default) | fit (into the size bounds)")
    ] = None,
    front: Annotated[
        str | None, typer.Option(help="The files' front axis: -y | +y | -x | +x")
    ] = None,
    rooms: Annotated[
        list[str] | None,
        typer.Option(
            help="Room type that holds it, TYPE or TYPE:LOW-HIGH per room (repeatable), e.g. "
            "kitchen:1-2: how a new class gets into generated rooms."
        ),
    ] = None,
) -> None:
    """Write a catalog class for a folder of mesh files and print what was measured."""
    from sgdata.usd.mesh_files import register_usd_mesh_reader
    from sgdata.world.asset_entries import add_asset_class
    from sgdata.world.mesh_assets import orientation_warning

    register_usd_mesh_reader()  # USD / USDZ files too

    added = add_asset_class(
        folder,
        class_name,
        catalog,
        dynamics=dynamics,
        placement=placement,
        receptacles=tuple(on or ()),
        containers=tuple(inside or ()),
        up=up,
        units=units,
        scale=scale,
        front=front,
        rooms=_room_counts(rooms or []),
    )
    verb = "new class" if added.new else "overrides the shipped class"
    table = Table(title=f"{added.name} ({verb}) in {added.catalog}")
    for column in ("file", "format", "up", "unit", "size (m)", "triangles", "surfaces"):
        table.add_column(column, justify="left" if column == "file" else "right")
    for asset in added.assets:
        surfaces = ", ".join(f"{'in' if s.inside else 'top'} {s.z:.3f}" for s in asset.surfaces)
        table.add_row(
            Path(asset.path).name,
            Path(asset.path).suffix.lstrip("."),
            f"{asset.up.upper()} ({asset.up_from})",
            asset.units,
            " x ".join(f"{v:.3f}" for v in asset.size),
            str(asset.triangles),
            surfaces or "-",
        )
    console.print(table)
    warning = orientation_warning(added.name, added.assets)
    if warning:
        console.print(f"warning: {warning}", markup=False, highlight=False)
    console.print(f"appears: {added.appears}", markup=False, highlight=False)
    console.print(added.entry.rstrip(), markup=False, highlight=False)


def _room_counts(values: list[str]) -> dict[str, tuple[int, int]]:
    """``--rooms`` values (``kitchen`` or ``kitchen:1-2``) as room type -> (low, high)."""
    counts = {}
    for value in values:
        room_type, _, span = value.partition(":")
        low, _, high = (span or "1").partition("-")
        if not (low.isdigit() and (high or low).isdigit()):
            raise typer.BadParameter(
                f"--rooms {value!r}: expected TYPE or TYPE:LOW-HIGH, e.g. kitchen:1-2"
            )
        counts[room_type] = (int(low), int(high or low))
    return counts


main = run_app(app, "sgdata")

if __name__ == "__main__":
    main()
