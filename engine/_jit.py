"""The one place that sets numba's compilation flags for every kernel.

``kernel`` compiles serial code; ``parallel_kernel`` adds ``prange`` support;
``inline_kernel`` is a ``kernel`` inlined into its callers. All are
cached on disk (``NUMBA_CACHE_DIR`` selects where) and use fastmath. Kernels that run
in parallel must write disjoint slices so results do not depend on the thread count.
``prefetch`` asks the CPU to start loading an array element's cache line.
``threads_for`` runs the parallel kernels of small jobs on one thread.
"""

import contextlib

import numba
from llvmlite import binding as llvm
from llvmlite import ir
from numba import types
from numba.core import cgutils, codegen
from numba.extending import intrinsic


def _optimize_with_own_copies(library, _optimize=codegen.CPUCodeLibrary._optimize_final_module):
    """Bind each library's calls to its own copies of the kernels it links in.

    Numba links a copy of every called kernel (and of every ``prange`` body) into the
    caller's module as a weak (``linkonce_odr``, ``weak_odr``) definition and optimizes it again there; the
    JIT then binds a call to whichever definition of the name it loaded first: the callee's
    own code after a fresh compilation, the caller's copy when the caller comes from the disk
    cache. With fastmath's ``reassoc`` the two may round differently, so results differed in
    the last bits between a fresh and a cached process. Made internal, the copies are always
    the code that runs, the same code as the cached object.
    """
    linked = {
        function.name
        for linked_library in library._linking_libraries
        for function in linked_library._get_module_for_linking().functions
        if not function.is_declaration
    }
    for function in library._final_module.functions:
        if function.name in linked and not function.is_declaration:
            function.linkage = llvm.Linkage.internal
    _optimize(library)


codegen.CPUCodeLibrary._optimize_final_module = _optimize_with_own_copies

kernel = numba.njit(cache=True, fastmath=True, nogil=True)
parallel_kernel = numba.njit(cache=True, fastmath=True, nogil=True, parallel=True)
#: A ``kernel`` copied into each caller (no call with dozens of array fields per use;
#: longer compilation): for small functions called in the innermost loops.
inline_kernel = numba.njit(cache=True, fastmath=True, nogil=True, inline="always")


@intrinsic
def prefetch(typingctx, array, index):
    """Hint that ``array.ravel()[index]`` (C-contiguous ``array``) will soon be read."""
    if not isinstance(array, types.Array) or array.layout != "C" or not isinstance(index, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        offset = context.cast(builder, args[1], signature.args[1], types.intp)
        address = builder.bitcast(builder.gep(data, [offset]), ir.IntType(8).as_pointer())
        function_type = ir.FunctionType(ir.VoidType(), [address.type] + [ir.IntType(32)] * 3)
        function = cgutils.get_or_insert_function(builder.module, function_type, "llvm.prefetch.p0")
        read, keep_in_all_caches, data_cache = (ir.Constant(ir.IntType(32), value) for value in (0, 3, 1))
        builder.call(function, [address, read, keep_in_all_caches, data_cache])
        return context.get_dummy_value()

    return types.void(array, index), codegen


#: Jobs over fewer pixels run their parallel kernels on one thread: on the shared 2-core
#: machine a parallel region waits for its slowest thread, which then often waits for a
#: busy core (measured: a 38×32 PatchMatch pass 8.8 ms on two threads, 1.7 ms on one).
SERIAL_BELOW_PIXELS = 1 << 15


@contextlib.contextmanager
def threads_for(pixels):
    """Within the block, parallel kernels use one thread when ``pixels < SERIAL_BELOW_PIXELS``
    (results do not depend on the thread count)."""
    if pixels >= SERIAL_BELOW_PIXELS:
        yield
        return
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(previous)
