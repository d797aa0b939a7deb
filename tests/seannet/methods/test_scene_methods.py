"""The methods with a scene term (``boxes-*``, ``MODEL+boxes``, ``MODEL+box-kernel``) hold one
:class:`SceneTerm`: its state is plain data, and a method pickled before it still opens."""

from __future__ import annotations

import io

import pytest
import torch

from seannet.evaluation.box_kernel import BoxKernel
from seannet.evaluation.scene_term import SceneTerm
from seannet.methods.boxes import box_scores, box_vectors
from seannet.methods.bundled import NetworkMethod
from seannet.methods.reference import BoxKernelMethod

SLOTS = 5


def _box_vectors(views: int, seed: int) -> torch.Tensor:
    """(views, 4 SLOTS) box vectors: each slot present with probability 0.7."""
    g = torch.Generator().manual_seed(seed)
    lo = torch.rand(views, SLOTS, 2, generator=g) * 0.6
    boxes = torch.cat([lo, lo + 0.05 + 0.3 * torch.rand(views, SLOTS, 2, generator=g)], dim=2)
    boxes[torch.rand(views, SLOTS, generator=g) > 0.7] = float("nan")
    return box_vectors(boxes)


def _kernel() -> BoxKernel:
    kernel = BoxKernel(SLOTS)
    with torch.no_grad():
        kernel.slot_weight.copy_(torch.linspace(-1.0, 1.0, SLOTS))
    return kernel.eval()


def _reopened(obj: object) -> object:
    buffer = io.BytesIO()
    torch.save(obj, buffer)
    return torch.load(io.BytesIO(buffer.getvalue()), weights_only=False)


def test_a_box_kernel_method_state_is_its_scene_term_as_plain_data() -> None:
    method = BoxKernelMethod()
    method.scene = SceneTerm("+box-kernel", _kernel(), choices={"box_kernel": {"x": 1}})
    state = method.state_dict()
    buffer = io.BytesIO()
    torch.save(state, buffer)
    plain = torch.load(io.BytesIO(buffer.getvalue()), weights_only=True)  # no class pickled
    again = BoxKernelMethod()
    again.load_state_dict(plain)
    a, b = _box_vectors(30, 0), _box_vectors(30, 1)
    assert torch.equal(again.similarity(a, b), method.similarity(a, b))
    assert again.scene.choices == {"box_kernel": {"x": 1}} and again.kernel is not None
    assert not torch.equal(method.similarity(a, b), box_scores(a, b, SceneTerm("+boxes")).float())


def test_a_method_pickled_before_the_scene_term_opens() -> None:
    # boxes-kernel held its kernel itself
    old = BoxKernelMethod.__new__(BoxKernelMethod)
    old.__dict__["kernel"] = _kernel()
    opened = _reopened(old)
    assert opened.scene.term == "+box-kernel" and opened.kernel is not None
    a, b = _box_vectors(20, 2), _box_vectors(20, 3)
    assert torch.equal(
        opened.similarity(a, b), box_scores(a, b, SceneTerm("+box-kernel", _kernel())).float()
    )
    # a network held lambda and the kernel itself; its similarity is the same formula
    network = NetworkMethod("resnet18+boxes")
    network.__dict__.pop("scene")
    network.__dict__.update(box_weight=0.5, kernel=None, _dim=3)
    opened = _reopened(network)
    assert opened.scene == SceneTerm("+boxes", None, 0.5) and opened.box_weight == 0.5
    unit = torch.nn.functional.normalize(torch.randn(20, 3), dim=1)
    va, vb = torch.cat([unit, a], dim=1), torch.cat([unit.flip(0), b], dim=1)
    s = (unit * unit.flip(0)).sum(1).double()
    want = (s + 0.5 * box_scores(a, b, SceneTerm("+boxes"))) / 1.5
    assert opened.similarity(va, vb) == pytest.approx(want, abs=1e-12)
    assert opened.similarity(va, vb).abs().max() <= 1.0
