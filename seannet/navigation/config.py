"""The navigation stage's settings and their defaults, in one place: the visual navigator's
(``NavigatorConfig``) and the navigation test's (``NavigationTestConfig``).

Plain frozen dataclasses importing no torch, so the CLI and the bench scripts read their
defaults from here (``NavigationTestConfig().episodes``) instead of typing them again.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from seannet.errors import ModelError, NavigationError
from seannet.weights import IMAGE_ENCODERS

__all__ = [
    "FUSIONS",
    "K_MAX",
    "MAP_MEMORY",
    "MAP_SPACING",
    "RULES",
    "STOP_POLICY_VAL_EPISODES",
    "NavigationTestConfig",
    "NavigatorConfig",
]

K_MAX = 12  # steps per segment (paper §VI-B)
MAP_SPACING = 2  # cells between map nodes: the authors' maps (1: every reachable cell)
FUSIONS = ("early", "late")  # NavigatorConfig.fusion
# how an episode's collision is judged: the paper's (it ends the episode) and, beyond the
# paper, bump and replan (the robot stays, the map path is planned again from where it stands)
RULES = ("paper", "replan")
# val episodes per case and room a stop policy is chosen on (seannet navigate --stop-policy):
# 400 per case on medium's 8 val rooms
STOP_POLICY_VAL_EPISODES = 50
# beyond the paper, a map that learns the layout it is in: a sub-node's stored embedding is
# replaced by the current view's when a stop rule stops on it, for the rest of the episode or
# for every later episode of the task in the same layout (NavigationTestConfig.map_memory)
MAP_MEMORY = ("off", "episode", "layout")


@dataclass(frozen=True)
class NavigatorConfig:
    """Everything a navigator run depends on; stored in its checkpoints."""

    encoder: str = "resnet18"  # torchvision image encoder (the paper: VGG-16)
    # "early": the two views stacked as six input channels, so the first convolution already
    # compares them pixel by pixel (what a relative-pose answer needs); "late": a siamese
    # encoder whose pooled features are concatenated (it must say where things are in a
    # vector that pooling has made blind to position)
    fusion: str = "early"
    image_size: int = 96  # square input (64..112 keeps a CPU run short)
    hidden: int = 256  # MLP width after the concatenated features
    epochs: int = 10
    batch_size: int = 32
    lr: float = 0.01  # SGD, as the authors
    momentum: float = 0.9
    train_pairs: int = 2000  # pairs rendered from the train rooms (all epochs reuse them)
    val_pairs: int = 400  # from the val rooms: accuracy every epoch picks best.pt
    max_side: int = 2  # goal within +-max_side cells sideways ...
    max_forward: int = 4  # ... and 0..max_forward cells forward
    # What the test changes: its goal is the map's view of layout 0 while the robot walks in
    # another layout (moved objects, their looks, the light). Share of pairs whose goal view
    # is rendered in another layout of the room than the current view (train and val alike):
    cross_layout: float = 0.0
    jitter: float = 0.0  # train-time brightness and contrast jitter, +- this share, per view
    seed: int = 0

    def __post_init__(self) -> None:
        if self.encoder not in IMAGE_ENCODERS:
            raise ModelError(
                f"navigator.encoder {self.encoder!r}: expected one of {', '.join(IMAGE_ENCODERS)}"
            )
        if self.fusion not in FUSIONS:
            raise ModelError(
                f"navigator.fusion {self.fusion!r}: expected one of {', '.join(FUSIONS)}"
            )
        for name in ("image_size", "hidden", "epochs", "batch_size", "train_pairs"):
            if getattr(self, name) < 1:
                raise ModelError(f"navigator.{name} must be >= 1, got {getattr(self, name)}")
        if self.image_size < 32:
            raise ModelError(f"navigator.image_size {self.image_size}: expected >= 32 pixels")
        if self.val_pairs < 0 or self.max_side < 0 or self.max_forward < 0:
            raise ModelError("navigator: val_pairs, max_side and max_forward must be >= 0")
        if self.max_side + self.max_forward < 1:
            raise ModelError("navigator: max_side + max_forward must be >= 1 (a goal must move)")
        if not 0 <= self.cross_layout <= 1 or not 0 <= self.jitter < 1:
            raise ModelError(
                f"navigator: cross_layout {self.cross_layout} must be within [0, 1], "
                f"jitter {self.jitter} within [0, 1)"
            )
        if self.lr <= 0 or not 0 <= self.momentum < 1:
            raise ModelError(f"navigator: lr {self.lr} must be > 0, momentum within [0, 1)")

    def replace(self, **changes: Any) -> NavigatorConfig:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class NavigationTestConfig:
    """What the navigation test's episodes depend on (paper §VI-B, Table II); stored in its
    results, and with the run, the room and the case, the key a finished part is reused by."""

    split: str = "test"  # the rooms episodes run in
    episodes: int = 20  # per case (N, A) and room
    seed: int = 0  # of the episodes (seannet.seeds.episode_seed)
    k_max: int = K_MAX  # steps per segment
    spacing: int = MAP_SPACING  # cells between map nodes
    replan: bool = False  # also run bump and replan (its paper-rule outcome read off the same run)
    # trace every segment for stop rules judged offline (seannet.navigation.stopping); its
    # paper-rule outcome is the one a plain run has
    trace: bool = False
    # MAP_MEMORY: with chosen stop rules only (run_navigation's stop_rules)
    map_memory: str = "off"

    def __post_init__(self) -> None:
        if self.episodes < 1:
            raise NavigationError(f"--episodes {self.episodes}: expected >= 1 per case and room")
        if self.k_max < 1:
            raise NavigationError(f"k_max {self.k_max}: expected >= 1 step per segment")
        if self.spacing < 1:
            raise NavigationError(f"--spacing {self.spacing}: expected >= 1 cell")
        if self.trace and self.replan:
            raise NavigationError("a traced test is judged under the paper's rule: no --replan")
        if self.map_memory not in MAP_MEMORY:
            raise NavigationError(
                f"--map-memory {self.map_memory}: expected one of {', '.join(MAP_MEMORY)}"
            )

    @property
    def rules(self) -> tuple[str, ...]:
        """The rules its results hold (:data:`RULES`)."""
        return RULES if self.replan else RULES[:1]

    def replace(self, **changes: Any) -> NavigationTestConfig:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def settings(self) -> dict[str, Any]:
        """The fields under the names results files have always used (the part key's)."""
        return {
            "split": self.split,
            "episodes_per_case_and_room": self.episodes,
            "seed": self.seed,
            "k_max": self.k_max,
            "spacing": self.spacing,
            "replan": self.replan,
            "trace": self.trace,
            # beyond the paper: named only when set, so older results keep their keys
            **({"map_memory": self.map_memory} if self.map_memory != "off" else {}),
        }

    @classmethod
    def from_results(cls, results: dict[str, Any]) -> NavigationTestConfig:
        """The config a results file was made with (:meth:`settings`' names)."""
        return cls(
            split=results["split"],
            episodes=results["episodes_per_case_and_room"],
            seed=results["seed"],
            k_max=results["k_max"],
            spacing=results["spacing"],
            replan=bool(results.get("replan", False)),
            trace=bool(results.get("trace", False)),
            map_memory=results.get("map_memory", "off"),
        )
