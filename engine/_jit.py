"""The one place that sets numba's compilation flags for every kernel.

``kernel`` compiles serial code; ``inline_kernel`` is a ``kernel`` inlined into its
callers; ``run_parts`` runs a kernel's share of the work on each of a few threads (the
engine has no ``prange``: see its docstring). All are
cached on disk (``NUMBA_CACHE_DIR`` selects where) and use fastmath. Kernels that run
in parts must write disjoint slices so results do not depend on the thread count.
``exact_kernel`` is a ``kernel`` without fastmath, for kernels whose results must not
depend on where numpy happened to allocate their arrays (see its comment).
``prefetch`` asks the CPU to start loading an array element's cache line.
``borrowed`` drops the reference counting of a serial kernel's arrays (see its docstring).
``threads_for`` runs the kernels of small jobs on one thread.
A kernel's disk cache is also keyed to the files of the kernels it calls from other modules.
Loading a cached kernel skips the compiler's registries, and numba's array functions are
imported without scipy.linalg (each saves a fraction of a second of every start).
Processes sharing the disk cache save kernels into it one at a time; ``compiled_elsewhere`` makes
this one wait for, and load, the kernels another process is compiling.
Kernels should not assign an array to a slice (``out[y] = row``, ``out[y] += row``): numba
then compiles a formatted shape-mismatch error, seconds of string code on a first run; loops
assign element by element. They sort with :mod:`fluidymation.engine.sorting`, not numba's sort.
"""

import contextlib
import fcntl
import importlib
import itertools
import os
from concurrent.futures import ThreadPoolExecutor

import numba
from llvmlite import binding as llvm
from llvmlite import ir
from numba import types
from numba.core import caching, cgutils, codegen, event
from numba.core.dispatcher import Dispatcher
from numba.core.runtime import rtsys
from numba.extending import intrinsic
from numba.np import linalg

from fluidymation.engine import compiling


def _optimize_with_own_copies(library, _optimize=codegen.CPUCodeLibrary._optimize_final_module):
    """Bind each library's calls to its own copies of the kernels it links in.

    Numba links a copy of every called kernel into the
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


def _key_cache_to_callees(cache, py_func, _init=caching.CacheImpl.__init__):
    """Key a kernel's disk cache also to the source files of the kernels it calls.

    Numba checks only the kernel's own file, but the cached code holds the kernel's own
    copies of its callees (above): after an edit of engine/patch_cost.py, say, a process
    loading the PatchMatch search from the cache would still run the old patch cost while
    a fresh one compiles the new.
    """
    _init(cache, py_func)
    own_stamp = cache._locator.get_source_stamp
    callee_files = _callee_files(py_func)
    cache._locator.get_source_stamp = lambda: (own_stamp(), *map(_file_stamp, callee_files))


def _callee_files(py_func):
    """The files of the kernels ``py_func``'s module refers to by name, of those their modules
    refer to, and so on; ``py_func``'s own file left out."""
    files = set()
    namespaces = [py_func.__globals__]
    seen = {id(py_func.__globals__)}
    while namespaces:
        for value in list(namespaces.pop().values()):
            if isinstance(value, Dispatcher) and id(value.py_func.__globals__) not in seen:
                seen.add(id(value.py_func.__globals__))
                namespaces.append(value.py_func.__globals__)
                files.add(value.py_func.__code__.co_filename)
    files.discard(py_func.__code__.co_filename)
    return sorted(files)


def _file_stamp(path):
    status = os.stat(path)
    return caching._hash_source_file(path, status.st_mtime, status.st_size)


caching.CacheImpl.__init__ = _key_cache_to_callees


def _load_without_registries(cache, signature, target_context):
    """numba's loading of a cached kernel, without first filling the compiler's registries.

    Numba's loader first refreshes the target context: it imports and installs every typing
    and lowering registry, which only a compilation reads (0.3 s of a cached ``synth``'s first
    kernel call, docs/performance.md). Cached machine code needs only numba's runtime, whose
    functions it calls. A compilation still refreshes the context itself (numba's compiler
    does so before typing), so only processes that compile nothing skip it.
    """
    rtsys.initialize(target_context)
    with cache._guard_against_spurious_io_errors():
        loaded = cache._load_overload(signature, target_context)
        if loaded is None and _wait_if_compiled_elsewhere(cache._py_func.__module__):
            loaded = cache._load_overload(signature, target_context)
        return loaded


caching.Cache.load_overload = _load_without_registries

#: module name → the wait for the process compiling its kernels (:func:`compiled_elsewhere`)
_compiling_elsewhere = {}


@contextlib.contextmanager
def compiled_elsewhere(modules, wait):
    """Within the block, another process compiles the kernels of ``modules`` (module names) into the disk
    cache, and ``wait()`` returns once it has finished (at once afterwards). A kernel of those modules that
    the cache lacks first waits for it and is loaded from the cache; only a kernel it did not save (another
    signature) is compiled here, so the two processes do not compile the same kernels at once.
    """
    _compiling_elsewhere.update(dict.fromkeys(modules, wait))
    try:
        yield
    finally:
        for module in modules:
            _compiling_elsewhere.pop(module, None)


def _wait_if_compiled_elsewhere(module):
    """Wait for the process compiling ``module``'s kernels, if one does; whether one does."""
    wait = _compiling_elsewhere.get(module)
    if wait is None:
        return False
    wait()
    return True


def in_disk_cache(dispatcher):
    """Whether numba's disk cache holds machine code of ``dispatcher`` (any signature) for its current source."""
    return bool(dispatcher._cache._cache_file._load_index())


def _save_one_process_at_a_time(cache_file, key, data):
    """numba's saving of a cache entry, under an exclusive lock of the kernel's index, data before index.

    Numba names a new entry's data file by the first number its index does not list. Two processes
    saving two signatures of one kernel at once (pytest's workers, a render and its compile helper,
    :mod:`fluidymation.pipeline.compile_helper`) read the same index, took the same number, and the index
    kept by the last writer then named the other signature's machine code. One at a time they take
    different numbers; with the data written first, an index entry never names a file still missing.
    """
    with open(cache_file._index_path + ".lock", "ab") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        overloads = cache_file._load_index()
        new = key not in overloads
        if new:
            taken = set(overloads.values())
            overloads[key] = next(name for name in map(cache_file._data_name, itertools.count(1)) if name not in taken)
        cache_file._save_data(overloads[key], data)
        if new:
            cache_file._save_index(overloads)


caching.IndexDataCacheFile.save = _save_one_process_at_a_time


def _import_arraymath_without_blas():
    """Import numba's array functions without importing scipy.linalg.

    ``numba.np.arraymath`` imports scipy.linalg when it is first imported (0.3 s), only to set
    a flag that picks BLAS or a plain loop for ``np.convolve`` and ``np.correlate``, which no
    kernel calls; told there is no BLAS, it would pick the loop. ``np.dot`` and ``np.linalg``
    look for BLAS when a kernel using them is compiled, and still find it.
    """
    ensure_blas = linalg.ensure_blas

    def no_blas():
        raise ImportError("the engine's kernels do not call BLAS (engine/_jit.py)")

    linalg.ensure_blas = no_blas
    try:
        importlib.import_module("numba.np.arraymath")
    finally:
        linalg.ensure_blas = ensure_blas


_import_arraymath_without_blas()


class _CompileEvents(event.Listener):
    """Forwards numba's compilations (not its disk-cache loads) to :mod:`fluidymation.engine.compiling`."""

    def on_start(self, compilation):
        compiling.notify(compilation.data["dispatcher"].py_func.__qualname__, True)

    def on_end(self, compilation):
        compiling.notify(compilation.data["dispatcher"].py_func.__qualname__, False)


event.register("numba:compile", _CompileEvents())


kernel = numba.njit(cache=True, fastmath=True, nogil=True)
#: A ``kernel`` copied into each caller (no call with dozens of array fields per use;
#: longer compilation): for small functions called in the innermost loops.
inline_kernel = numba.njit(cache=True, fastmath=True, nogil=True, inline="always")
#: A ``kernel`` with IEEE arithmetic (no fastmath). LLVM vectorizes a loop that writes one
#: array while reading others behind a run-time check that the accessed address ranges do
#: not overlap, and falls back to the scalar loop when they might (the ranges it checks
#: run past the rows a loop really touches, so an output that numpy allocated right after
#: an input fails the check). With fastmath's ``reassoc`` the vector and the scalar loop
#: round differently, so results depended on the heap layout, which changes with the
#: allocation history of the process (watercolor exemplars differed between two runs in
#: one process, more often on a busy machine). Without fastmath both loops compute the
#: same IEEE operations and give the same bits wherever the arrays are.
exact_kernel = numba.njit(cache=True, nogil=True)


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


@intrinsic
def borrowed(typingctx, value):
    """``value``, an array or a tuple of arrays and scalars, with its arrays' reference counting dropped.

    Numba counts references to every array a kernel passes on or stores, an atomic update of the
    array's count each time; a kernel that calls non-inlined kernels in its innermost loop spends
    much of its time there (a serial PatchMatch tile ran 2× slower than the same code as the
    body of a numba ``prange`` loop, whose arrays numba hands over uncounted). Borrowed arrays have no
    count (a null ``meminfo``), so LLVM deletes the updates. Only for arrays the caller keeps
    alive while the kernel runs, and never returned from it.
    """
    if not _holds_arrays(value):
        return None

    def codegen(context, builder, signature, args):
        return _without_meminfo(context, builder, signature.args[0], args[0])

    return value(value), codegen


def _holds_arrays(value_type):
    if isinstance(value_type, types.Array):
        return True
    return isinstance(value_type, types.BaseTuple) and any(map(_holds_arrays, value_type))


def _without_meminfo(context, builder, value_type, value):
    if isinstance(value_type, types.Array):
        array = context.make_array(value_type)(context, builder, value)
        array.meminfo = cgutils.get_null_value(array.meminfo.type)
        return array._getvalue()
    if isinstance(value_type, types.BaseTuple):
        for index, element_type in enumerate(value_type):
            element = _without_meminfo(context, builder, element_type, builder.extract_value(value, index))
            value = builder.insert_value(value, element, index)
    return value


#: Jobs over fewer pixels (64×64) run their kernels on one thread: on the shared
#: 2-core machine a parallel region waits for its slowest thread, which then often waits for
#: a busy core (measured: a 38×32 PatchMatch pass 8.8 ms on two threads, 1.7 ms on one).
#: Above 64×64 two threads pay: bench_synth's small job 2.25 s with this bound against 2.65 s
#: with 1 << 15 (two runs each, load 0.2–0.4); bench_stylize speed unchanged within noise.
SERIAL_BELOW_PIXELS = 1 << 12


@contextlib.contextmanager
def threads_for(pixels):
    """Within the block, :func:`run_parts` uses one thread when ``pixels < SERIAL_BELOW_PIXELS``
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


_helpers = ThreadPoolExecutor(max_workers=max(1, numba.config.NUMBA_NUM_THREADS - 1), thread_name_prefix="kernel")


def run_parts(serial_kernel, *args):
    """``serial_kernel(*args, part, parts)`` for every ``part`` below ``parts``, one call per thread
    (``nogil`` kernels, so they run at once); their results in the order of ``part``.

    The kernel splits its work into fixed items (rows, tiles) and does items ``part, part +
    parts, …``, so the result does not depend on ``parts``, the thread count that
    :func:`threads_for`, ``numba.set_num_threads`` and ``NUMBA_NUM_THREADS`` set. This replaces
    numba's ``prange``: its parallel lowering compiled again, per wrapper, the code of every
    kernel the loop calls (half of a first run's compile time, docs/performance.md), and its
    OpenMP threads spin for a while after each loop, taking a core from the next kernel.
    """
    parts = numba.get_num_threads()
    helpers = [_helpers.submit(serial_kernel, *args, part, parts) for part in range(1, parts)]
    return [serial_kernel(*args, 0, parts)] + [helper.result() for helper in helpers]
