import numpy as np
import pytest

from fluidymation.engine.random import counter_hash, random_below


def test_hash_is_a_pure_function_of_seed_and_counters():
    assert counter_hash(3, 1, 2, 3) == counter_hash(3, 1, 2, 3)
    values = {int(counter_hash(seed, a, b)) for seed in range(3) for a in range(3) for b in range(3)}
    assert len(values) == 27


def test_random_below_is_roughly_uniform():
    draws = np.array([random_below(7, (1, 2), k, 10) for k in range(5000)])
    assert draws.min() == 0 and draws.max() == 9
    counts = np.bincount(draws, minlength=10)
    chi2 = ((counts - 500.0) ** 2 / 500.0).sum()
    assert chi2 < 30  # 9 degrees of freedom; p ≈ 0.0004


def test_rejects_negative_counters():
    with pytest.raises(ValueError):
        counter_hash(0, -1)
