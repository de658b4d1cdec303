import numpy as np

from fluidymation.engine.nnf import NNF
from fluidymation.engine.vote import vote
from tests.naive import naive_vote


def test_vote_matches_naive_with_rotations_and_holes():
    rng = np.random.default_rng(2)
    source = rng.random((2, 9, 8, 3)).astype(np.float32)
    frame = rng.integers(0, 2, (6, 7)).astype(np.int32)
    frame[0, 0] = -1
    frame[3, 4] = -1
    coords = np.stack(
        [rng.integers(0, 8, (6, 7)), rng.integers(0, 9, (6, 7)), np.zeros((6, 7))], axis=2
    ).astype(np.float32)
    coords[1::2, :, 0] += 0.37
    coords[:, 1::3, 2] = rng.uniform(-3, 3, (6, 7))[:, 1::3]
    image, coverage = vote(source, NNF(frame, coords), patch_size=5)
    np.testing.assert_allclose(image, naive_vote(source, frame, coords, 5), atol=2e-5)
    assert coverage[3, 3] == 24 and coverage[0, 6] == 9


def test_identity_field_votes_the_source_back():
    source = np.random.default_rng(3).random((1, 6, 7, 2)).astype(np.float32)
    ys, xs = np.mgrid[0:6, 0:7]
    field = NNF(np.zeros((6, 7), np.int32), np.stack([xs, ys, np.zeros_like(xs)], 2).astype(np.float32))
    image, _ = vote(source, field, patch_size=3)
    np.testing.assert_allclose(image, source[0], atol=1e-6)
