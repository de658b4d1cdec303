"""Layers rendered in other processes (--jobs) or on a Dask cluster give the same bytes as here."""

import json
import logging
import sys
from pathlib import Path

import pytest
from fluidymation.pipeline.cli import main

from tests.scenes import blob_scene, write_scene


SCENE = blob_scene(frames=(2, 5), layers='  - {name: blob, color: "#2a6fdb"}\n'
                                                 "  - {name: drop, exemplar: dry, blend: over, opacity: 0.5}\n")


def _render(folder: Path, *options) -> Path:
    assert main(["-q", "render", str(write_scene(folder, SCENE)), *options]) == 0
    return folder / "out"


def _products(out: Path) -> dict[str, bytes]:
    return {str(path.relative_to(out)): path.read_bytes()
            for path in sorted(out.glob("*/*/*.png")) + [out / "film.mp4"]}


@pytest.fixture(scope="module")
def user_cache(tmp_path_factory):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("FLUIDYMATION_CACHE", str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="module")
def here(user_cache, tmp_path_factory):
    """The scene's products rendered in this process, one layer after the other."""
    return _products(_render(tmp_path_factory.mktemp("here") / "scene"))


def test_two_jobs_render_the_layers_in_two_processes_with_the_same_output(here, tmp_path, caplog):
    caplog.set_level(logging.DEBUG, logger="fluidymation.pipeline.executors")
    out = _render(tmp_path / "jobs", "--jobs", "2")
    assert "running 2 jobs in 2 processes" in caplog.text
    assert _products(out) == here and len(here) == 2 * 3 * 5 + 1  # masks, coverage, colour, stylized, layers; film
    report = json.loads((out / "report.json").read_text())
    assert [(entry["stage"], entry["layer"]) for entry in report["stages"]][:6] == [
        (stage, layer) for layer in ("blob", "drop") for stage in ("masks", "stylize", "colorize")]


def test_the_dask_executor_renders_on_a_local_cluster_with_the_same_output(here, tmp_path, caplog):
    distributed = pytest.importorskip("distributed")
    caplog.set_level(logging.DEBUG, logger="fluidymation.pipeline.executors")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        address = cluster.scheduler_address.removeprefix("tcp://")
        out = _render(tmp_path / "dask", "--executor", f"dask://{address}")
    assert f"running 2 jobs on the Dask cluster at tcp://{address}" in caplog.text
    assert _products(out) == here


def test_executor_errors_are_clear(cli, tmp_path, monkeypatch):
    (tmp_path / "scene.yaml").write_text(SCENE)
    code, _, err = cli("render", tmp_path / "scene.yaml", "--executor", "spark://here")
    assert code == 2 and "dask://HOST:PORT" in err
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if the extra were not installed
    code, _, err = cli("render", tmp_path / "scene.yaml", "--executor", "dask://localhost:8786")
    assert code == 2 and "pip install 'fluidymation[distributed]'" in err
    code, _, err = cli("render", tmp_path / "scene.yaml", "--jobs", "0")
    assert code == 2 and "--jobs 0" in err
