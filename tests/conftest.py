"""Shared fixtures."""

import os

import pytest

os.environ.setdefault("NUMBA_NUM_THREADS", "2")


@pytest.fixture
def cli(capsys):
    """Run ``fluidymation ARGS`` in-process; return (exit code, stdout, stderr)."""
    from fluidymation.pipeline.cli import main

    def run(*args):
        code = main([str(a) for a in args])
        out, err = capsys.readouterr()
        return code, out, err

    return run


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true",
                     help="rewrite the golden frames of tests/golden/ from this run's renders")


@pytest.fixture
def update_golden(request) -> bool:
    return request.config.getoption("--update-golden")
