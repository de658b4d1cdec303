"""The ``lottie-svg`` renderer: a Lottie document through the lottie package's SVG builder, then cairosvg."""

from __future__ import annotations

from xml.etree import ElementTree

from lottie.parsers.svg.builder import to_svg

from fluidymation.stages.vector.base import Renderer
from fluidymation.stages.vector.raster import render_svg


class LottieSvgRenderer(Renderer):
    """Draws Lottie documents as the SVG of one frame, rasterized by cairosvg."""

    name = "lottie-svg"
    version = 1
    kinds = ("lottie", "dotlottie", "tgs")

    def render(self, document, layers, time_seconds, size):
        animation, frame = document.isolate(layers, time_seconds)
        svg = ElementTree.tostring(to_svg(animation, frame).getroot())
        return render_svg(svg, size, str(document.path))
