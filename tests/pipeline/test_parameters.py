"""Parameter errors name the file, the line and the key path, whether the value came from the scene or from a
stylizer's defaults file."""

import pytest

from fluidymation.errors import SceneError
from fluidymation.pipeline import exemplars, parameters, presets
from fluidymation.pipeline.resolve import plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.pipeline.stylizers import get_stylizer
from fluidymation.stages import stylize

from tests.scenes import blob_scene, write_scene


def _plan(tmp_path, layers, params='{opt_iters: "2, 1", pm_iters: 2}'):
    return plan_scene(load_scene(write_scene(tmp_path, blob_scene(layers=layers, params=params))))


def _error(call) -> str:
    with pytest.raises(SceneError) as caught:
        call()
    return str(caught.value)


@pytest.mark.parametrize("layer, message", [
    ("{w_bound: -1}", "line 13: layers[0].params.w_bound: stylize: parameter w_bound must be ≥ 0, got -1"),
    ("{w_bound: high}", "line 13: layers[0].params.w_bound: parameter w_bound: expected a number, got 'high'"),
    ("{patch_size: 5.5}", "line 13: layers[0].params.patch_size: parameter patch_size: expected a whole number"),
    ("{reverse: 1}", "line 13: layers[0].params.reverse: parameter reverse: expected true or false, got 1"),
    ("{pm_iters: 'four'}", "line 13: layers[0].params.pm_iters: parameter pm_iters: expected whole numbers such as"),
    ("{border_width: 0}", "line 13: layers[0].params.border_width: guides: parameter border_width must be positive"),
])
def test_a_bad_layer_value_is_reported_at_its_key(tmp_path, layer, message):
    plan = _plan(tmp_path, f"  - {{name: blob, params: {layer}}}\n")
    error = _error(lambda: (parameters.layer_guide_params(plan, plan.layer("blob")),
                            parameters.layer_stylize_params(plan, plan.layer("blob"))))
    assert "scene.yaml" in error and message in error


def test_a_value_from_the_scene_defaults_is_reported_there(tmp_path):
    plan = _plan(tmp_path, "  - {name: blob}\n", params="{alpha: 2}")
    error = _error(lambda: parameters.layer_stylize_params(plan, plan.layer("blob")))
    assert "line 11: defaults.params.alpha: stylize: parameter alpha must be between 0 and 1" in error


def test_a_count_or_a_text_of_counts_is_accepted(tmp_path):
    plan = _plan(tmp_path, "  - {name: blob, params: {opt_iters: 3, pm_iters: '5 2'}}\n")
    params = parameters.layer_stylize_params(plan, plan.layer("blob"))
    assert isinstance(params, stylize.Params) and params.opt_iters == (3,) and params.pm_iters == (5, 2)
    assert params.seed == 0 and params.w_bound == 4.0  # the scene's seed, configs/fluidymation.yaml's default


def test_a_list_of_counts_is_accepted_and_a_list_of_anything_else_refused_at_its_key(tmp_path):
    plan = _plan(tmp_path, "  - {name: blob, params: {opt_iters: [2, 1], pm_iters: [5, 2, 2]}}\n")
    params = parameters.layer_stylize_params(plan, plan.layer("blob"))
    assert params.opt_iters == (2, 1) and params.pm_iters == (5, 2, 2)
    error = _error(lambda: _plan(tmp_path / "bad", "  - {name: blob, params: {opt_iters: [2, x]}}\n"))
    assert "layers[0].params.opt_iters: expected a number, true/false, text or a list of numbers" in error


def test_a_bad_defaults_file_is_reported_in_that_file(tmp_path, monkeypatch):
    stylizer = get_stylizer("fluidymation")
    config = tmp_path / "fluidymation.yaml"
    text = stylizer.defaults.read_text()
    config.write_text(text.replace("w_temp: 4.0 ", "w_temp: warm"))
    monkeypatch.setattr(type(stylizer), "defaults", config)
    plan = _plan(tmp_path / "scene", "  - {name: blob}\n")
    line = text.splitlines().index(next(row for row in text.splitlines() if row.startswith("  w_temp:"))) + 1
    error = _error(lambda: parameters.layer_stylize_params(plan, plan.layer("blob")))
    assert error.startswith(f"{config}, line {line}: params.w_temp: parameter w_temp: expected a number")
    config.write_text(text.replace("  w_temp:", "  w_tmp:"))
    error = _error(lambda: parameters.layer_stylize_params(plan, plan.layer("blob")))
    assert f"{config}, line {line}: params.w_tmp: unknown key 'w_tmp' (did you mean 'w_temp'?)" in error


def test_a_builtin_exemplar_the_stage_refuses_is_reported_at_its_scene_entry(tmp_path):
    plan = _plan(tmp_path, "  - {name: blob}\n")
    scene = plan.scene.path
    scene.write_text(scene.read_text().replace("size: [32, 32], frames: 6}", "size: [8, 8], frames: 6}", 1))
    plan = plan_scene(load_scene(scene))
    error = _error(lambda: exemplars.exemplar_identity(plan, plan.layer("blob")))
    assert "line 9: exemplars.ink: exemplar size must be between 16 and 4096 pixels per side, got 8x8" in error


def test_a_bad_preset_default_is_reported_in_the_presets_file(tmp_path, monkeypatch):
    config = tmp_path / "exemplars.yaml"
    text = presets.CONFIG.read_text()
    config.write_text(text.replace("wetness: 0.5", "wetness: soggy", 1))
    monkeypatch.setattr(presets, "CONFIG", config)
    line = text.splitlines().index("    wetness: 0.5") + 1
    error = _error(lambda: presets.resolve_params("watercolor-bloom"))
    assert error.startswith(f"{config}, line {line}: presets.watercolor-bloom.wetness: expected a number")
