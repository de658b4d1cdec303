"""Parameters of the built-in exemplar presets: defaults from ``configs/exemplars.yaml``,
overridden by a scene's ``exemplars:`` entry or the ``exemplar make`` options."""

from __future__ import annotations

import re
from importlib import resources

from fluidymation.errors import InputError
from fluidymation.pipeline.schema import Checker
from fluidymation.pipeline.yaml_lines import load_yaml
from fluidymation.stages import exemplar_builtin

_SIZE = re.compile(r"^(\d+)[xX](\d+)$")


_PRESET_KEYS = ("seed", "size", "frames", "color", "wetness")
#: The presets' defaults file.
CONFIG = resources.files("fluidymation.configs").joinpath("exemplars.yaml")


def preset_defaults() -> dict:
    """Default parameters of every built-in preset, by name, from ``configs/exemplars.yaml``.

    The file is checked as a scene is: a bad key or value is a SceneError naming the file, line and key path.
    """
    with resources.as_file(CONFIG) as path:
        check = Checker(load_yaml(path))
    check.mapping((), ("version", "presets"), required=True)
    presets = {}
    for name in check.mapping(("presets",), None, required=True):
        where = ("presets", name)
        check.mapping(where, _PRESET_KEYS, required=True)
        size = check.sequence(where + ("size",), required=True)
        if len(size) != 2:
            raise check.error(where + ("size",), "expected [width, height]")
        presets[name] = {
            "seed": check.integer(where + ("seed",), minimum=0),
            "size": [check.integer(where + ("size", i), minimum=16, maximum=4096) for i in range(2)],
            "frames": check.integer(where + ("frames",), minimum=2, maximum=10000),
            "color": check.color(where + ("color",)),
            "wetness": check.number(where + ("wetness",), minimum=0, maximum=1),
        }
    return presets


def resolve_params(name: str, *, seed=None, size=None, frames=None, color=None, wetness=None) -> exemplar_builtin.Params:
    """The preset's defaults overridden by the given values (``None`` keeps the default).

    ``size`` is (width, height). Raises :class:`InputError` for an unknown name.
    """
    defaults = preset_defaults()
    if name not in defaults or name not in exemplar_builtin.PRESETS:
        valid = ", ".join(sorted(set(defaults) & set(exemplar_builtin.PRESETS)))
        raise InputError(f"unknown built-in exemplar {name!r}; valid names: {valid}")
    chosen = dict(defaults[name])
    for key, value in (("seed", seed), ("size", size), ("frames", frames), ("color", color), ("wetness", wetness)):
        if value is not None:
            chosen[key] = value
    if isinstance(chosen["size"], str):
        chosen["size"] = parse_size([chosen["size"]])
    try:
        width, height = chosen["size"]
        return exemplar_builtin.Params(
            preset=name,
            seed=_whole(chosen["seed"], "seed"),
            size=(_whole(width, "size"), _whole(height, "size")),
            frames=_whole(chosen["frames"], "frames"),
            color=str(chosen["color"]).lower(),
            wetness=float(chosen["wetness"]),
        )
    except (TypeError, ValueError):
        raise InputError(f"built-in exemplar {name!r}: expected seed and frames as whole numbers, size as "
                         f"[width, height], wetness as a number; got {chosen}") from None


def _whole(value, key):
    if isinstance(value, bool) or int(value) != value:
        raise ValueError(f"{key} must be a whole number")
    return int(value)


def parse_size(tokens) -> tuple[int, int] | None:
    """``["W", "H"]``, ``["WxH"]`` or ``["N"]`` (a square) to (width, height); ``None`` stays ``None``."""
    if tokens is None:
        return None
    if len(tokens) == 1 and _SIZE.match(tokens[0]):
        width, height = _SIZE.match(tokens[0]).groups()
    elif len(tokens) == 1 and tokens[0].isdigit():
        width = height = tokens[0]
    elif len(tokens) == 2 and all(token.isdigit() for token in tokens):
        width, height = tokens
    else:
        raise InputError(f"--size: expected `N`, `W H` or `WxH` (e.g. 256, 256 256 or 256x256), "
                         f"got {' '.join(tokens)!r}")
    return int(width), int(height)
