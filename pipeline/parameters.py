"""Per-layer stage parameters: defaults from ``configs/``, overridden by the scene.

A layer's ``params`` (the scene's ``defaults.params`` merged with the layer's own) may
name any parameter of the stylize and guides stages; an unknown name is an error that
names the scene file and the key path and suggests the closest valid name.
"""

from __future__ import annotations

import dataclasses
import difflib
from importlib import resources

import yaml

from fluidymation.errors import SceneError, StageError
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.stages import guides, stylize

#: Guides parameters a scene may set (``scale`` follows the output size).
GUIDE_NAMES = tuple(field.name for field in dataclasses.fields(guides.Params) if field.name != "scale")


def _stylize_config() -> dict:
    text = resources.files("fluidymation.configs").joinpath("stylize.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def stylize_defaults() -> dict:
    """The stylize stage's default parameters, from ``configs/stylize.yaml``."""
    return dict(_stylize_config()["stylize"])


def preview_overrides() -> dict:
    """The quicker schedule ``render --preview`` uses, from ``configs/stylize.yaml``."""
    return {key: tuple(value) if isinstance(value, list) else value
            for key, value in _stylize_config()["preview"].items()}


def _key_path(plan: Plan, layer: PlannedLayer, key: str) -> str:
    if key in plan.scene.defaults.params:
        return f"defaults.params.{key}"
    for index, spec in enumerate(plan.scene.layers or ()):
        if spec.name == layer.name:
            return f"layers[{index}].params.{key}"
    return f"params.{key}"


def check_layer_params(plan: Plan, layer: PlannedLayer) -> None:
    """Raise SceneError for a ``params`` key that no stage knows, with a did-you-mean hint."""
    known = stylize.parameter_names() + GUIDE_NAMES
    for key in layer.spec.params:
        if key not in known:
            close = difflib.get_close_matches(key, known, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else f"; valid names: {', '.join(sorted(known))}"
            raise SceneError(f"{plan.scene.path}: {_key_path(plan, layer, key)}: unknown parameter '{key}'{hint}")


def layer_stylize_params(plan: Plan, layer: PlannedLayer, **overrides) -> stylize.Params:
    """Stylize parameters of a layer: configs defaults < scene seed < layer params < ``overrides``."""
    check_layer_params(plan, layer)
    chosen = stylize_defaults() | {"seed": plan.scene.seed}
    chosen |= {key: value for key, value in layer.spec.params.items() if key in stylize.parameter_names()}
    chosen |= overrides
    for key in ("opt_iters", "pm_iters"):
        if isinstance(chosen[key], str):
            chosen[key] = _counts(plan, layer, key, chosen[key])
    try:
        return stylize.Params(**chosen)
    except (TypeError, ValueError, StageError) as exc:
        raise SceneError(f"{plan.scene.path}: layer '{layer.name}' params: {exc}") from None


def layer_guide_params(plan: Plan, layer: PlannedLayer) -> guides.Params:
    """Guides parameters of a layer: defaults < layer params of the same names; lengths scaled with the output size."""
    check_layer_params(plan, layer)
    chosen = {key: value for key, value in layer.spec.params.items() if key in GUIDE_NAMES}
    try:
        return guides.Params(**chosen, scale=plan.size[0] / plan.document.width)
    except (TypeError, ValueError, StageError) as exc:
        raise SceneError(f"{plan.scene.path}: layer '{layer.name}' params: {exc}") from None


def _counts(plan, layer, key, text):
    try:
        return tuple(int(part) for part in text.replace(",", " ").split())
    except ValueError:
        raise SceneError(f"{plan.scene.path}: {_key_path(plan, layer, key)}: expected whole numbers such as "
                         f"'4, 2, 1' (coarsest level first), got {text!r}") from None
