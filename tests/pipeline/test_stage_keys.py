"""The stage contract: changing a stage's version, parameters or inputs changes the key of exactly that stage
and of every stage downstream of it, and no other key."""

import dataclasses
from pathlib import Path
from typing import Any

import pytest

from fluidymation.pipeline import render
from fluidymation.pipeline.render import STAGES, Options
from fluidymation.pipeline.resolve import plan_scene
from fluidymation.pipeline.scene import load_scene

from tests.scenes import ROOT, blob_scene, write_scene

LAYERS = ("blob", "drop")
TWO_LAYERS = '  - {name: blob, color: "#2a6fdb"}\n  - {name: drop, exemplar: dry}\n'
#: What each stage's change must invalidate, besides itself (per layer for the layer stages).
DOWNSTREAM = {
    "masks": {"guides", "stylize", "colorize", "composite", "encode"},
    "guides": {"stylize", "colorize", "composite", "encode"},
    "stylize": {"colorize", "composite", "encode"},
    "colorize": {"composite", "encode"},
    "background": {"composite", "encode"},
    "composite": {"encode"},
    "encode": set(),
}
SCENE_STAGES = {"background", "composite", "encode"}


def _keys(scene: Path, stages=STAGES, options=Options()) -> dict:
    run = render._Run(plan_scene(load_scene(scene)), options, stages=stages)
    return run.keys.all()


def _invalidated(stage: str, layers=LAYERS) -> set:
    """The (stage, layer) keys a change of ``stage`` (for ``layers``) must change."""
    names = {stage} | DOWNSTREAM[stage]
    return ({(name, None) for name in names & SCENE_STAGES}
            | {(name, layer) for name in names - SCENE_STAGES for layer in layers})


def _changed(before: dict, after: dict) -> set:
    assert before.keys() == after.keys()
    return {where for where in before if before[where] != after[where]}


@pytest.fixture
def scene(tmp_path):
    return write_scene(tmp_path, blob_scene(layers=TWO_LAYERS))


def test_every_layer_stage_and_scene_stage_has_a_key(scene):
    keys = _keys(scene)
    assert set(keys) == _invalidated("masks") | {("background", None)}
    assert len(set(keys.values())) == len(keys)


@dataclasses.dataclass(frozen=True)
class _Tagged:
    params: Any
    tag: int = 1


@pytest.mark.parametrize("stage", [stage.name for stage in STAGES])
@pytest.mark.parametrize("change", ["version", "params", "inputs"])
def test_a_change_of_any_stage_invalidates_it_and_what_follows_only(scene, stage, change):
    index = [each.name for each in STAGES].index(stage)
    declared = STAGES[index]
    if change == "version":
        changed = dataclasses.replace(declared, version=declared.version + 1)
    elif change == "params":
        changed = dataclasses.replace(declared, params=lambda work, old=declared.params: _Tagged(old(work)))
    else:
        changed = dataclasses.replace(declared, inputs=lambda work, old=declared.inputs: old(work) | {"new": 1})
    table = STAGES[:index] + (changed,) + STAGES[index + 1:]
    assert _changed(_keys(scene), _keys(scene, stages=table)) == _invalidated(stage)


def _edit(scene: Path, old: str, new: str) -> Path:
    text = scene.read_text()
    assert old in text
    scene.write_text(text.replace(old, new))
    return scene


@pytest.mark.parametrize("old, new, stage, layers", [
    ('{name: drop, exemplar: dry}', '{name: drop, exemplar: dry, params: {w_temp: 2}}', "stylize", ["drop"]),
    ('{name: drop, exemplar: dry}', '{name: drop, exemplar: ink}', "stylize", ["drop"]),
    ('{name: drop, exemplar: dry}', '{name: drop, exemplar: dry, params: {border_width: 3}}', "guides", ["drop"]),
    ('color: "#2a6fdb"', 'color: "#d94f30"', "colorize", ["blob"]),
    ('{name: drop, exemplar: dry}', '{name: drop, exemplar: dry, colorize: none}', "colorize", ["drop"]),
    ('{name: drop, exemplar: dry}', '{name: drop, exemplar: dry, blend: over}', "composite", []),
    ('{name: drop, exemplar: dry}', '{name: drop, exemplar: dry, opacity: 0.5}', "composite", []),
    ('color: "#f4efe4"', 'color: "#ffffff"', "background", []),
    ("output: {dir: out, video: film.mp4}", "output: {dir: out, video: film.mp4, crf: 20}", "encode", []),
    ("fps: 12", "fps: 13", "masks", list(LAYERS)),
])
def test_a_scene_change_invalidates_its_stage_and_what_follows_only(scene, old, new, stage, layers):
    before = _keys(scene)
    after = _keys(_edit(scene, old, new))
    assert _changed(before, after) == _invalidated(stage, layers)


def test_a_change_of_the_input_file_or_the_renderer_invalidates_the_masks_onwards(scene, tmp_path, monkeypatch):
    svg = tmp_path / "blob.svg"
    svg.write_text((ROOT / "examples" / "blob" / "blob.svg").read_text())
    _edit(scene, str(ROOT / "examples" / "blob" / "blob.svg"), str(svg))
    before = _keys(scene)
    svg.write_text(svg.read_text().replace("</svg>", "<!-- edited -->\n</svg>"))
    assert _changed(before, _keys(scene)) == _invalidated("masks")
    plan = plan_scene(load_scene(scene))
    keys = render._Run(plan, Options()).keys.all()
    bumped = dataclasses.replace(plan, renderer=_Renamed(plan.renderer))
    assert _changed(keys, render._Run(bumped, Options()).keys.all()) == _invalidated("masks")


def test_a_dotlottie_theme_picked_in_the_scene_invalidates_the_masks_onwards(tmp_path):
    themed = ROOT / "tests" / "data" / "lottie" / "themed.lottie"
    scene = write_scene(tmp_path, f"version: 1\ninput: {themed}\nsize: [32, 32]\nframes: {{start: 0, end: 2}}\n"
                                  "output: {dir: out, video: film.mp4}\nlayers:\n  - {name: square}\n")
    before = _keys(scene)
    after = _keys(_edit(scene, "size: [32, 32]", "theme: recoloured\nsize: [32, 32]"))
    assert _changed(before, after) == _invalidated("masks", ["square"])


class _Renamed:
    """The plan's renderer under another version."""

    def __init__(self, renderer):
        self.name, self.version = renderer.name, renderer.version + 1


def test_window_preview_and_nnf_invalidate_stylize_onwards(scene):
    base = _keys(scene)
    assert _changed(base, _keys(scene, options=Options(nnf=True))) == _invalidated("stylize")
    assert _changed(base, _keys(scene, options=Options(preview=True))) == _invalidated("stylize")
    assert _changed(base, _keys(scene, options=Options(window=(1, 3)))) == _invalidated("guides")
