"""Cosine similarity and the triplet loss, with the (A, P, N) argument order."""

from __future__ import annotations

import pytest
import torch

from seannet import ModelError, TripletLoss, similarity


def test_similarity_is_cosine() -> None:
    a = torch.tensor([[1.0, 0.0], [3.0, 4.0]])
    b = torch.tensor([[2.0, 0.0], [4.0, -3.0]])
    torch.testing.assert_close(similarity(a, b), torch.tensor([1.0, 0.0]))
    torch.testing.assert_close(similarity(a, -a), torch.tensor([-1.0, -1.0]))


def test_loss_is_exactly_zero_when_the_margin_holds() -> None:
    loss = TripletLoss(margin=0.1)
    a = torch.tensor([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    p = a.clone()  # S(A, P) = 1
    n = torch.tensor([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])  # S(A, N) = 0
    out = loss(a, p, n)
    assert out.item() == 0.0
    # margin just holds: S(A,P) - S(A,N) = 0.2 > 0.1
    p2 = torch.tensor([[1.0, 0.0, 0.0]])
    n2 = torch.tensor([[0.8, 0.6, 0.0]])  # S = 0.8
    assert loss(p2, p2, n2).item() == 0.0


def test_loss_is_positive_otherwise_and_mean_over_batch() -> None:
    loss = TripletLoss(margin=0.1)
    a = torch.tensor([[1.0, 0.0], [1.0, 0.0]])
    p = torch.tensor([[1.0, 0.0], [0.6, 0.8]])  # S(A,P) = 1, 0.6
    n = torch.tensor([[0.0, 1.0], [0.8, 0.6]])  # S(A,N) = 0, 0.8
    per = TripletLoss(margin=0.1, reduction="none")(a, p, n)
    torch.testing.assert_close(per, torch.tensor([0.0, 0.8 + 0.1 - 0.6]))
    torch.testing.assert_close(loss(a, p, n), per.mean())


def test_swapping_positive_and_negative_is_penalised() -> None:
    """The authors' baselines were fed (A, N, P): a perfect triplet then costs 1 + margin."""
    loss = TripletLoss(margin=0.1)
    a = torch.randn(4, 16)
    p = a * 2.0  # same direction: perfect positive
    n = torch.linalg.qr(torch.stack([a[0], torch.randn(16)], 1)).Q[:, 1].expand(4, 16)
    n = n - (n * a).sum(1, keepdim=True) / (a * a).sum(1, keepdim=True) * a  # orthogonal to A
    assert loss(a, p, n).item() == pytest.approx(0.0, abs=1e-6)
    assert loss(a, n, p).item() == pytest.approx(1.1, abs=1e-5)


def test_loss_checks() -> None:
    with pytest.raises(ModelError, match="margin=-0.1"):
        TripletLoss(margin=-0.1)
    with pytest.raises(ModelError, match="reduction='max'"):
        TripletLoss(reduction="max")
    with pytest.raises(ModelError, match="shapes differ"):
        TripletLoss()(torch.zeros(2, 3), torch.zeros(2, 3), torch.zeros(2, 4))
