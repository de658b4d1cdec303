"""SVG bytes to pixels with cairosvg, in memory, with external fetching refused."""

from __future__ import annotations

import re

import cairocffi
import cairosvg.parser
import cairosvg.surface
import numpy as np

from fluidymation.errors import InputError
from fluidymation.stages.vector.safety import refuse_fetch


def render_svg(svg: bytes, size: tuple[int, int], source: str) -> np.ndarray:
    """Render ``svg`` at ``size`` = (width, height) px.

    Returns
    -------
    (H, W, 4) uint8 RGBA, colour premultiplied by alpha (as cairo stores it).
    """
    width, height = size
    try:
        tree = cairosvg.parser.Tree(bytestring=svg, url_fetcher=refuse_fetch, unsafe=False)
        _refuse_huge_radii(tree, source)
        surface = cairosvg.surface.PNGSurface(tree, None, 96, output_width=width, output_height=height)
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    except (ValueError, TypeError, KeyError, IndexError, AttributeError, ZeroDivisionError) as exc:
        raise InputError(f"{source}: cannot be rendered as SVG ({type(exc).__name__}: {exc})") from None
    except cairocffi.CairoError as exc:  # cairo refuses what cairosvg passes on, e.g. an ellipse of ry="nan"
        raise InputError(f"{source}: cannot be rendered as SVG (cairo: {exc.args[0] if exc.args else exc}; "
                         "is a length or transform not a finite number?)") from None
    image = surface.cairo
    image.flush()
    stride = image.get_stride()
    rows = np.frombuffer(image.get_data(), dtype=np.uint8).reshape(image.get_height(), stride)
    bgra = rows[:, : image.get_width() * 4].reshape(image.get_height(), image.get_width(), 4)
    if bgra.shape[:2] != (height, width):
        raise InputError(f"{source}: rendered at {bgra.shape[1]}x{bgra.shape[0]} instead of {width}x{height}")
    return _bgra_to_rgba(bgra)


#: Radii beyond this (user units) are refused: cairo's arc loops for ever on radii near 1e308.
MAX_RADIUS = 1e7
_RADII = {"circle": ("r",), "ellipse": ("rx", "ry"), "rect": ("rx", "ry")}
_LEADING_NUMBER = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def _refuse_huge_radii(node, source: str) -> None:
    """An InputError naming the element whose circle or ellipse radius is beyond :data:`MAX_RADIUS`."""
    pending = [node]
    while pending:
        node = pending.pop()
        for name in _RADII.get(node.tag, ()):
            match = _LEADING_NUMBER.match(node.get(name) or "")
            if match and not abs(float(match.group(1))) <= MAX_RADIUS:
                raise InputError(f"{source}: <{node.tag} {name}=\"{node.get(name)}\">: a radius beyond "
                                 f"{MAX_RADIUS:g} cannot be drawn")
        pending.extend(node.children)


def _bgra_to_rgba(bgra: np.ndarray) -> np.ndarray:
    """Cairo's BGRA bytes as RGBA, one channel at a time (fancy indexing the channels is 7× slower)."""
    rgba = np.empty_like(bgra)
    for target, source in enumerate((2, 1, 0, 3)):
        rgba[:, :, target] = bgra[:, :, source]
    return rgba
