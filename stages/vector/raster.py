"""SVG bytes to pixels with cairosvg, in memory, with external fetching refused."""

from __future__ import annotations

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


def _bgra_to_rgba(bgra: np.ndarray) -> np.ndarray:
    """Cairo's BGRA bytes as RGBA, one channel at a time (fancy indexing the channels is 7× slower)."""
    rgba = np.empty_like(bgra)
    for target, source in enumerate((2, 1, 0, 3)):
        rgba[:, :, target] = bgra[:, :, source]
    return rgba
