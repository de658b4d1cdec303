"""Per-layer parameters: a stylizer's defaults file, overridden by the scene.

A layer's ``params`` (the scene's ``defaults.params`` merged with the layer's own) may
name any parameter of the layer's stylizer and, for stylizers that use them, of the
guides stage. Every value keeps where it was written (the defaults file in ``configs/``
or the scene file, with its line and key path), so an unknown name, a value of the wrong
type or one a ``Params`` class refuses is reported there, e.g.
``scene.yaml, line 9: layers[0].params.w_bound: stylize: parameter w_bound must be ≥ 0, got -1``.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import types
import typing
from importlib import resources

from fluidymation.errors import ParameterError, SceneError, StageError
from fluidymation.pipeline.resolve import Plan, PlannedLayer
from fluidymation.pipeline.schema import Checker
from fluidymation.pipeline.stylizers import get_stylizer
from fluidymation.pipeline.yaml_lines import KeyPath, LocatedYaml, load_yaml
from fluidymation.stages.guide_params import Params as GuideParams
from fluidymation.stages.stylizer import Stylizer

#: Guides parameters a scene may set (``scale`` follows the output size).
GUIDE_NAMES = tuple(field.name for field in dataclasses.fields(GuideParams) if field.name != "scale")

#: A value and where it was written: (document, key path), or None for values the program sets.
Origin = tuple[LocatedYaml, KeyPath] | None


def layer_stylizer(plan: Plan, layer: PlannedLayer) -> Stylizer:
    """The stylizer the layer's ``stylizer:`` names."""
    try:
        return get_stylizer(layer.spec.stylizer)
    except StageError as exc:
        raise SceneError(f"{plan.scene.path}: layer '{layer.name}': {exc}") from None


def stylizer_config(stylizer: Stylizer) -> LocatedYaml | None:
    """The stylizer's defaults file, checked: ``version``, a ``params:`` mapping and an optional ``preview:`` one."""
    if stylizer.defaults is None:
        return None
    with resources.as_file(stylizer.defaults) as path:
        doc = load_yaml(path)
    check = Checker(doc)
    check.mapping((), ("version", "params", "preview"), required=True)
    known = stylizer.parameter_names()
    for section in ("params", "preview"):
        check.mapping((section,), known)
    return doc


def _config_values(stylizer: Stylizer, section: str) -> dict[str, tuple]:
    doc = stylizer_config(stylizer)
    if doc is None:
        return {}
    return {key: (value, (doc, (section, key))) for key, value in (doc.data.get(section) or {}).items()}


def default_params(stylizer: Stylizer):
    """The stylizer's ``Params`` with the values of its defaults file (benchmarks and tools outside a scene)."""
    return build_params(stylizer.Params, _config_values(stylizer, "params"), fallback=None)


def known_parameters(plan: Plan, layer: PlannedLayer) -> tuple[str, ...]:
    """The ``params`` keys the layer accepts: its stylizer's, and the guides' when the stylizer uses guides."""
    stylizer = layer_stylizer(plan, layer)
    return stylizer.parameter_names() + (GUIDE_NAMES if stylizer.uses_guides else ())


def check_layer_params(plan: Plan, layer: PlannedLayer) -> None:
    """Raise SceneError for a ``params`` key that the layer's stylizer and guides do not know, with a hint."""
    known = known_parameters(plan, layer)
    owners = f"stylizer '{layer.spec.stylizer}'" + (" or the guides" if layer_stylizer(plan, layer).uses_guides else "")
    for key in layer.spec.params:
        if key not in known:
            close = difflib.get_close_matches(key, known, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else f"; valid names: {', '.join(sorted(known))}"
            raise plan.scene.error(_param_path(layer, key), f"unknown parameter '{key}' of {owners}{hint}")
    check_layer_keyframes(plan, layer)


def _layer_path(plan: Plan, layer: PlannedLayer) -> KeyPath:
    for index, spec in enumerate(plan.scene.layers or ()):
        if spec.name == layer.name:
            return ("layers", index)
    return ("defaults",)


def check_layer_keyframes(plan: Plan, layer: PlannedLayer) -> None:
    """Raise SceneError when a stylizer that paints from keyframes has none, when keyframes are given to
    one that does not, or when a keyframe's frame lies outside the scene's frames."""
    stylizer = layer_stylizer(plan, layer)
    where = _layer_path(plan, layer) + ("keyframes",)
    if stylizer.uses_keyframes and not layer.spec.keyframes:
        raise plan.scene.error(_layer_path(plan, layer), f"layer '{layer.name}': the stylizer '{stylizer.name}' "
                               "paints from keyframes: give them as keyframes: {FRAME: IMAGE, ...}")
    if layer.spec.keyframes and not stylizer.uses_keyframes:
        raise plan.scene.error(where, f"layer '{layer.name}': the stylizer '{stylizer.name}' does not use "
                               "keyframes (use stylizer: keyframes, or leave them out)")
    for frame, path in layer.spec.keyframes:
        if not plan.start <= frame < plan.end:
            raise plan.scene.error(where + (frame,), f"{path}: keyframe {frame} is outside the scene's frames "
                                   f"{plan.start}:{plan.end}")


def layer_colorize(plan: Plan, layer: PlannedLayer) -> str:
    """The layer's ``colorize:``, or its stylizer's default (``layer``; ``none`` for painted keyframes)."""
    return layer.spec.colorize or layer_stylizer(plan, layer).default_colorize


def layer_stylize_params(plan: Plan, layer: PlannedLayer, *, preview: bool = False):
    """The layer's stylizer parameters: its defaults file < scene seed < layer params < ``preview:`` (with ``preview``)."""
    check_layer_params(plan, layer)
    stylizer = layer_stylizer(plan, layer)
    values = _default_values(plan, stylizer) | _scene_values(plan, layer, stylizer.parameter_names())
    if preview:
        values |= _config_values(stylizer, "preview")
    return build_params(stylizer.Params, values, fallback=_fallback(plan, layer))


def scene_default_params(plan: Plan, stylizer: Stylizer):
    """The stylizer's parameters for a layer it does not paint in the scene: its defaults file < the scene's
    seed (``fluidymation compare``)."""
    return build_params(stylizer.Params, _default_values(plan, stylizer), fallback=None)


def _default_values(plan: Plan, stylizer: Stylizer) -> dict[str, tuple]:
    """The stylizer's defaults file, with the scene's seed when its ``Params`` has a ``seed``."""
    values = _config_values(stylizer, "params")
    if "seed" in stylizer.parameter_names():
        values["seed"] = (plan.scene.seed, (plan.scene.doc, ("seed",)))
    return values


def layer_guide_params(plan: Plan, layer: PlannedLayer) -> GuideParams:
    """Guides parameters of a layer: defaults < layer params of the same names; lengths scaled with the output size."""
    check_layer_params(plan, layer)
    values = _scene_values(plan, layer, GUIDE_NAMES) | {"scale": (plan.size[0] / plan.document.width, None)}
    return build_params(GuideParams, values, fallback=_fallback(plan, layer))


def build_params(cls: type, values: dict[str, tuple], *, fallback: Origin):
    """``cls(**values)`` for a frozen Params dataclass, ``values`` mapping names to (value, origin).

    Each value is checked against the field's type first (a number for ``float``, a whole
    number for ``int``, true/false for ``bool``; a list, a single number or text such as
    ``"4, 2, 1"`` for ``tuple``); errors are SceneErrors at the value's origin, or at
    ``fallback`` when the class refuses a combination of values.
    """
    hints = typing.get_type_hints(cls)
    chosen = {name: _typed(value, hints[name], name, origin) for name, (value, origin) in values.items()}
    try:
        return cls(**chosen)
    except ParameterError as exc:
        raise _located(values.get(exc.name, (None, fallback))[1] or fallback, str(exc)) from None
    except (TypeError, ValueError, StageError) as exc:
        raise _located(fallback, str(exc)) from None


def _typed(value, hint, name: str, origin: Origin):
    """``value`` checked against the field type ``hint`` (lists become tuples)."""
    options = typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType) else (hint,)
    if value is None:
        if type(None) in options:
            return None
        raise _located(origin, f"parameter {name} cannot be null")
    kind = next(option for option in options if option is not type(None))
    if kind is bool:
        if not isinstance(value, bool):
            raise _located(origin, f"parameter {name}: expected true or false, got {value!r}")
    elif kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _located(origin, f"parameter {name}: expected a whole number, got {value!r}")
    elif kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _located(origin, f"parameter {name}: expected a number, got {value!r}")
    elif kind is tuple:
        return _counts(value, name, origin)
    return value


def _counts(value, name: str, origin: Origin) -> tuple:
    """A tuple parameter: a list, one whole number, or text such as ``"4, 2, 1"``."""
    if isinstance(value, str):
        try:
            return tuple(int(part) for part in value.replace(",", " ").split())
        except ValueError:
            raise _located(origin, f"parameter {name}: expected whole numbers such as '4, 2, 1' (coarsest level "
                                   f"first), got {value!r}") from None
    items = value if isinstance(value, (list, tuple)) else [value]
    if any(isinstance(item, bool) or not isinstance(item, int) for item in items):
        raise _located(origin, f"parameter {name}: expected whole numbers, got {value!r}")
    return tuple(items)


def _located(origin: Origin, message: str) -> SceneError:
    if origin is None:
        return SceneError(message)
    doc, path = origin
    return Checker(doc).error(path, message)


def _scene_values(plan: Plan, layer: PlannedLayer, names: tuple[str, ...]) -> dict[str, tuple]:
    return {key: (value, (plan.scene.doc, _param_path(layer, key))) for key, value in layer.spec.params.items()
            if key in names}


def _param_path(layer: PlannedLayer, key: str) -> KeyPath:
    return layer.spec.param_paths.get(key, ("params", key))


def _fallback(plan: Plan, layer: PlannedLayer) -> Origin:
    """Where a layer's params as a whole are: its own ``params:`` or the scene's ``defaults.params``."""
    for index, spec in enumerate(plan.scene.layers or ()):
        if spec.name == layer.name and "params" in (plan.scene.doc.data["layers"][index] or {}):
            return plan.scene.doc, ("layers", index, "params")
    return plan.scene.doc, ("defaults", "params")
