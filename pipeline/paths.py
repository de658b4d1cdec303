"""Where fluidymation keeps data shared between renders (generated exemplars and their guides)."""

from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path:
    """The user cache folder: ``$FLUIDYMATION_CACHE``, else ``$XDG_CACHE_HOME/fluidymation``, else
    ``~/.cache/fluidymation``."""
    chosen = os.environ.get("FLUIDYMATION_CACHE")
    if chosen:
        return Path(chosen).expanduser()
    base = os.environ.get("XDG_CACHE_HOME")
    return (Path(base).expanduser() if base else Path.home() / ".cache") / "fluidymation"


def exemplar_cache_dir() -> Path:
    """Generated built-in exemplars."""
    return cache_dir() / "exemplars"


def exemplar_guides_cache_dir() -> Path:
    """Guidance channels of exemplars, one folder per exemplar and guide parameters."""
    return cache_dir() / "exemplar-guides"
