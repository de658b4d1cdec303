"""Sorting inside kernels, without numba's own sort: :func:`argsort_prefix`.

numba compiles its quicksort anew for every element type, about 1.6 s each on a first run
(two of them made 3.3 s of the quick start's compilation, docs/performance.md). This heap
sort is a few lines and compiles in a fraction of that. Kernels sort short runs with it
(a block's keys, a scanline's crossings), where the sort's speed does not matter.
"""

from fluidymation.engine._jit import inline_kernel, kernel


@kernel
def argsort_prefix(values, count, order):
    """Fill ``order[:count]`` with the indices that sort ``values[:count]`` ascending (ties in index
    order, as a stable sort leaves them)."""
    for index in range(count):
        order[index] = index
    for start in range(count // 2 - 1, -1, -1):
        _sift_down_indices(values, order, start, count)
    for end in range(count - 1, 0, -1):
        order[0], order[end] = order[end], order[0]
        _sift_down_indices(values, order, 0, end)


@inline_kernel
def _before(values, first, second):
    """Whether index ``first`` sorts before ``second``: by value, then by index."""
    return values[first] < values[second] or (values[first] == values[second] and first < second)


@inline_kernel
def _sift_down_indices(values, order, root, end):
    while True:
        child = 2 * root + 1
        if child >= end:
            return
        if child + 1 < end and _before(values, order[child], order[child + 1]):
            child += 1
        if not _before(values, order[root], order[child]):
            return
        order[root], order[child] = order[child], order[root]
        root = child
