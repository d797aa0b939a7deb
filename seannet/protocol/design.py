"""What the docs need, as units: the protocol's design and the planner that turns it, with
the records made so far, into the units still to run.

A *unit* is one training (a network at one learning rate, seed and budget; or a method's
``fit`` at one seed) plus every evaluation any doc needs from it, done in one process while
the model exists (DESIGN §12). Its record is the result; no doc needs the model again.

The order of choices follows DESIGN §12:

- a bundled network's learning rate is chosen on val with seed 0: seed 0 is trained at every
  lr of :attr:`Design.lrs`, each of those units evaluating every method spec on that network
  (``resnet18``, ``resnet18+boxes``, ``resnet18+box-kernel`` share one training); each spec
  then takes the lr its own val accuracy favours (ties: the smaller);
- the other seeds and the learning curve's other budgets train at the chosen lr only, so they
  can be planned once seed 0's records exist (until then they are *pending*);
- test figures are computed in every unit (the model exists once), and a doc reads them only
  at the lr val chose: a run val did not choose is never shown.

A method that is not a bundled network (a reference method, a plug-in) makes its own choices
on val inside ``fit``: one unit per seed. A method with no ``fit`` is run on one seed.

The navigation test (:class:`NavigationDesign`, paper Table II) has units of its own, so that
asking it adds units and re-runs none: per method and seed, its network trained again at the
lr val chose, then the method is the localizer of the test, its stop rule chosen on val
episodes and the test episodes read once by the paper's rule and by the chosen one. The network
is trained as the headline's unit of that seed trains it, but not to the same bits (training on
CPU threads is not bit-reproducible: seannet-fc512 seed 0 gave 83.25 and 83.75 % test), so
the unit records its own triplet figures beside the test. One method a unit: two tests on one
training would pass the limit.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from seannet.data.box_noise import BoxNoise
from seannet.errors import ModelError
from seannet.seeds import DEFAULT_SEEDS
from seannet.training.config import DEFAULT_PRESET

__all__ = [
    "AIM",
    "COVISIBILITY",
    "DEFAULT_BUDGET_S",
    "DESIGN",
    "Design",
    "Evaluation",
    "NAVIGATION",
    "NOISE_GRID",
    "NavigationDesign",
    "PROTOCOL_VERSION",
    "Plan",
    "Row",
    "Unit",
    "chosen_lrs",
    "covers",
    "diagnostic_unit",
    "navigation_unit",
    "network_of",
    "plan_units",
]

# Bumped when a unit's evaluations or a choice's rule change: records of another version are
# never mixed in (a doc says how many it left out).
PROTOCOL_VERSION = 1
# Seconds of one thread's compute per training run (seannet.training.budget). Chosen from the
# learning curve of 2026-12-03: val accuracy of seannet-fc512 went 84.2 -> 84.7 % from 300 s
# to 1,200 s, half a point for 4x the compute (docs/learning-curve.md).
DEFAULT_BUDGET_S = 300.0
LIMIT_S = 45 * 60.0  # a unit must fit a preemptible machine's slice, on 2 cores
LRS = (0.003, 0.01)
# Box noise (corners jittered by S x the box's size, objects missed with probability P): the
# aim's point on every seed, the grid on one seed.
AIM = BoxNoise(jitter=0.05, drop=0.1)
NOISE_GRID = (
    BoxNoise(jitter=0.02),
    BoxNoise(jitter=0.05),
    BoxNoise(jitter=0.1),
    BoxNoise(drop=0.1),
    BoxNoise(drop=0.25),
    AIM,
)


@dataclass(frozen=True)
class Row:
    """A method some doc shows, and what it needs measured."""

    method: str  # a model spec (``resnet18+boxes``), a registered method or an import path
    seeds: int = len(DEFAULT_SEEDS)  # seeds 0 .. seeds - 1
    noise: bool = False  # the box-noise grid on one seed, the aim's point on every seed
    full_map: bool = False  # recall among every sub-node of a test room's map, one seed
    stage: int = 0  # run order: every unit of stage 0 before any of stage 1 (the headline first)


# a navigation unit's name ends with it: it trains what a headline unit trains, for another test
NAVIGATION = "nav"


@dataclass(frozen=True)
class NavigationDesign:
    """The navigation test the docs need: which methods localize, on how many seeds, on how
    many episodes. ``navigator`` is a ``seannet train-navigator`` run on this machine, or None
    for the oracle navigator (the right action from the true pose): it needs no model kept
    between units, and it leaves the stop decision as the only failure the localizer causes."""

    methods: tuple[str, ...]
    seeds: int = len(DEFAULT_SEEDS)
    episodes: int = 20  # test episodes per case and room
    val_episodes: int = 50  # val episodes per case and room the stop rule is chosen on
    navigator: str | None = None


@dataclass(frozen=True)
class Design:
    """Every row the docs need, and the rules they are measured by."""

    rows: tuple[Row, ...]
    budget_s: float = DEFAULT_BUDGET_S  # where lrs are chosen and the headline is read
    lrs: tuple[float, ...] = LRS
    curve_methods: tuple[str, ...] = ()  # measured again at each of ``curve``'s budgets
    curve: tuple[tuple[float, int], ...] = ()  # (budget seconds, seeds) besides budget_s
    preset: str = DEFAULT_PRESET
    batches: int | None = None  # batches per epoch at budget_s, handed in: no calibration
    epochs: int | None = None  # None: the preset's
    noise_grid: tuple[BoxNoise, ...] = NOISE_GRID
    aim: BoxNoise = AIM
    limit_s: float = LIMIT_S
    map_spacing: int = 1  # the full map: every reachable cell
    diagnostics: tuple[str, ...] = ()  # units that train nothing: COVISIBILITY
    navigation: NavigationDesign | None = None

    def __post_init__(self) -> None:
        names = [r.method for r in self.rows]
        if len(set(names)) != len(names):
            raise ModelError(f"protocol: a method is named twice in {names}")
        rowless = [m for m in self.navigation.methods if m not in names] if self.navigation else []
        if rowless:
            raise ModelError(f"protocol: navigation methods {rowless} have no row")
        if not self.lrs or any(lr <= 0 for lr in self.lrs):
            raise ModelError(f"protocol: learning rates must be > 0, got {self.lrs}")
        unknown = [m for m in self.curve_methods if m not in names]
        if unknown:
            raise ModelError(f"protocol: curve methods {unknown} have no row")

    def row(self, method: str) -> Row:
        return next(r for r in self.rows if r.method == method)

    def with_methods(self, methods: list[str], seeds: int = len(DEFAULT_SEEDS)) -> Design:
        """This design with ``methods`` added as rows (a user's methods under our tables)."""
        have = {r.method for r in self.rows}
        added = tuple(Row(m, seeds=seeds) for m in methods if m not in have)
        return Design(**{**self.__dict__, "rows": self.rows + added})


@dataclass(frozen=True)
class Evaluation:
    """One method spec evaluated in a unit, with the box noise and full map asked of it."""

    method: str
    noise: tuple[BoxNoise, ...] = ()
    full_map: bool = False
    navigation: bool = False  # the navigation test with this method as localizer


@dataclass(frozen=True)
class Unit:
    """One training (or one method's fit) and its evaluations."""

    trains: str  # the bundled network trained, or the method fitted
    seed: int
    budget_s: float | None  # None: a method that is not a bundled network
    lr: float | None  # None: the method chooses its own on val
    evaluations: tuple[Evaluation, ...]
    network: bool = True  # trains a bundled network (calibrated batches, an lr)
    # NAVIGATION: a unit of the navigation test; its name says so, and names its method when
    # that is not what it trains (seannet-fc512+box-kernel on seannet-fc512)
    purpose: str = ""

    @property
    def name(self) -> str:
        """The record's file name, without ``.json``."""
        from seannet.methods.cards import method_label

        parts = [method_label(self.trains)]
        if self.budget_s is not None:
            parts.append(f"b{self.budget_s:g}")
        if self.lr is not None:
            parts.append(f"lr{self.lr:g}")
        parts.append(f"s{self.seed}")
        if self.purpose:
            parts.append(self.purpose)
            parts += [method_label(e.method) for e in self.evaluations if e.method != self.trains]
        return "-".join(parts)

    def to_dict(self) -> dict[str, Any]:
        return {
            "trains": self.trains,
            "seed": self.seed,
            "budget_s": self.budget_s,
            "lr": self.lr,
            "network": self.network,
            "purpose": self.purpose,
            "evaluations": [
                {
                    "method": e.method,
                    "noise": [n.label() for n in e.noise],
                    "full_map": e.full_map,
                    "navigation": e.navigation,
                }
                for e in self.evaluations
            ],
        }


@dataclass
class Plan:
    """The units of a design: recorded, still to run, and pending on a choice not yet made."""

    done: list[Unit] = field(default_factory=list)
    todo: list[Unit] = field(default_factory=list)
    pending: int = 0  # units known to come once seed 0's records choose their lr
    open_ended: bool = False  # more may come: specs on one network may choose lrs apart

    @property
    def total(self) -> int:
        return len(self.done) + len(self.todo) + self.pending


def network_of(method: str) -> str | None:
    """The bundled network a model spec trains (``resnet18+boxes`` -> ``resnet18``), or None
    for a method that is not a model spec."""
    if ":" in method:
        return None
    from seannet.methods.registry import load_method

    try:
        _, bundled = load_method(method)
    except Exception:  # noqa: BLE001 - not loadable now: the unit says why when it runs
        return None
    return bundled.trained if bundled is not None else None


def chosen_lrs(
    design: Design, network: str, records: dict[str, dict[str, Any]]
) -> dict[str, float] | None:
    """Each spec on ``network`` and the lr its val accuracy chose at the design's budget
    (ties: the smaller), from seed 0's records; None while one of them is missing."""
    specs = [r.method for r in design.rows if network_of(r.method) == network]
    val: dict[float, dict[str, float]] = {}
    for lr in design.lrs:
        unit = _seed_zero(design, network, lr, specs)
        record = records.get(unit.name)
        if record is None or not covers(record, unit):
            return None
        val[lr] = {m: r["val_accuracy"] for m, r in record["results"].items()}
    return {m: max(design.lrs, key=lambda lr: (val[lr][m], -lr)) for m in specs}


def _seed_zero(design: Design, network: str, lr: float, specs: list[str]) -> Unit:
    evaluations = tuple(
        Evaluation(m, noise=(design.aim,) if design.row(m).noise else ()) for m in specs
    )
    return Unit(network, 0, design.budget_s, lr, evaluations)


def _extras_seed(row: Row) -> int:
    """The seed that carries the one-seed evaluations (noise grid, full map): the first seed
    trained after the lr was chosen, so no evaluation is spent on a run val did not choose."""
    return min(1, row.seeds - 1)


def _evaluation(design: Design, row: Row, seed: int) -> Evaluation:
    extras = seed == _extras_seed(row)
    noise: tuple[BoxNoise, ...] = ()
    if row.noise:
        noise = design.noise_grid if extras else (design.aim,)
    return Evaluation(row.method, noise=noise, full_map=row.full_map and extras)


def diagnostic_unit(name: str) -> Unit:
    """The unit of a diagnostic (one per dataset: no seed, no training)."""
    return Unit(name, 0, None, None, (), network=False)


def plan_units(design: Design, records: dict[str, dict[str, Any]]) -> Plan:
    """Every unit of ``design`` in the order they should run (choices first), split into those
    ``records`` (by unit name) hold and those still to run; units that wait on a choice are
    counted as pending."""
    plan = Plan()
    units: list[Unit] = []
    networks: dict[str, list[Row]] = {}
    for row in design.rows:
        network = network_of(row.method)
        if network is None:
            units += [
                Unit(row.method, seed, None, None, (_evaluation(design, row, seed),), False)
                for seed in range(row.seeds)
            ]
        elif network not in networks:  # the lr choice first, in the rows' order
            networks[network] = [r for r in design.rows if network_of(r.method) == network]
            specs = [r.method for r in networks[network]]
            units += [_seed_zero(design, network, lr, specs) for lr in design.lrs]
    units += [diagnostic_unit(name) for name in design.diagnostics]
    later: list[Unit] = []
    for network, rows in networks.items():
        chosen = chosen_lrs(design, network, records)
        if chosen is None:
            # at least one lr; more if the specs choose apart
            plan.open_ended |= len(rows) > 1
            plan.pending += max(r.seeds for r in rows) - 1
            plan.pending += sum(
                seeds for budget, seeds in design.curve if _curve_rows(design, rows)
            )
            continue
        for lr in sorted(set(chosen.values())):
            at = [r for r in rows if chosen[r.method] == lr]
            for seed in range(1, max(r.seeds for r in at)):
                evaluations = tuple(_evaluation(design, r, seed) for r in at if r.seeds > seed)
                later.append(Unit(network, seed, design.budget_s, lr, evaluations))
            curve = [r for r in _curve_rows(design, rows) if chosen[r.method] == lr]
            for budget, seeds in design.curve if curve else ():
                for seed in range(seeds):
                    evaluations = tuple(Evaluation(r.method) for r in curve)
                    later.append(Unit(network, seed, budget, lr, evaluations))
    navigation, waiting = _navigation_units(design, records)
    later += navigation
    plan.pending += waiting
    # by stage (the headline before the fc and the ablations), the curve's other budgets last;
    # within a stage every row's first seed before any row's second (a partial doc has each
    # row early), then the rows' order; a diagnostic runs with the first seeds
    rank = {r.method: (r.stage, k) for k, r in enumerate(design.rows)}
    for network, rows in networks.items():
        rank[network] = min(rank[r.method] for r in rows)
    ranked = sorted(
        units + later,
        key=lambda u: (u.budget_s not in (None, design.budget_s),
                       rank.get(u.trains, (0, len(rank)))[0], u.seed,
                       rank.get(u.trains, (0, len(rank)))[1]),
    )  # fmt: skip
    for unit in ranked:
        done = unit.name in records and covers(records[unit.name], unit)
        (plan.done if done else plan.todo).append(unit)
    return plan


def navigation_unit(design: Design, method: str, seed: int, lr: float | None) -> Unit:
    """The navigation unit of ``method``'s seed (``lr``: the one val chose for its network)."""
    evaluations = (Evaluation(method, navigation=True),)
    network = network_of(method)
    if network is None:
        return Unit(method, seed, None, None, evaluations, network=False, purpose=NAVIGATION)
    return Unit(network, seed, design.budget_s, lr, evaluations, purpose=NAVIGATION)


def _navigation_units(design: Design, records: dict[str, dict[str, Any]]) -> tuple[list[Unit], int]:
    """The navigation test's units that can be planned now, and how many wait on an lr."""
    nav = design.navigation
    if nav is None:
        return [], 0
    units: list[Unit] = []
    pending = 0
    for method in nav.methods:
        # a method that fits nothing gives every seed the same test: its row's seeds bound it
        seeds = min(nav.seeds, design.row(method).seeds)
        network = network_of(method)
        chosen = None if network is None else chosen_lrs(design, network, records)
        if network is not None and chosen is None:
            pending += seeds
            continue
        lr = None if chosen is None else chosen[method]
        units += [navigation_unit(design, method, seed, lr) for seed in range(seeds)]
    return units, pending


def covers(record: dict[str, Any], unit: Unit) -> bool:
    """Whether ``record`` holds every evaluation ``unit`` asks (a record made for a design
    that asked less is run again, and its new record replaces it)."""
    made = {e["method"]: e for e in record.get("evaluations", [])}
    for e in unit.evaluations:
        got = made.get(e.method)
        if got is None or e.method not in record["results"]:
            return False
        if not {n.label() for n in e.noise} <= set(got["noise"]) or e.full_map > got["full_map"]:
            return False
        if e.navigation > got.get("navigation", False):
            return False
    return True


def _curve_rows(design: Design, rows: list[Row]) -> list[Row]:
    return [r for r in rows if r.method in design.curve_methods]


# The covisibility oracle (seannet.evaluation.covisibility_oracle): how many test triplets
# the views can decide at all; a diagnostic unit, no method
COVISIBILITY = "covisibility-oracle"
SEANNET = "seannet-fc512"  # SeanNet as the default preset trains it (the paper's fc: `seannet`)
# The headline: SeanNet, the strongest simple baseline (resnet18+boxes) and every baseline the
# leaderboard holds; SeanNet and the strongest baseline on 5 seeds, the rest on 3.
HEADLINE = (
    Row(SEANNET, seeds=5, noise=True, full_map=True),
    Row("resnet18+boxes", seeds=5, noise=True),
    Row("resnet18", seeds=3, full_map=True),
    Row(f"{SEANNET}+boxes", seeds=3),
    Row(f"{SEANNET}+box-kernel", seeds=3),
    Row("resnet18+box-kernel", seeds=3),
    Row("lite0-gem", seeds=1),
    Row("lite0-gem-head", seeds=3),
    Row("tiny-image", seeds=1),
    Row("boxes-kernel", seeds=3),
)
FC = (Row("seannet", seeds=3, stage=1),)  # the paper's GCN fc, 4,096 wide, against fc512
ABLATIONS = (
    Row("seannet-image", stage=1),
    Row("seannet-nolayout", stage=1),
    Row("seannet-graph", stage=1),
)
CURVE_METHODS = (SEANNET, "resnet18+boxes", f"{SEANNET}+box-kernel")

# Table II: SeanNet, its box-kernel fusion (the best localizer of docs/navigation.md), the
# strongest simple baseline, and the image-only floor, as localizers of the oracle navigator
NAVIGATION_TEST = NavigationDesign(
    methods=(SEANNET, f"{SEANNET}+box-kernel", "resnet18+boxes", "tiny-image")
)

DESIGN = Design(
    rows=HEADLINE + FC + ABLATIONS,
    curve_methods=CURVE_METHODS,
    curve=((150.0, 3), (600.0, 3), (1200.0, 1)),
    diagnostics=(COVISIBILITY,),
    navigation=NAVIGATION_TEST,
)
