"""Finding stylizers: the ``fluidymation.stylizers`` entry-point group.

Every installed distribution may register stylizers in its metadata, for example in
``pyproject.toml``::

    [project.entry-points."fluidymation.stylizers"]
    fluidymation = "fluidymation.stages.fluidymation_stylizer:FluidymationStylizer"

The entry point's name is the scene's ``stylizer:`` value and must equal the class's
``name``; the class (a :class:`~fluidymation.stages.stylizer.Stylizer`) is imported only
when a scene uses it.
"""

from __future__ import annotations

from functools import cache
from importlib.metadata import EntryPoint, entry_points

from fluidymation.errors import StageError
from fluidymation.stages.stylizer import Stylizer

GROUP = "fluidymation.stylizers"


@cache
def _registered() -> dict[str, EntryPoint]:
    found: dict[str, EntryPoint] = {}
    for entry in entry_points(group=GROUP):
        found.setdefault(entry.name, entry)
    return found


def stylizer_names() -> tuple[str, ...]:
    """Names of every installed stylizer, sorted."""
    return tuple(sorted(_registered()))


@cache
def get_stylizer(name: str) -> Stylizer:
    """The installed stylizer called ``name``; a StageError names the entry point when it cannot be loaded."""
    entry = _registered().get(name)
    if entry is None:
        raise StageError(f"no stylizer called '{name}' is installed (installed: {', '.join(stylizer_names())})")
    try:
        loaded = entry.load()
    except Exception as exc:  # a third-party module may fail in any way on import
        raise StageError(f"stylizer '{name}' ({entry.value}, entry point of {GROUP}) cannot be loaded: "
                         f"{type(exc).__name__}: {exc}") from None
    if not (isinstance(loaded, type) and issubclass(loaded, Stylizer)):
        raise StageError(f"stylizer '{name}' ({entry.value}) is not a fluidymation.stages.stylizer.Stylizer class")
    if loaded.name != name:
        raise StageError(f"stylizer '{name}' ({entry.value}) calls itself '{loaded.name}'; the entry point's name "
                         "and the class's name must agree")
    return loaded()


def forget_installed() -> None:
    """Look the entry points up again on next use (after distributions were added to the path)."""
    _registered.cache_clear()
    get_stylizer.cache_clear()
