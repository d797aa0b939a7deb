"""A user's localization method for `seannet benchmark`: a colour histogram plus box overlap.

seannet benchmark --data ROOT --methods examples/custom_method.py:ColourBoxes --out cards/
"""

import torch
import torch.nn.functional as F


class ColourBoxes:
    uses_boxes = True  # the box-noise sweep applies
    image_size = 64  # views arrive as 64 x 64 pixels

    def embed(self, views):
        bins = (views.images.long() // 64).flatten(2)  # 4 levels per channel
        codes = bins[:, 0] * 16 + bins[:, 1] * 4 + bins[:, 2]  # (N, H * W) of 64 colours
        hist = F.normalize(F.one_hot(codes, 64).sum(1).float(), dim=1)
        boxes = torch.nan_to_num(views.slot_boxes(), nan=-1.0).flatten(1)
        return torch.cat([hist, boxes], dim=1)

    def similarity(self, a, b):
        colour = (a[:, :64] * b[:, :64]).sum(1)
        ba, bb = a[:, 64:].view(len(a), -1, 4), b[:, 64:].view(len(b), -1, 4)
        both = (ba[..., 0] >= 0) & (bb[..., 0] >= 0)
        either = ((ba[..., 0] >= 0) | (bb[..., 0] >= 0)).sum(1).clamp_min(1)
        lo, hi = torch.maximum(ba[..., :2], bb[..., :2]), torch.minimum(ba[..., 2:], bb[..., 2:])
        inter = (hi - lo).clamp_min(0).prod(-1)
        area = lambda x: (x[..., 2:] - x[..., :2]).prod(-1)  # noqa: E731
        iou = torch.where(both, inter / (area(ba) + area(bb) - inter).clamp_min(1e-9), 0)
        return 0.5 * colour + 0.5 * iou.sum(1) / either
