"""The ``cairosvg`` renderer: plain SVG documents (static or a sequence) rasterized by cairosvg."""

from __future__ import annotations

from fluidymation.stages.vector.base import Renderer


class CairoSvgRenderer(Renderer):
    """Draws the SVG a plain-SVG document gives for the layers and time."""

    name = "cairosvg"
    version = 1
    kinds = ("svg", "svg-sequence")

    def render(self, document, layers, time_seconds, size):
        from fluidymation.stages.vector.raster import render_svg  # cairo: loaded when something is drawn

        svg, source = document.isolate(layers, time_seconds)
        return render_svg(svg, size, source)
