"""Regenerate the browser reference frames of the animated-SVG fixtures in this folder.

Every ``*.svg`` here names its reference frames in a comment,
``<!-- reference: size 96x96, times 0 0.25 0.5 1.5 -->``; headless Chromium draws each
at those times (seconds) into ``reference/<name>/<time>.png``: 8-bit coverage (the
alpha of the page on a transparent background). Run from the repository root after
installing Debian's ``chromium``:

    .venv/bin/python tests/data/svg_animated/make_references.py [NAME.svg ...]
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np

sys.path.insert(0, str(Path(__file__).parents[3]))
from tests.references.chromium import coverage  # noqa: E402

HERE = Path(__file__).parent
_REFERENCE = re.compile(r"<!--\s*reference:\s*size\s+(\d+)x(\d+),\s*times\s+([0-9.\s]+?)\s*-->")


def reference_spec(svg_text: str) -> tuple[tuple[int, int], list[float]]:
    """The size and times a fixture's ``reference:`` comment names."""
    match = _REFERENCE.search(svg_text)
    if match is None:
        raise ValueError("no <!-- reference: size WxH, times T1 T2 ... --> comment")
    return (int(match.group(1)), int(match.group(2))), [float(t) for t in match.group(3).split()]


def reference_path(name: str, time: float) -> Path:
    return HERE / "reference" / name / f"{time:g}.png"


def main(names: list[str]) -> None:
    fixtures = [HERE / name for name in names] if names else sorted(HERE.glob("*.svg"))
    for fixture in fixtures:
        text = fixture.read_text()
        size, times = reference_spec(text)
        for time, frame in zip(times, coverage(text, times, size)):
            path = reference_path(fixture.stem, time)
            path.parent.mkdir(parents=True, exist_ok=True)
            iio.imwrite(path, np.round(frame * 255).astype(np.uint8))
        print(f"{fixture.name}: {len(times)} frames at {size[0]}x{size[1]}")


if __name__ == "__main__":
    main(sys.argv[1:])
