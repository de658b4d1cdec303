"""A fixed-seed subset of the readers' fuzzing (tests/fuzz/harness.py): mutated scenes, Lottie files and SVGs
through ``fluidymation check`` (a few through ``masks``), every case exit 0 or 2 with a message naming the file.
The long run is ``python -m tests.fuzz --cases 10000``."""

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings, strategies as st, given

from tests.fuzz.harness import MAKERS, lottie_seeds, run_case, scene_seeds, svg_seeds

SEEDS = {"scene": scene_seeds(), "lottie": lottie_seeds(), "svg": svg_seeds()}
FIXED = settings(derandomize=True, deadline=None, database=None, print_blob=True,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def assert_holds(reader, rng, **options):
    case = MAKERS[reader](rng, SEEDS[reader], **options)
    with tempfile.TemporaryDirectory(prefix=f"fuzz-{reader}-") as folder:
        outcome = run_case(case, Path(folder))
        problem = outcome.problem(case, Path(folder))
    assert problem is None, f"{case.label} ({case.argv}): {problem}\n{outcome.stderr[-2000:]}"


@settings(FIXED, max_examples=150)
@given(st.randoms(use_true_random=False))
def test_scene_mutations(rng):
    assert_holds("scene", rng)


@settings(FIXED, max_examples=100)
@given(st.randoms(use_true_random=False))
def test_lottie_mutations(rng):
    assert_holds("lottie", rng)


@settings(FIXED, max_examples=120)
@given(st.randoms(use_true_random=False))
def test_svg_mutations(rng):
    assert_holds("svg", rng)


@pytest.mark.parametrize("reader", ["lottie", "svg"])
@settings(FIXED, max_examples=5)
@given(rng=st.randoms(use_true_random=False))
def test_masks_of_mutations(reader, rng):
    assert_holds(reader, rng, masks=True)
