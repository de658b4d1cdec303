"""engine/_jit.py's ``borrowed`` (the same arrays, without reference counting, and nothing leaked) and
``run_parts`` (every item done once, by the part that owns it, on any thread count)."""

import numba
import numpy as np
import pytest
from numba.core.errors import TypingError
from numba.core.runtime import _nrt_python, rtsys

from fluidymation.engine._jit import borrowed, kernel, run_parts


@kernel
def _add_through_borrowed(values, out, offset):
    """``out[i] = values[i] + offset`` through borrowed views, the scalar passed along in the tuple."""
    values, out, offset = borrowed((values, out, offset))
    for index in range(values.shape[0]):
        out[index] = values[index] + offset


@kernel
def _sum_of_local_copy(values):
    """A kernel-allocated array borrowed and sliced; it is still freed once."""
    local = values.copy()
    view = borrowed(local)[1:]
    return view.sum() + local[0]


@kernel
def _borrow_scalar(value):
    return borrowed(value)


def test_borrowed_arrays_are_the_callers_memory():
    values = np.arange(5, dtype=np.float32)
    out = np.zeros(5, np.float32)
    _add_through_borrowed(values, out, np.float32(2.0))
    np.testing.assert_array_equal(out, values + 2.0)


def test_borrowing_leaks_and_frees_nothing():
    values = np.arange(6, dtype=np.float64)
    _sum_of_local_copy(values)  # compile first: compilation allocates too
    _nrt_python.memsys_enable_stats()
    try:
        before = rtsys.get_allocation_stats()
        for _ in range(10):
            assert _sum_of_local_copy(values) == values.sum()
        after = rtsys.get_allocation_stats()
    finally:
        _nrt_python.memsys_disable_stats()
    allocated, freed = after.mi_alloc - before.mi_alloc, after.mi_free - before.mi_free
    assert allocated >= 10  # one copy per call at least (the unboxed argument may count too)
    assert freed == allocated
    assert after.free - before.free == after.alloc - before.alloc


def test_borrowed_refuses_values_without_arrays():
    with pytest.raises(TypingError):
        _borrow_scalar(1.0)


@kernel
def _mark_items(owner, part, parts):
    """``owner[i] += part + 1`` for the items ``part, part + parts, …``; returns how many it did."""
    done = 0
    for index in range(part, owner.shape[0], parts):
        owner[index] += part + 1
        done += 1
    return done


@pytest.mark.parametrize("threads", [1, min(2, numba.config.NUMBA_NUM_THREADS)])
def test_run_parts_does_every_item_once_per_part(threads):
    previous = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        owner = np.zeros(7, np.int64)
        done = run_parts(_mark_items, owner)
    finally:
        numba.set_num_threads(previous)
    assert len(done) == threads and sum(done) == 7
    assert owner.tolist() == [index % threads + 1 for index in range(7)]
