"""Counter-based random numbers: a hash of (seed, counters...), never a shared generator.

Every random decision in the engine is a pure function of the seed and of where it is
made (pyramid level, iteration, pixel, candidate number), so results do not depend on
the order in which threads visit pixels or on how many threads there are. The mixing
function is the SplitMix64 finalizer.
"""

import numpy as np

from fluidymation.engine._jit import kernel

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX_A = np.uint64(0xBF58476D1CE4E5B9)
_MIX_B = np.uint64(0x94D049BB133111EB)
_SHIFT_A = np.uint64(30)
_SHIFT_B = np.uint64(27)
_SHIFT_C = np.uint64(31)
_MANTISSA_SHIFT = np.uint64(11)


@kernel
def _mix64(value):
    value = (value ^ (value >> _SHIFT_A)) * _MIX_A
    value = (value ^ (value >> _SHIFT_B)) * _MIX_B
    return value ^ (value >> _SHIFT_C)


@kernel
def _combine(key, counter):
    """Hash ``counter`` (a non-negative integer) into ``key`` (a uint64)."""
    return _mix64(key ^ (np.uint64(counter) * _GOLDEN + _GOLDEN))


@kernel
def _key4(seed, a, b, c):
    """A uint64 key from a seed and three non-negative counters."""
    return _combine(_combine(_combine(_combine(np.uint64(0), seed), a), b), c)


@kernel
def _random_below(key, counter, bound):
    """Uniform integer in ``[0, bound)`` for draw number ``counter`` under ``key``."""
    return np.int64((_combine(key, counter) >> _MANTISSA_SHIFT) % np.uint64(bound))


def counter_hash(seed, *counters):
    """Hash a seed and non-negative integer counters into a uint64.

    Parameters
    ----------
    seed : int
        Non-negative seed.
    *counters : int
        Up to three non-negative counters (missing ones count as 0).

    Returns
    -------
    numpy.uint64
    """
    values = [int(seed), *map(int, counters)]
    if len(values) > 4 or min(values) < 0:
        raise ValueError("counter_hash takes a non-negative seed and at most three non-negative counters")
    values += [0] * (4 - len(values))
    return np.uint64(_key4(*values))


def random_below(seed, counters, draw, bound):
    """Uniform integer in ``[0, bound)`` for draw ``draw`` under ``(seed, *counters)``."""
    if bound < 1:
        raise ValueError(f"bound must be positive, got {bound}")
    return int(_random_below(counter_hash(seed, *counters), int(draw), int(bound)))
