"""Fixtures of the pipeline tests."""

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]


@pytest.fixture
def command_line(tmp_path):
    """``command_line(*args)``: argv and environment of a ``fluidymation`` subprocess, user cache in ``tmp_path``."""
    env = os.environ | {"FLUIDYMATION_CACHE": str(tmp_path / "cache"), "NUMBA_CACHE_DIR": str(ROOT / ".numba-cache")}

    def command(*args):
        return [sys.executable, "-m", "fluidymation", *map(str, args)], env

    return command
