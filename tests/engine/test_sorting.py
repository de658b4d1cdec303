"""engine/sorting.py's heap sort against numpy's stable argsort."""

import numpy as np
import pytest

from fluidymation.engine.sorting import argsort_prefix


@pytest.mark.parametrize("count", [0, 1, 2, 9, 100])
def test_argsort_prefix_is_a_stable_argsort(count):
    rng = np.random.default_rng(count)
    values = np.round(rng.normal(size=120), 1)  # many ties: their indices must stay in order
    order = np.full(120, -1, np.int64)
    argsort_prefix(values, count, order)
    np.testing.assert_array_equal(order[:count], np.argsort(values[:count], kind="stable"))
    assert (order[count:] == -1).all()
