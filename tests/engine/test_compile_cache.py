"""A kernel compiled in this process and the same kernel loaded from numba's disk cache give the same bits.

Before ``engine/_jit.py`` bound each compiled library to its own copies of the kernels it
calls, a fresh process ran the callee's code and a cached one the caller's copy, which
fastmath had reassociated differently: rotated patch costs differed in the last bits.
And since the cached code holds those copies, a kernel's cache entry must go when a kernel it
calls, in another file, changes.
"""

import importlib
import os
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import hashlib
    import numpy as np
    from fluidymation.engine.nnf import NNF, ROTATION_FLOW, fill_random
    from fluidymation.engine.patch_cost import build_patch_cost, patch_errors
    from fluidymation.engine.patchmatch import patchmatch_pass

    rng = np.random.default_rng(1)
    source, target = (2, 30, 32), (20, 24)
    angles = dict(source_angle=rng.uniform(-3, 3, source).astype(np.float32),
                  target_angle=rng.uniform(-3, 3, target).astype(np.float32))
    cost = build_patch_cost(
        source_colour=rng.random(source + (3,)).astype(np.float32),
        source_guides=rng.random(source + (2,)).astype(np.float32),
        target_colour=rng.random(target + (3,)).astype(np.float32),
        target_guides=rng.random(target + (2,)).astype(np.float32),
        colour_weights=[1.0, 0.5, 0.25], guide_weights=(2.0, 3.0), **angles)
    field = NNF.empty(*target)
    fill_random(field, target_segment=cost.target_segment, source_segment=cost.source_segment, seed=3,
                rotation_mode=ROTATION_FLOW, **angles)
    error = patch_errors(cost, field)
    digest = hashlib.sha1(error.tobytes())
    for iteration in range(2):
        patchmatch_pass(cost, field, error, rotation_mode=ROTATION_FLOW, seed=5, salt=iteration)
    for array in (field.frame, field.coords, error):
        digest.update(array.tobytes())
    print(digest.hexdigest())
""")


def _run(cache, script=SCRIPT, folder=None):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True,
                          cwd=folder)
    return done.stdout.strip()


def _cache_files(cache):
    return {path: path.stat().st_mtime_ns for path in cache.rglob("*.nbc")}


def test_fresh_and_cached_kernels_agree_bit_for_bit(tmp_path):
    cache = tmp_path / "numba-cache"
    compiled = _run(cache)
    written = _cache_files(cache)
    assert written  # the kernels were cached...
    loaded = _run(cache)
    assert _cache_files(cache) == written  # ...and the second process loaded them instead of compiling
    assert loaded == compiled


def test_editing_a_called_kernel_recompiles_its_callers(tmp_path):
    callee = tmp_path / "callee.py"
    callee.write_text("from fluidymation.engine._jit import kernel\n\n@kernel\ndef scale(x):\n    return x * 2.0\n")
    (tmp_path / "caller.py").write_text(
        "from fluidymation.engine._jit import kernel\nfrom callee import scale\n\n"
        "@kernel\ndef run(x):\n    return scale(x) + 1.0\n"
    )
    script = "from caller import run; print(run(1.0))"  # run in tmp_path
    cache = tmp_path / "numba-cache"
    assert _run(cache, script, tmp_path) == "3.0"
    callee.write_text(callee.read_text().replace("2.0", "3.0"))
    # an edit made seconds later, as a person makes it: Python's bytecode cache compares
    # whole seconds of the source's mtime, so a same-size edit within the second that
    # wrote the .pyc would import the old scale whatever numba does
    edited = callee.stat().st_mtime_ns + 2_000_000_000
    os.utime(callee, ns=(edited, edited))
    assert _run(cache, script, tmp_path) == "4.0"  # not the cached caller's copy of the old scale


LOAD_THEN_COMPILE = textwrap.dedent("""
    import sys
    import numba
    import numpy as np
    from fluidymation.engine.pyramid import downsample

    half = downsample(np.arange(64, dtype=np.float32).reshape(8, 8, 1))
    print("registries" if "numba.np.npyimpl" in sys.modules else "no registries", "scipy.linalg" in sys.modules)

    @numba.njit
    def needs_registries(values):  # compiled here: ufuncs, reductions and strings need numba's registries
        return np.sqrt(values).sum(), str(values.shape[0])

    print(half.shape, needs_registries(np.full(4, 4.0)))
""")


def test_a_process_loading_cached_kernels_skips_the_compilers_registries_until_it_compiles(tmp_path):
    """engine/_jit.py: loading from the cache fills none of numba's typing and lowering registries
    and imports no scipy.linalg; a later compilation in the same process still works."""
    cache = tmp_path / "numba-cache"
    first = _run(cache, LOAD_THEN_COMPILE).splitlines()
    assert first[0] == "registries False"  # compiled: numba's compiler filled the registries
    loaded = _run(cache, LOAD_THEN_COMPILE).splitlines()
    assert loaded[0] == "no registries False"
    assert loaded[1] == first[1] == "(4, 4, 1) (8.0, '4')"


def test_two_processes_saving_two_signatures_of_one_kernel_at_once_keep_both(tmp_path, monkeypatch):
    """engine/_jit.py: numba's cache saves one process at a time. Two views of one kernel's cache
    files (as two processes hold) save two signatures at once: the first to read the index waits up
    to 0.5 s for the other to read it too; unlocked, both then took data file 1."""
    import threading

    from numba.core import caching

    importlib.import_module("fluidymation.engine._jit")  # installs the locked save

    views = [caching.IndexDataCacheFile(str(tmp_path), "kernel-1.py311", "stamp") for _ in range(2)]
    other_read = threading.Event()
    first_reader = threading.Lock()
    load_index = caching.IndexDataCacheFile._load_index

    def slow_load_index(view):
        overloads = load_index(view)
        if first_reader.acquire(blocking=False):
            other_read.wait(0.5)
        else:
            other_read.set()
        return overloads

    monkeypatch.setattr(caching.IndexDataCacheFile, "_load_index", slow_load_index)
    savers = [threading.Thread(target=view.save, args=(key, f"code of {key}")) for view, key in zip(views, "ab")]
    for saver in savers:
        saver.start()
    for saver in savers:
        saver.join()
    monkeypatch.undo()
    assert [views[0].load(key) for key in "ab"] == ["code of a", "code of b"]


GATED = textwrap.dedent("""
    import subprocess, sys
    from numba.core import event
    from fluidymation.engine import _jit

    compiled, waits = [], []
    class Heard(event.Listener):
        def on_start(self, compilation):
            compiled.append(compilation.data["args"])
        def on_end(self, compilation):
            pass
    event.register("numba:compile", Heard())

    def helper_compiles():  # the other process, run at the first wait: compiles double(float) into the cache
        if not waits:
            subprocess.run([sys.executable, "-c", "from gated import double; double(1.5)"], check=True)
        waits.append(1)

    import gated
    print("cached before", _jit.in_disk_cache(gated.double))
    with _jit.compiled_elsewhere(["gated"], helper_compiles):
        print(gated.double(2.5), gated.double(3))  # float: the helper's; int: compiled here
    print("cached after", _jit.in_disk_cache(gated.double), "waits", len(waits), "compiled here", compiled)
""")


def test_a_kernel_another_process_compiles_is_waited_for_and_loaded(tmp_path):
    """engine/_jit.py's compiled_elsewhere: a cache miss of a kernel of the other process's modules waits for
    it and loads what it saved; a signature it did not save is compiled here."""
    (tmp_path / "gated.py").write_text("from fluidymation.engine._jit import kernel\n\n@kernel\n"
                                       "def double(x):\n    return x * 2.0\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"), PYTHONPATH=str(tmp_path))
    done = subprocess.run([sys.executable, "-c", GATED], env=env, capture_output=True, text=True, check=True,
                          cwd=tmp_path)
    lines = done.stdout.strip().splitlines()
    assert lines[0] == "cached before False"
    assert lines[1] == "5.0 6.0"
    assert lines[2] == "cached after True waits 2 compiled here [(int64,)]"
