"""Typed access to a located YAML document, with errors that name file, line and key path.

Scene loading reads every value through a :class:`Checker`, so each message has the form
``scene.yaml, line 12: layers[2].params.w_temp: expected a number, got 'high'``.
"""

from __future__ import annotations

import difflib
import math
import os
import re
from pathlib import Path

from fluidymation.errors import SceneError
from fluidymation.pipeline.yaml_lines import KeyPath, LocatedYaml

_MISSING = object()
HEX_COLOR = re.compile(r"^#[0-9a-fA-F]{6}$")


def format_path(path: KeyPath) -> str:
    """('layers', 2, 'params') -> 'layers[2].params'."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(top level)"


class Checker:
    """Reads values out of a located YAML document, validating as it goes."""

    def __init__(self, doc: LocatedYaml):
        self.doc = doc
        self.base_dir = Path(doc.filename).resolve().parent

    def error(self, path: KeyPath, message: str) -> SceneError:
        line = self.doc.line_of(path)
        where = f"{self.doc.filename}, line {line}" if line else self.doc.filename
        return SceneError(f"{where}: {format_path(path)}: {message}")

    def value(self, path: KeyPath, default=_MISSING):
        node = self.doc.data
        for part in path:
            if isinstance(node, dict) and part in node:
                node = node[part]
            elif isinstance(node, list) and isinstance(part, int) and part < len(node):
                node = node[part]
            elif default is _MISSING:
                raise self.error(path, "is required")
            else:
                return default
        return node

    def has(self, path: KeyPath) -> bool:
        return self.value(path, None) is not None

    def mapping(self, path: KeyPath, allowed: tuple[str, ...] | None, *, required: bool = False) -> dict:
        """The mapping at ``path`` ({} when absent); unknown keys are errors with a suggestion."""
        data = self.value(path, _MISSING if required else None)
        if data is None:
            return {}
        if not isinstance(data, dict):
            raise self.error(path, f"expected a mapping of keys to values, got {_describe(data)}")
        for key in data:
            if not isinstance(key, str):
                raise self.error(path, f"keys must be text, got {key!r}")
            if allowed is not None and key not in allowed:
                raise self.error(path + (key,), f"unknown key '{key}'{_suggest(key, allowed, listing=True)}")
        return data

    def sequence(self, path: KeyPath, *, required: bool = False) -> list:
        data = self.value(path, _MISSING if required else None)
        if data is None:
            return []
        if not isinstance(data, list):
            raise self.error(path, f"expected a list, got {_describe(data)}")
        return data

    def integer(self, path: KeyPath, default=_MISSING, *, minimum=None, maximum=None) -> int:
        data = self.value(path, default)
        if data is None:
            return _absent(self, path, default)
        if isinstance(data, bool) or not isinstance(data, int):
            raise self.error(path, f"expected a whole number, got {_describe(data)}")
        _check_range(self, path, data, minimum, maximum)
        return data

    def number(self, path: KeyPath, default=_MISSING, *, minimum=None, maximum=None, above=None) -> float:
        data = self.value(path, default)
        if data is None:
            return _absent(self, path, default)
        if isinstance(data, bool) or not isinstance(data, (int, float)) or not math.isfinite(data):
            raise self.error(path, f"expected a number, got {_describe(data)}")
        if above is not None and not data > above:
            raise self.error(path, f"must be greater than {above}, got {data}")
        _check_range(self, path, data, minimum, maximum)
        return float(data)

    def boolean(self, path: KeyPath, default=_MISSING) -> bool:
        data = self.value(path, default)
        if not isinstance(data, bool):
            raise self.error(path, f"expected true or false, got {_describe(data)}")
        return data

    def text(self, path: KeyPath, default=_MISSING, *, choices: tuple[str, ...] | None = None) -> str:
        data = self.value(path, default)
        if data is None:
            return _absent(self, path, default)
        if not isinstance(data, str) or not data:
            raise self.error(path, f"expected text, got {'empty text' if data == '' else _describe(data)}")
        if choices is not None and data not in choices:
            raise self.error(path, f"'{data}' is not one of {', '.join(choices)}{_suggest(data, choices)}")
        return data

    def color(self, path: KeyPath, default=_MISSING) -> str:
        data = self.text(path, default)
        if data is not None and not HEX_COLOR.match(data):
            raise self.error(path, f"expected a colour as \"#rrggbb\", got {data!r}")
        return data.lower() if data else data

    def path(self, path: KeyPath, default=_MISSING) -> Path | None:
        """A file path, resolved relative to the scene file's folder."""
        data = self.text(path, default)
        if data is None:
            return None
        if "\0" in data:
            raise self.error(path, f"a file path cannot hold a NUL character, got {data!r}")
        if len(os.fsencode(data)) > 4096 or any(len(os.fsencode(part)) > 255 for part in Path(data).parts):
            raise self.error(path, f"file name too long ({len(data)} characters)")
        return (self.base_dir / Path(data).expanduser()).resolve()

    def text_list(self, path: KeyPath, default=_MISSING) -> list[str]:
        """A list of texts; a single text is accepted as a one-element list."""
        data = self.value(path, default)
        if data is None:
            return None
        if isinstance(data, str):
            data = [data]
        if not isinstance(data, list) or not data:
            raise self.error(path, f"expected a non-empty list of names, got {_describe(data)}")
        for index, item in enumerate(data):
            if not isinstance(item, str) or not item:
                raise self.error(path + (index,), f"expected a name, got {_describe(item)}")
        return list(data)


def _check_range(checker: Checker, path: KeyPath, value, minimum, maximum) -> None:
    if minimum is not None and value < minimum:
        raise checker.error(path, f"must be at least {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise checker.error(path, f"must be at most {maximum}, got {value}")


def _absent(check: Checker, path: KeyPath, default):
    """What a value written as null reads as: its default, unless it has none (it is required)."""
    if default is _MISSING:
        raise check.error(path, "is required, got nothing (null)")
    return default


def _describe(value) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{type(value).__name__} {value!r}"


def _suggest(word: str, choices, *, listing: bool = False) -> str:
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    if close:
        return f" (did you mean '{close[0]}'?)"
    return f"; valid keys: {', '.join(sorted(choices))}" if listing else ""
