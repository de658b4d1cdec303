"""The stage cache: unchanged work is never redone, and a change redoes only what depends on it."""

import json

from tests.scenes import blob_scene, write_scene


def _write(tmp_path, blob_color="#2a6fdb", drop_exemplar="ink"):
    return write_scene(tmp_path, blob_scene(size=40, frames=(4, 7),
                                            layers=f'  - {{name: blob, color: "{blob_color}"}}\n'
                                                   f"  - {{name: drop, exemplar: {drop_exemplar}}}\n"))


def _ran(tmp_path):
    """The (stage, layer) pairs the last render computed rather than took from the cache."""
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    return {(entry["stage"], entry["layer"]) for entry in report["stages"] if not entry["cached"]}, report


def test_unchanged_scene_recomputes_nothing(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _write(tmp_path)
    assert cli("-q", "render", scene)[0] == 0
    first_ran, first = _ran(tmp_path)
    video = (tmp_path / "out" / "film.mp4").read_bytes()
    assert first_ran == {(entry["stage"], entry["layer"]) for entry in first["stages"]}
    assert {"stylize", "encode"} <= {stage for stage, _ in first_ran}
    assert cli("-q", "render", scene)[0] == 0
    ran, second = _ran(tmp_path)
    assert ran == set() and second["cache_hits"] == len(second["stages"]) == len(first["stages"])
    assert (tmp_path / "out" / "film.mp4").read_bytes() == video


def test_a_colour_change_redoes_only_that_layers_colorize_and_the_film(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    assert cli("-q", "render", _write(tmp_path))[0] == 0
    assert cli("-q", "render", _write(tmp_path, blob_color="#d94f30"))[0] == 0
    ran, _ = _ran(tmp_path)
    assert ran == {("colorize", "blob"), ("encode", None)}


def test_an_exemplar_change_redoes_that_layers_stylize_onwards(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    assert cli("-q", "render", _write(tmp_path))[0] == 0
    assert cli("-q", "render", _write(tmp_path, drop_exemplar="dry"))[0] == 0
    ran, _ = _ran(tmp_path)
    assert ran == {("stylize", "drop"), ("colorize", "drop"), ("encode", None)}


def test_one_layer_rerendered_and_forced_stages(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _write(tmp_path)
    assert cli("-q", "render", scene)[0] == 0
    assert cli("-q", "render", scene, "--layer", "drop", "--force-stage", "stylize")[0] == 0
    ran, report = _ran(tmp_path)
    assert ran == {("stylize", "drop")}  # same output, so colorize and the film stay cached
    assert {entry["layer"] for entry in report["stages"]} == {"drop", None}
    code, out, _ = cli("cache", "info", scene)
    assert code == 0 and "stylize" in out and "complete" in out


def test_prune_keeps_finished_work_and_removes_the_rest(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    scene = _write(tmp_path)
    assert cli("-q", "render", scene, "--until", "stylize")[0] == 0
    stale = tmp_path / "out" / "stylized" / "blob" / "00099.png"
    stale.write_bytes(b"left over from an older run")
    leftover = tmp_path / "out" / "stylized" / ".guides-killed"
    leftover.mkdir()
    kept = sorted((tmp_path / "out" / "stylized" / "blob").glob("0000*.png"))
    code, out, _ = cli("cache", "prune", scene)
    assert code == 0 and "removed 2" in out
    assert not stale.exists() and not leftover.exists() and all(path.is_file() for path in kept)
    assert cli("-q", "render", scene, "--until", "stylize")[0] == 0
    assert _ran(tmp_path)[0] == set()
