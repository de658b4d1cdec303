"""pipeline/compile_helper.py: a first render leaves its stylizer's kernels to a helper process."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

BLOB = Path(__file__).parents[2] / "examples" / "blob" / "blob.svg"

RENDER_AND_RECORD = textwrap.dedent("""
    import json, sys
    from numba.core import event
    from fluidymation.pipeline.cli import main

    compiled = []
    class Heard(event.Listener):
        def on_start(self, compilation):
            compiled.append(compilation.data["dispatcher"].py_func.__module__)
        def on_end(self, compilation):
            pass
    event.register("numba:compile", Heard())
    code = main(sys.argv[1:])
    print(json.dumps({"code": code, "compiled": compiled}))
""")


def _render(tmp_path, *args):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"), FLUIDYMATION_CACHE=str(tmp_path / "cache"))
    done = subprocess.run([sys.executable, "-c", RENDER_AND_RECORD, "render", str(tmp_path / "scene.yaml"), *args],
                          env=env, capture_output=True, text=True, cwd=tmp_path)
    return json.loads(done.stdout.strip().splitlines()[-1]), done.stderr


@pytest.mark.slow
def test_a_first_render_waits_for_the_helper_and_loads_the_stylizers_kernels(tmp_path):
    from fluidymation.stages.fluidymation_stylizer import FluidymationStylizer

    (tmp_path / "scene.yaml").write_text(f"input: {BLOB}\nfps: 12\nsize: [32, 32]\nframes: {{start: 0, end: 3}}\n"
                                         "output: {dir: out}\nlayers:\n  - {name: blob}\n")
    first, err = _render(tmp_path, "--until", "stylize")  # the background's synthesis would come after the helper
    assert first["code"] == 0, err
    assert "a helper process compiled" in err
    assert first["compiled"]  # the masks' and guides' kernels, here
    assert not set(first["compiled"]) & set(FluidymationStylizer.warm_up_modules)  # the helper compiled those
    again, err = _render(tmp_path, "--until", "stylize", "--force")
    assert again == {"code": 0, "compiled": []} and "helper" not in err


def test_a_helper_that_fails_leaves_the_compiling_to_the_render(caplog):
    import dataclasses
    import logging

    from fluidymation.engine import compiling
    from fluidymation.pipeline import compile_helper
    from fluidymation.pipeline.parameters import default_params
    from fluidymation.pipeline.stylizers import get_stylizer

    lazyfluids = get_stylizer("lazyfluids")
    params = dataclasses.replace(default_params(lazyfluids), exemplar_frame=99)  # the tiny exemplar has 4 frames
    heard = []
    compiling.helper_listeners.append(lambda kernels, seconds: heard.append(kernels))
    caplog.set_level(logging.DEBUG, logger="fluidymation")
    helper = compile_helper._Helper(lazyfluids, params)
    try:
        helper.wait()
        helper.wait()  # at once, the second time
    finally:
        helper.stop()
        compiling.helper_listeners.pop()
    assert helper.process.returncode != 0
    assert "the lazyfluids kernel warm-up failed" in caplog.text and "exemplar_frame 99" in caplog.text
    assert heard == []


def test_a_helper_that_takes_too_long_is_stopped_and_the_render_compiles(caplog, monkeypatch):
    import logging

    from fluidymation.pipeline import compile_helper
    from fluidymation.pipeline.parameters import default_params
    from fluidymation.pipeline.stylizers import get_stylizer

    monkeypatch.setattr(compile_helper, "WAIT_AT_MOST", 0.05)  # less than the helper's start-up
    caplog.set_level(logging.DEBUG, logger="fluidymation")
    stylizer = get_stylizer("fluidymation")
    helper = compile_helper._Helper(stylizer, default_params(stylizer))
    try:
        helper.wait()
        helper.wait()
    finally:
        helper.stop()
    assert helper.process.returncode != 0  # killed
    assert "the fluidymation kernel warm-up took over 0.05 s" in caplog.text
