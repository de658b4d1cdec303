"""YAML loading that remembers the line of every value, so errors can point at it."""

from __future__ import annotations

from pathlib import Path

import yaml

from fluidymation.errors import SceneError

MAX_NODES = 200_000  # guards against alias bombs ("billion laughs")
MAX_DEPTH = 100  # nesting deeper than any scene needs (and than Python's recursion allows)

KeyPath = tuple  # of str (mapping keys) and int (sequence indices)


class LocatedYaml:
    """A parsed YAML document plus the 1-based line of each value, by key path."""

    def __init__(self, data, lines: dict[KeyPath, int], filename: str):
        self.data = data
        self.lines = lines
        self.filename = filename

    def line_of(self, path: KeyPath) -> int | None:
        """Line of ``path``, or of its nearest ancestor that has one."""
        path = tuple(path)
        while path not in self.lines and path:
            path = path[:-1]
        return self.lines.get(path)


def load_yaml(path: Path) -> LocatedYaml:
    """Parse ``path`` as YAML (safe loader), recording the line of every value."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: cannot be read as UTF-8 text ({exc})") from None
    loader = yaml.SafeLoader(text)
    try:
        root = loader.get_single_node()
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f", line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise SceneError(f"{path}{where}: malformed YAML: {problem}") from None
    except RecursionError:
        raise SceneError(f"{path}: malformed YAML: nested too deeply") from None
    finally:
        loader.dispose()
    if root is None:
        raise SceneError(f"{path}: the scene file is empty")
    lines: dict[KeyPath, int] = {}
    data = _build(root, (), lines, str(path), [0])
    return LocatedYaml(data, lines, str(path))


def _build(node, path: KeyPath, lines: dict, filename: str, count: list):
    count[0] += 1
    if count[0] > MAX_NODES:
        raise SceneError(f"{filename}: too many YAML values (over {MAX_NODES}); are aliases nested?")
    if len(path) > MAX_DEPTH:
        raise SceneError(f"{filename}, line {node.start_mark.line + 1}: values nested more than {MAX_DEPTH} deep")
    lines[path] = node.start_mark.line + 1
    if isinstance(node, yaml.MappingNode):
        result = {}
        for key_node, value_node in node.value:
            key = _scalar(key_node, filename)
            if key in result:
                raise SceneError(f"{filename}, line {key_node.start_mark.line + 1}: duplicate key '{key}'")
            result[key] = _build(value_node, path + (key,), lines, filename, count)
            lines[path + (key,)] = key_node.start_mark.line + 1
        return result
    if isinstance(node, yaml.SequenceNode):
        return [_build(item, path + (index,), lines, filename, count) for index, item in enumerate(node.value)]
    return _scalar(node, filename)


def _scalar(node, filename: str):
    if not isinstance(node, yaml.ScalarNode):
        raise SceneError(f"{filename}, line {node.start_mark.line + 1}: a mapping key must be a plain value")
    try:
        return yaml.SafeLoader("").construct_object(node)
    except yaml.YAMLError as exc:
        raise SceneError(f"{filename}, line {node.start_mark.line + 1}: {exc}") from None
