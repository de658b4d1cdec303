"""Frames of an animated SVG as headless Chromium draws them: the independent reference for SMIL and CSS.

The SVG is inlined in a page that pauses its SMIL timeline (``pauseAnimations``,
``setCurrentTime``) and every CSS animation (``currentTime``) at the time named in the
page's URL, then screenshotted on a transparent background: the screenshot's alpha is
the coverage. The SVG is drawn at the requested size the way our rasterizer draws it
(scaled from its viewBox, or from its width and height when it has none). Needs
Debian's ``chromium`` (``/usr/bin/chromium``); used by the fixture script
``tests/data/svg_animated/make_references.py`` and the corpus benchmark, never by tests.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path
from xml.etree import ElementTree

import imageio.v3 as iio
import numpy as np

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
#: Headless windows smaller than this paint only their top rows: shoot a larger window and crop.
_MIN_WINDOW = 500
_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
          "--disable-background-networking", "--disable-component-update", "--disable-sync", "--hide-scrollbars",
          "--default-background-color=00000000", "--force-device-scale-factor=1"]
_PAGE = """<!DOCTYPE html>
<html><head><style>html, body {{ margin: 0; padding: 0; background: transparent; overflow: hidden; }}
svg {{ display: block; }}</style></head>
<body>{svg}
<script>
const t = parseFloat(location.hash.slice(3));
const root = document.querySelector("svg");
if (root.pauseAnimations) {{ root.pauseAnimations(); root.setCurrentTime(t); }}
for (const animation of document.getAnimations()) {{ animation.pause(); animation.currentTime = t * 1000; }}
</script></body></html>
"""


def sized_svg(svg_text: str, size: tuple[int, int]) -> str:
    """The SVG with its root sized to ``size`` px, keeping (or making, from width/height) its viewBox."""
    ElementTree.register_namespace("", "http://www.w3.org/2000/svg")
    ElementTree.register_namespace("xlink", "http://www.w3.org/1999/xlink")
    root = ElementTree.fromstring(svg_text)
    if root.get("viewBox") is None:
        width, height = (float("".join(c for c in root.get(side, "0") if c in "0123456789.")) for side in
                         ("width", "height"))
        root.set("viewBox", f"0 0 {width:g} {height:g}")
    root.set("width", str(size[0]))
    root.set("height", str(size[1]))
    return ElementTree.tostring(root, encoding="unicode")


def coverage(svg_text: str, times: list[float], size: tuple[int, int], *, timeout: float = 60.0) -> list[np.ndarray]:
    """Chromium's coverage of the SVG at each of ``times`` (seconds): (H, W) float32 alpha in [0, 1]."""
    width, height = size
    frames = []
    with tempfile.TemporaryDirectory(prefix="chromium-") as folder:
        page = Path(folder) / "page.html"
        page.write_text(_PAGE.format(svg=sized_svg(svg_text, size)))
        for t in times:
            shot = Path(folder) / "shot.png"
            shot.unlink(missing_ok=True)
            subprocess.run([CHROMIUM, *_FLAGS, f"--user-data-dir={folder}/profile", f"--window-size={max(width, _MIN_WINDOW)},{max(height, _MIN_WINDOW)}",
                            f"--screenshot={shot}", f"file://{page}#t={t!r}"],
                           check=True, capture_output=True, timeout=timeout)
            image = iio.imread(shot)
            frames.append(image[:height, :width, 3].astype(np.float32) / 255.0)
    return frames
