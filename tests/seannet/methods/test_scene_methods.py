"""The methods with a scene term (``boxes-*``, ``MODEL+boxes``, ``MODEL+box-kernel``) hold one
:class:`SceneTerm`: its state is plain data."""

from __future__ import annotations

import io

import torch

from seannet.evaluation.box_kernel import BoxKernel
from seannet.evaluation.scene_term import SceneTerm
from seannet.methods.boxes import box_scores, box_vectors
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
    assert again.scene.choices == {"box_kernel": {"x": 1}} and again.scene.kernel is not None
    assert not torch.equal(method.similarity(a, b), box_scores(a, b, SceneTerm("+boxes")).float())
