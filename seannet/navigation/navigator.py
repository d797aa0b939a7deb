"""The visual navigator (paper §VI-B, after SPTM): forward / left / right from two views.

The network and what it learns from: its config, the label rule and the draw of a training
pair (the authors: goal within +-2 cells sideways and 0..4 cells forward of the current pose,
same heading; the label is the larger displacement). Rendering pairs is in
:mod:`seannet.navigation.pairs`, training in :mod:`seannet.navigation.navigator_training`;
:class:`Policy` acts with a trained one.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import torch
from torch import Tensor, nn

from seannet.data.batch import normalise_pixels
from seannet.data.view_inputs import ImageTransform
from seannet.errors import CheckpointError, ModelError
from seannet.model.backbones import image_encoder
from seannet.navigation.config import FUSIONS, NavigatorConfig
from seannet.navigation.motion import FORWARD, HEADINGS, NAVIGATOR_ACTIONS, local_offset
from seannet.training.runs import BEST, device_for_run, load_checkpoint
from seannet.weights import normalisation

__all__ = [
    "KIND",
    "NavigatorConfig",
    "Policy",
    "VisualNavigator",
    "draw_pair",
    "label_for",
    "load_navigator",
    "navigator_inputs",
    "resize",
]

KIND = "navigator"  # checkpoints say what they hold: a localizer run is refused here


def resize(rgb: np.ndarray, size: int) -> np.ndarray:
    """(H, W, 3) uint8 -> (size, size, 3) uint8, resampled as the localizers' views are."""
    return ImageTransform(size).resize(rgb, _NO_BOXES)[0]


def navigator_inputs(images: np.ndarray, encoder: str = "resnet18") -> Tensor:
    """(B, S, S, 3) uint8 -> (B, 3, S, S) float32 normalised as ``encoder``'s ImageNet
    weights saw their pixels (EfficientNet-Lite0's differ from torchvision's)."""
    pixels = torch.from_numpy(np.array(images, dtype=np.uint8)).permute(0, 3, 1, 2)
    return normalise_pixels(pixels, *normalisation(encoder))


_NO_BOXES = np.zeros((0, 4), dtype=np.float32)


class VisualNavigator(nn.Module):
    r"""A siamese classifier of the action that brings the current view towards the goal view.

    After SPTM's locomotion network (Savinov et al., arXiv 1803.00653) as the paper uses it
    (§VI-B): one image encoder shared by both views, the two feature vectors concatenated,
    then ``Linear -> ReLU -> Linear`` to logits over
    :data:`seannet.navigation.motion.NAVIGATOR_ACTIONS`
    (forward, left, right: translations of one cell).

    Args:
        encoder: a name of :data:`seannet.model.backbones.ENCODER_NAMES` (default ``"resnet18"``).
        hidden: MLP width (default 256).
        pretrained: optional local ImageNet weights of ``encoder`` (SHA-256 checked).

    Shapes:
        - **current**, **goal**: :math:`(B, 3, S, S)` normalised images
        - **output**: :math:`(B, 3)` logits
    """

    def __init__(
        self,
        encoder: str = "resnet18",
        *,
        hidden: int = 256,
        pretrained: Path | None = None,
        fusion: str = "early",
    ) -> None:
        super().__init__()
        if fusion not in FUSIONS:
            raise ModelError(f"navigator fusion {fusion!r}: expected one of {', '.join(FUSIONS)}")
        self.encoder_name, self.fusion = encoder, fusion
        self.encoder, width = image_encoder(encoder, pretrained=pretrained)
        if fusion == "early":
            _stack_inputs(self.encoder)
        self.head = nn.Sequential(
            nn.Linear(width if fusion == "early" else 2 * width, hidden),
            nn.ReLU(inplace=True),
            nn.Linear(hidden, len(NAVIGATOR_ACTIONS)),
        )

    def forward(self, current: Tensor, goal: Tensor) -> Tensor:
        if current.shape != goal.shape:
            raise ModelError(
                f"navigator views differ: {tuple(current.shape)} vs {tuple(goal.shape)}"
            )
        if self.fusion == "early":
            return self.head(self.encoder(torch.cat([current, goal], dim=1)))
        features = self.encoder(torch.cat([current, goal]))  # one pass, shared weights
        a, b = features.chunk(2)
        return self.head(torch.cat([a, b], dim=1))

    def extra_repr(self) -> str:
        return f"encoder={self.encoder_name!r}, fusion={self.fusion!r}"


def _stack_inputs(encoder: nn.Module) -> None:
    """Widen ``encoder``'s first 3-channel convolution to take two stacked RGB views.

    Each view's half starts as half the old kernel, so an ImageNet-initialised encoder sees
    the mean of the two views at first and loses nothing of what its weights learned.

    Raises:
        ModelError: the encoder has no 3-channel convolution.
    """
    for parent in encoder.modules():
        for name, child in parent.named_children():
            if isinstance(child, nn.Conv2d) and child.in_channels == 3:
                wide = copy.deepcopy(child)  # keeps its class (e.g. Lite0's "same" padding)
                wide.in_channels = 6
                with torch.no_grad():
                    wide.weight = nn.Parameter(torch.cat([child.weight, child.weight], 1) / 2)
                setattr(parent, name, wide)
                return
    raise ModelError("navigator: the encoder has no 3-channel input convolution to widen")


def label_for(forward: int, side: int) -> int:
    """The action index for a goal ``forward`` cells ahead and ``side`` cells to the left
    (negative: right): the larger displacement wins, forward on a tie."""
    if forward >= abs(side):
        return NAVIGATOR_ACTIONS.index("forward")
    return NAVIGATOR_ACTIONS.index("left" if side > 0 else "right")


def draw_pair(
    reachable: np.ndarray,
    rng: np.random.Generator,
    *,
    max_side: int = 2,
    max_forward: int = 4,
    tries: int = 100,
) -> tuple[tuple[int, int, int], tuple[int, int, int], int] | None:
    """A (current, goal, label) draw on a reachable mask (None when ``tries`` draws fail).

    The current pose is a reachable cell and a heading; the goal keeps the heading and lies
    ``0..max_forward`` cells ahead and ``-max_side..max_side`` sideways, not on the same cell,
    on a reachable cell.
    """
    cells = np.argwhere(reachable)
    if not len(cells):
        return None
    nx, ny = reachable.shape
    for _ in range(tries):
        i, j = (int(v) for v in cells[rng.integers(len(cells))])
        h = int(rng.integers(HEADINGS))
        forward = int(rng.integers(0, max_forward + 1))
        side = int(rng.integers(-max_side, max_side + 1))
        if forward == 0 and side == 0:
            continue
        (fi, fj), (li, lj) = FORWARD[h], FORWARD[(h + 1) % HEADINGS]
        gi, gj = i + forward * fi + side * li, j + forward * fj + side * lj
        if 0 <= gi < nx and 0 <= gj < ny and reachable[gi, gj]:
            assert local_offset((i, j, h), (gi, gj)) == (forward, side)
            return (i, j, h), (gi, gj, h), label_for(forward, side)
    return None


class Policy:
    """A trained navigator acting on RGB views: :meth:`act` gives an action name."""

    def __init__(self, model: VisualNavigator, config: NavigatorConfig, device: torch.device):
        self.model, self.config, self.device = model.eval(), config, device

    @torch.no_grad()
    def act(self, current: np.ndarray, goal: np.ndarray) -> str:
        """The action (forward / left / right) from (H, W, 3) uint8 current and goal views."""
        s = self.config.image_size
        encoder = self.config.encoder
        a = navigator_inputs(resize(current, s)[None], encoder).to(self.device)
        b = navigator_inputs(resize(goal, s)[None], encoder).to(self.device)
        return NAVIGATOR_ACTIONS[int(self.model(a, b).argmax(1)[0])]


def load_navigator(run: Path) -> Policy:
    """``run/best.pt`` of ``seannet train-navigator`` as a :class:`Policy`.

    Raises:
        CheckpointError: no checkpoint, or not a navigator's.
    """
    path = run / BEST
    state = load_checkpoint(path)
    if state.get("kind") != KIND:
        raise CheckpointError(
            f"{path}: not a navigator checkpoint (train one with train-navigator)"
        )
    # navigators trained before `fusion` existed were siamese
    config = NavigatorConfig(**{"fusion": "late", **state["config"]})
    device = device_for_run()
    model = VisualNavigator(config.encoder, hidden=config.hidden, fusion=config.fusion).to(device)
    model.load_state_dict(state["model"])
    return Policy(model, config, device)
