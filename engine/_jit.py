"""The one place that sets numba's compilation flags for every kernel.

``kernel`` compiles serial code; ``parallel_kernel`` adds ``prange`` support. Both are
cached on disk (``NUMBA_CACHE_DIR`` selects where) and use fastmath. Kernels that run
in parallel must write disjoint slices so results do not depend on the thread count.
"""

import numba

kernel = numba.njit(cache=True, fastmath=True, nogil=True)
parallel_kernel = numba.njit(cache=True, fastmath=True, nogil=True, parallel=True)
