"""The fuzzed readers: each one's case maker and seeds, by name (``--reader`` of the long run)."""

from tests.fuzz.harness import lottie_case, lottie_seeds, scene_case, scene_seeds, svg_case, svg_seeds
from tests.fuzz.packed import (dotlottie_case, dotlottie_seeds, svgseq_case, svgseq_seeds, tgs_case,
                               tgs_seeds)
from tests.fuzz.rasters import exemplar_case, exemplar_seeds, flow_case, flow_seeds

#: reader → (case maker, seeds maker, whether some of its cases may run ``masks``)
READERS = {"scene": (scene_case, scene_seeds, False), "lottie": (lottie_case, lottie_seeds, True),
           "svg": (svg_case, svg_seeds, True), "dotlottie": (dotlottie_case, dotlottie_seeds, True),
           "tgs": (tgs_case, tgs_seeds, True), "svgseq": (svgseq_case, svgseq_seeds, True),
           "exemplar": (exemplar_case, exemplar_seeds, False), "flow": (flow_case, flow_seeds, False)}
