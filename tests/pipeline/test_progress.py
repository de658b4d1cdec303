"""Observability: --json progress lines on stderr, and debug logs of every stage's fate."""

import json
import logging
from pathlib import Path

BLOB = Path(__file__).parents[2] / "examples" / "blob" / "blob.svg"


def _scene(tmp_path):
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"input: {BLOB}\nfps: 12\nsize: [32, 32]\nframes: {{start: 0, end: 3}}\noutput: {{dir: out}}\n"
                     "layers:\n  - {name: blob}\n  - {name: drop}\n")
    return scene


def test_json_replaces_the_bars_with_one_line_per_step(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    code, _, err = cli("--json", "render", _scene(tmp_path), "--until", "masks")
    assert code == 0, err
    lines = [json.loads(line) for line in err.splitlines()]
    assert all(set(line) == {"stage", "layer", "done", "total"} for line in lines)
    for layer in ("blob", "drop"):
        steps = [(line["done"], line["total"]) for line in lines if line["stage"] == "masks" and line["layer"] == layer]
        assert steps == [(0, 3), (1, 3), (2, 3), (3, 3)]
    code, _, err = cli("--json", "-q", "render", _scene(tmp_path), "--until", "masks", "--force")
    assert code == 0 and err == ""


def test_debug_logs_say_what_each_stage_did(cli, tmp_path, monkeypatch, caplog):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    caplog.set_level(logging.DEBUG, logger="fluidymation")
    assert cli("--debug", "-q", "render", _scene(tmp_path), "--until", "masks")[0] == 0
    assert "masks blob: running (key" in caplog.text and "masks blob: finished in" in caplog.text
    caplog.clear()
    assert cli("--debug", "-q", "render", _scene(tmp_path), "--until", "masks")[0] == 0
    assert "masks drop: cached (key" in caplog.text and "running" not in caplog.text


def test_a_first_compilation_is_announced_once_and_counted(capsys):
    import numba

    from fluidymation.engine import _jit  # noqa: F401  (it forwards numba's compilations)
    from fluidymation.pipeline.progress import CompileNotice

    notice = CompileNotice().listen()
    numba.njit(lambda x: x + 1)(1)  # not cached: numba compiles it here
    numba.njit(lambda x: x * 2.0)(1.5)
    notice.close()
    numba.njit(lambda x: x - 1)(1)  # after close: not heard
    err = capsys.readouterr().err
    assert err.count("compiling kernels (first run only") == 1
    assert "compiled 2 kernels in" in err


def test_a_run_that_compiles_nothing_says_nothing(capsys):
    from fluidymation.pipeline.progress import CompileNotice

    CompileNotice().listen().close()
    assert capsys.readouterr().err == ""


def test_compiling_time_counts_nested_compilations_once(capsys, monkeypatch):
    from fluidymation.pipeline import progress

    clock = iter([10.0, 13.0, 20.0, 21.0])
    monkeypatch.setattr(progress.time, "monotonic", lambda: next(clock))
    notice = progress.CompileNotice()
    for kernel, started in (("outer", True), ("inner", True), ("inner", False), ("outer", False),
                            ("other", True), ("other", False)):
        notice.heard(kernel, started)
    notice.close()
    assert "compiled 3 kernels in 4 s" in capsys.readouterr().err  # (13 − 10) + (21 − 20): work between is not compiling


def test_the_wait_for_a_compiling_helper_is_timed_not_counted_and_its_kernels_are_told(capsys, monkeypatch):
    from fluidymation.engine import compiling
    from fluidymation.pipeline import progress

    clock = iter([10.0, 12.0, 20.0, 29.0])
    monkeypatch.setattr(progress.time, "monotonic", lambda: next(clock))
    notice = progress.CompileNotice().listen()
    compiling.notify("masks kernel", True)
    compiling.notify("masks kernel", False)
    compiling.notify(None, True)  # waiting for the helper (pipeline/compile_helper.py)
    compiling.notify(None, False)
    compiling.helper_finished(40, 25.0)
    notice.close()
    assert ("compiled 1 kernel in 11 s; a helper process compiled 40 more alongside in 25 s (the 11 s include "
            "waiting for it)") in capsys.readouterr().err
