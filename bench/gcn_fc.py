"""The first layer of SeanNet's GCN fc (6144 -> 4096), forward + backward: the dense input
against the runs of used slots (issue 25, item 4).

    OMP_NUM_THREADS=1 python bench/gcn_fc.py [--views 16 2] [--zipf 1.5 1.0 0] [--calls 9]

Synthetic views of 10-30 objects over 107 classes that own 2 slots each (the catalog's 214 of
M = 256), class popularity ~ rank^-zipf (0: uniform, many slots in a batch), a class's
instances filling its slots from the first. For each batch: the pathway outputs scattered to
the dense (B, 6144) vector and ``nn.Linear``'s product (what ``forward_nodes`` did), against
``MultiPathwayGCN.fc_input`` and :class:`ColumnLinear` on its runs (what it does on a CPU);
gradients into W1, b1 and the outputs, checked equal. Times are process CPU seconds, min and
median over ``--calls`` interleaved calls: on a shared machine the wall clock counts other
jobs' work. Measured and dropped before (2 CPUs, one thread, B = 16 / 2): a
``torch.sparse.mm`` of a COO input (3-5x the dense time) and an ``index_select`` of the used
columns (slower than the dense at B = 16: it copies them, the copy and its gradient fresh).
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch
from torch.nn import functional as F

from seannet.model.layers import MultiPathwayGCN

CLASSES, SLOTS_PER_CLASS = 107, 2


def views(num_views: int, zipf: float, seed: int) -> tuple[torch.Tensor, torch.Tensor]:
    """(box_view, slots) of ``num_views`` synthetic views."""
    g = torch.Generator().manual_seed(seed)
    weight = torch.arange(1, CLASSES + 1, dtype=torch.float64) ** -zipf
    box_view, slots = [], []
    for v in range(num_views):
        count = int(torch.randint(10, 31, (1,), generator=g))
        filled: dict[int, int] = {}
        for c in torch.multinomial(weight, count, replacement=True, generator=g).tolist():
            if filled.get(c, 0) < SLOTS_PER_CLASS:
                box_view.append(v)
                slots.append(SLOTS_PER_CLASS * c + filled.get(c, 0))
                filled[c] = filled.get(c, 0) + 1
    return torch.tensor(box_view), torch.tensor(slots)


def dense_form(
    gcn: MultiPathwayGCN, box_view: torch.Tensor, slots: torch.Tensor, out: torch.Tensor, b: int
) -> torch.Tensor:
    """The outputs scattered to the dense (B, R·M·8) vector, then ``nn.Linear``'s product."""
    r, k, first = gcn.num_relations, slots.numel(), gcn.fc[0]
    index = (box_view.repeat(r), torch.arange(r).repeat_interleave(k), slots.repeat(r))
    grid = out.new_zeros(b, r, gcn.num_slots, out.shape[1]).index_put(index, out)
    return F.linear(grid.flatten(1), first.weight, first.bias)


def runs_form(
    gcn: MultiPathwayGCN, box_view: torch.Tensor, slots: torch.Tensor, out: torch.Tensor, b: int
) -> torch.Tensor:
    """What ``forward_nodes`` gives the fc's first layer on a CPU: the runs of used slots."""
    return gcn.fc[0](*gcn.fc_input(out, box_view, slots, num_views=b))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--views", type=int, nargs="+", default=[16, 2])
    parser.add_argument("--zipf", type=float, nargs="+", default=[1.5, 1.0, 0.0])
    parser.add_argument("--calls", type=int, default=9)
    args = parser.parse_args()
    torch.manual_seed(0)
    gcn = MultiPathwayGCN()  # M = 256, pathways to 8, fc 6144 -> 4096 -> 2048
    first, r = gcn.fc[0], gcn.num_relations
    for num_views in args.views:
        for zipf in args.zipf:
            box_view, slots = views(num_views, zipf, seed=num_views)
            k = slots.numel()
            out = torch.randn(r * k, 8).requires_grad_(True)
            upstream = torch.randn(num_views, first.out_features)
            batch = (gcn, box_view, slots, out, num_views)
            forms = {"dense": dense_form, "runs": runs_form}
            grads, seconds = {}, {name: [] for name in forms}
            for call in range(args.calls + 1):  # the first: a warm-up, and the gradients
                for name, form in forms.items():
                    first.zero_grad(set_to_none=True)
                    out.grad = None
                    start = time.process_time()
                    form(*batch).backward(upstream)
                    seconds[name].append(time.process_time() - start)
                    if call == 0:
                        grads[name] = (first.weight.grad, first.bias.grad, out.grad)
            for got, ref in zip(grads["runs"], grads["dense"], strict=True):
                torch.testing.assert_close(got, ref, rtol=1e-4, atol=1e-5)
            x, column_runs = gcn.fc_input(out, box_view, slots, num_views=num_views)
            line = (
                f"B={num_views:2d} zipf={zipf:3.1f} nodes={k:3d} "
                f"slots used={slots.unique().numel():3d} runs={len(column_runs):2d} "
                f"columns read={x.shape[1]:4d} of {first.in_features}:"
            )
            for name in forms:
                times = seconds[name][1:]
                line += (
                    f"  {name} {1000 * min(times):6.1f} / {1000 * statistics.median(times):6.1f}"
                )
            print(line + " ms (min / median)", flush=True)


if __name__ == "__main__":
    main()
