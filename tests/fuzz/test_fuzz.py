"""A fixed-seed subset of the readers' fuzzing (tests/fuzz/harness.py, readers.py): mutated scenes, Lottie files,
dotLottie archives, .tgs stickers, SVGs and SVG sequences through ``fluidymation check`` (a few through ``masks``),
recorded exemplars through ``render --until stylize``, flow files through ``guides --flow`` and ``exemplar show``;
every case exit 0 or 2 with a message naming the file, in time, in bounded memory, reading and writing only where
it may. The long run is ``python -m tests.fuzz --cases 10000``."""

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings, strategies as st, given

from tests.fuzz.harness import run_case
from tests.fuzz.readers import READERS

SEEDS = {}  # reader → its seeds, made on first use
FIXED = settings(derandomize=True, deadline=None, database=None, print_blob=True,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def assert_holds(reader, rng, **options):
    maker, seeds, _ = READERS[reader]
    if reader not in SEEDS:
        SEEDS[reader] = seeds()
    case = maker(rng, SEEDS[reader], **options)
    with tempfile.TemporaryDirectory(prefix=f"fuzz-{reader}-") as folder:
        outcome = run_case(case, Path(folder))
        problem = outcome.problem(case, Path(folder))
    assert problem is None, f"{case.label} ({case.argv}): {problem}\n{outcome.stderr[-2000:]}"


#: Cases per reader in the suite.
CASES = {"scene": 150, "lottie": 100, "svg": 120, "dotlottie": 40, "tgs": 40, "svgseq": 30, "exemplar": 30, "flow": 40}


@pytest.mark.parametrize("reader", sorted(CASES))
def test_mutations(reader):
    @settings(FIXED, max_examples=CASES[reader])
    @given(st.randoms(use_true_random=False))
    def holds(rng):
        assert_holds(reader, rng)

    holds()


@pytest.mark.parametrize("reader", ["lottie", "svg", "dotlottie", "tgs", "svgseq"])
@settings(FIXED, max_examples=5)
@given(rng=st.randoms(use_true_random=False))
def test_masks_of_mutations(reader, rng):
    assert_holds(reader, rng, masks=True)
