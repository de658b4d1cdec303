"""CSS animations in SVG files: masks against Chromium's frames, and the timing, easing, interpolation and cascade
rules they rest on; what is not played is reported, and --strict refuses it."""

import copy
import math
import re
from pathlib import Path
from xml.etree import ElementTree

import imageio.v3 as iio
import numpy as np
import pytest
import tinycss2

from fluidymation.stages.vector import open_document
from fluidymation.stages.vector.cairosvg_renderer import CairoSvgRenderer
from fluidymation.stages.vector.css_animation import parse_css_animation
from fluidymation.stages.vector.css_selectors import DocumentIndex, parse_selector_list
from fluidymation.stages.vector.css_stylesheet import parse_shorthand
from fluidymation.stages.vector.css_syntax import tokens
from fluidymation.stages.vector.css_timing import EASE, CubicBezier, Steps, Timing, parse_easing
from fluidymation.stages.vector.css_transform import (Box, Function, decompose, interpolate, interpolate_matrices,
                                                      matrix_of, parse_css_transform, parse_svg_transform, recompose,
                                                      resolve)
from fluidymation.stages.vector.css_values import PROPERTIES, Keyword

from tests.scenes import ROOT, blob_scene, write_scene

FIXTURES = Path(__file__).parents[1] / "data" / "svg_animated"
_REFERENCE = re.compile(r"<!--\s*reference:\s*size\s+(\d+)x(\d+),\s*times\s+([0-9.\s]+?)\s*-->")


def _reference_spec(path: Path) -> tuple[tuple[int, int], list[float]]:
    match = _REFERENCE.search(path.read_text())
    return (int(match.group(1)), int(match.group(2))), [float(t) for t in match.group(3).split()]


def masks(document, time_seconds, size):
    """Every layer's coverage ≥ 0.5, unioned, as the document and the cairosvg renderer draw them."""
    union = np.zeros((size[1], size[0]), bool)
    for layer in document.layers:
        union |= CairoSvgRenderer().render(document, [layer.name], time_seconds, size)[..., 3] / 255 >= 0.5
    return union


@pytest.mark.parametrize("fixture", sorted(FIXTURES.glob("css-*.svg")), ids=lambda path: path.stem)
def test_masks_match_chromium(fixture):
    size, times = _reference_spec(fixture)
    document = open_document(fixture)
    assert document.layers and document.animations
    for time_seconds in times:
        ours = masks(document, time_seconds, size)
        reference = iio.imread(FIXTURES / "reference" / fixture.stem / f"{time_seconds:g}.png") / 255 >= 0.5
        iou = (ours & reference).sum() / (ours | reference).sum()
        assert iou >= 0.98, f"{fixture.name} at {time_seconds} s: IoU {iou:.3f} with Chromium"


def _svg(style: str, body: str = '<g id="a"><rect id="r" class="c" width="10" height="10"/></g>'):
    root = ElementTree.fromstring(f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">'
                                  f"<style>{style}</style>{body}</svg>")
    return root, parse_css_animation(root, "test.svg")


def _styles_at(root, animation, time_seconds) -> dict[str, str]:
    """The style declarations the animation writes on each element with an id, at a time."""
    copies = {}
    copied = copy.deepcopy(root, copies)
    animation.apply(lambda element: copies[id(element)], time_seconds)
    return {element.get("id"): element.get("style") for element in copied.iter() if element.get("id")}


# Easing functions (CSS Easing 1).

def test_named_easings_and_cubic_bezier():
    assert parse_easing(tokens("linear")[0])(0.3) == 0.3
    assert EASE(0.5) == pytest.approx(0.8024033877399112, abs=1e-6)
    assert parse_easing(tokens("ease-in-out")[0])(0.5) == pytest.approx(0.5)
    overshoot = CubicBezier(0.3, -0.6, 0.7, 1.6)
    assert overshoot(0.2) < 0 and overshoot(0.8) > 1 and overshoot(1.0) == 1.0


@pytest.mark.parametrize("function, samples", [
    ("steps(4, jump-start)", {0.0: 0.25, 0.1: 0.25, 0.3: 0.5, 0.99: 1.0}),
    ("steps(4)", {0.0: 0.0, 0.1: 0.0, 0.3: 0.25, 0.99: 0.75, 1.0: 1.0}),
    ("steps(3, jump-none)", {0.0: 0.0, 0.4: 0.5, 0.7: 1.0}),
    ("steps(2, jump-both)", {0.0: 1 / 3, 0.6: 2 / 3, 1.0: 1.0}),
    ("step-start", {0.0: 1.0, 0.5: 1.0}),
    ("step-end", {0.0: 0.0, 0.99: 0.0, 1.0: 1.0}),
])
def test_steps(function, samples):
    easing = parse_easing(tokens(function)[0])
    assert {progress: easing(progress) for progress in samples} == pytest.approx(samples)


def test_invalid_steps_are_refused():
    with pytest.raises(ValueError):
        Steps(1, "jump-none")
    with pytest.raises(ValueError):
        CubicBezier(1.5, 0, 0, 1)


# Where an animation is at a time (Web Animations 1).

def test_delay_and_fill_modes():
    for fill, before, after in (("none", None, None), ("forwards", None, 1.0), ("backwards", 0.0, None),
                                ("both", 0.0, 1.0)):
        timing = Timing(duration=1.0, delay=0.5, fill=fill)
        assert timing.progress(0.2) == before and timing.progress(2.0) == after
        assert timing.progress(1.0) == pytest.approx(0.5)


def test_directions_and_iteration_counts():
    progress = {direction: Timing(1.0, iterations=3, direction=direction).progress(1.25)
                for direction in ("normal", "reverse", "alternate", "alternate-reverse")}
    assert progress == pytest.approx({"normal": 0.25, "reverse": 0.75, "alternate": 0.75,
                                      "alternate-reverse": 0.25})
    assert Timing(1.0, iterations=2.5, fill="forwards").progress(9.0) == pytest.approx(0.5)
    assert Timing(1.0, iterations=2, direction="alternate", fill="forwards").progress(9.0) == 0.0
    assert Timing(1.0, iterations=math.inf).progress(1000.4) == pytest.approx(0.4)
    assert Timing(1.0, iterations=1, fill="forwards").progress(1.0) == 1.0


def test_negative_delay_and_paused():
    assert Timing(1.0, delay=-0.25, iterations=math.inf).progress(0.0) == pytest.approx(0.25)
    assert Timing(1.0, delay=-2.0, fill="forwards").progress(0.0) == 1.0
    assert Timing(1.0, delay=-2.0).progress(0.0) is None
    assert Timing(1.0, delay=-0.3, paused=True).progress(5.0) == pytest.approx(0.3)


def test_duration_rule():
    """The default range ends with the longest animation: finite ones at their end, infinite ones after one cycle."""
    assert Timing(2.0, delay=0.5, iterations=1.5).end() == 3.5
    assert Timing(0.8, delay=-0.8, iterations=math.inf).end() == 0.8
    assert Timing(0.8, delay=0.3, iterations=math.inf).end() == pytest.approx(1.1)
    assert Timing(1.0, paused=True).end() == 0.0
    root, animation = _svg(".c{animation: a 1s 2, a 0.75s infinite -0.2s} @keyframes a{to{opacity:0}}")
    assert animation.duration() == 2.0


# Interpolation (CSS Transforms 1 and 2, CSS Values).

def _transform(text, box=Box(0, 0, 100, 100)):
    return resolve(parse_css_transform(tokens(text)), box)


def test_matching_transform_lists_interpolate_per_function():
    assert interpolate(_transform("rotate(0deg)"), _transform("rotate(2turn)"), 0.25) == (Function("rotate", (180.0,)),)
    assert interpolate((), _transform("translate(10px, 20%) scale(3)"), 0.5) == (
        Function("translate", (5.0, 10.0)), Function("scale", (2.0, 2.0)))


def test_mismatched_transform_lists_interpolate_as_decomposed_matrices():
    """skewX → skew has no common primitive; Chromium draws the half-way square 73.9 px wide (measured)."""
    (blended,) = interpolate(_transform("skewX(40deg)"), _transform("skew(0deg, 40deg)"), 0.5)
    a, b, c, d, _, _ = blended.arguments
    assert blended.name == "matrix" and 50 * (a + c) == pytest.approx(73.87, abs=0.01)
    prefix = interpolate(_transform("translate(0px) rotate(0deg)"),
                         _transform("translate(20px) scale(2) rotate(90deg)"), 0.5)
    assert prefix[0] == Function("translate", (10.0, 0.0)) and prefix[1].name == "matrix"


def test_matrix_decomposition_round_trips_and_singular_matrices_flip_half_way():
    rng = np.random.default_rng(1)
    for matrix in rng.uniform(-3, 3, (200, 6)):
        assert recompose(decompose(tuple(matrix))) == pytest.approx(tuple(matrix))
    singular, turned = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 1.0, -1.0, 0.0, 0.0, 0.0)
    assert interpolate_matrices(singular, turned, 0.4) == singular
    assert interpolate_matrices(singular, turned, 0.6) == turned
    quarter = interpolate_matrices((1.0, 0.0, 0.0, 1.0, 0.0, 0.0), turned, 0.5)
    assert quarter == pytest.approx(matrix_of((Function("rotate", (45.0,)),)))


def test_svg_transform_attribute_syntax():
    assert parse_svg_transform(tokens("translate(12, 12) scale(0)")) == parse_css_transform(
        tokens("translate(12px, 12px) scale(0)"))
    assert matrix_of(resolve(parse_svg_transform(tokens("rotate(90 10 10)")), Box(0, 0, 0, 0))) == pytest.approx(
        (0.0, 1.0, -1.0, 0.0, 20.0, 0.0))


def test_colours_dash_arrays_visibility_and_discrete_values():
    fill = PROPERTIES["fill"].kind
    transparent, red = fill.parse(tokens("transparent")), fill.parse(tokens("#ff0000"))
    assert fill.interpolate(transparent, red, 0.5) == pytest.approx((1.0, 0.0, 0.0, 0.5))
    assert fill.interpolate(Keyword("none"), red, 0.49) == Keyword("none")
    assert fill.interpolate(Keyword("none"), red, 0.5) == red
    dashes = PROPERTIES["stroke-dasharray"].kind
    assert dashes.interpolate((10.0, 20.0), (20.0, 40.0, 60.0), 0.5) == pytest.approx(
        (15.0, 30.0, 35.0, 20.0, 25.0, 40.0))  # (10 20 10 20 10 20) to (20 40 60 20 40 60)
    visibility = PROPERTIES["visibility"].kind
    hidden, visible = Keyword("hidden"), Keyword("visible")
    assert [visibility.interpolate(hidden, visible, p) for p in (0.0, 0.1, 0.9, 1.0)] == [hidden] + [visible] * 3
    assert PROPERTIES["opacity"].kind.serialize(1.3) == "1"


# The cascade, the shorthand and the keyframes.

def test_shorthand_assigns_keywords_by_position():
    parsed = parse_shorthand(tokens("ease ease 1s 2s, infinite linear spin"))
    assert parsed["animation-name"] == ("ease", "spin")
    assert parsed["animation-timing-function"][0] is EASE
    assert parsed["animation-duration"] == (1.0, 0.0) and parsed["animation-delay"] == (2.0, 0.0)
    assert parsed["animation-iteration-count"] == (1.0, math.inf)


def test_selector_specificity():
    root = ElementTree.fromstring('<svg><g class="row"><rect id="x" class="a b"/></g></svg>')
    index = DocumentIndex(root)
    rect = root.find(".//rect")
    found = {text: [(s.matches(rect, index), s.specificity) for s in parse_selector_list(
        tinycss2.parse_component_value_list(text))] for text in (".row > rect.a", "#x", "g rect:nth-child(1)",
                                                                 "rect:not(.b)", "svg rect:hover")}
    assert found == {".row > rect.a": [(True, (0, 2, 1))], "#x": [(True, (1, 0, 0))],
                     "g rect:nth-child(1)": [(True, (0, 1, 2))], "rect:not(.b)": [(False, (0, 1, 1))],
                     "svg rect:hover": [(False, (0, 1, 2))]}


def test_cascade_style_attribute_important_and_inheritance():
    root, animation = _svg(
        "@keyframes fade { to { opacity: 0; fill-opacity: 0.5 } } "
        "rect { animation: fade 1s linear; } #r { animation-duration: 2s } .c { animation-duration: 4s }"
        ".forced { animation-duration: 10s !important }",
        '<g id="a"><rect id="r" class="c" width="10" height="10"/>'
        '<rect id="s" class="forced" style="animation-duration: 1s" width="10" height="10"/></g>')
    styles = _styles_at(root, animation, 0.5)
    assert styles["r"] == "opacity:0.75;fill-opacity:0.875"
    assert styles["s"] == "animation-duration: 1s;opacity:0.95;fill-opacity:0.975"


def test_missing_keyframes_use_the_element_value_and_later_animations_win():
    root, animation = _svg("@keyframes grow { 50% { r: 30px } } @keyframes move { to { cx: 60px } }"
                           "@keyframes jump { to { cx: 90px } }"
                           "circle { animation: grow 1s linear, move 1s linear, jump 1s linear; r: 20px }",
                           '<g id="a"><circle id="c" cx="0" r="10"/></g>')
    assert _styles_at(root, animation, 0.25)["c"] == "r:25;cx:33.75"  # jump starts from move's 15


def test_transform_origin_and_fill_box_are_folded_into_one_matrix():
    root, animation = _svg("@keyframes turn { to { transform: rotate(90deg) } }"
                           "#r { transform-box: fill-box; transform-origin: center;"
                           "     animation: turn 1s linear forwards }"
                           "#v { transform-origin: 50% 50%; animation: turn 1s linear forwards }",
                           '<g id="a"><rect id="r" x="10" y="10" width="20" height="10"/>'
                           '<rect id="v" width="10" height="10"/></g>')
    styles = _styles_at(root, animation, 2.0)
    numbers = [float(n) for n in re.findall(r"-?[\d.e-]+", styles["r"].split("matrix(")[1].split(")")[0])]
    assert numbers == pytest.approx([0, 1, -1, 0, 35, -5], abs=1e-9)  # about (20, 15), the box's centre
    numbers = [float(n) for n in re.findall(r"-?[\d.e-]+", styles["v"].split("matrix(")[1].split(")")[0])]
    assert numbers == pytest.approx([0, 1, -1, 0, 100, 0], abs=1e-9)  # about (50, 50), the viewBox's centre
    assert styles["r"].endswith("transform-origin:0 0")


def test_a_file_without_animation_is_not_parsed():
    root = ElementTree.fromstring('<svg xmlns="http://www.w3.org/2000/svg"><style>rect{fill:red}</style></svg>')
    assert parse_css_animation(root, "still.svg") is None


# What is not played is reported.

def test_unsupported_css_is_reported_naming_the_rule_or_element():
    root, animation = _svg(
        "@keyframes spin { to { filter: blur(2px); transform: rotate3d(1, 0, 0, 40deg); opacity: var(--o) } }"
        "@media (min-width: 10px) { rect { fill: red } }"
        "@media (prefers-reduced-motion: reduce) { * { animation: none } }"
        "@media screen { .c { fill: red } } @supports (display: grid) { }"
        ".c:focus-visible:blink { fill: red }"
        "rect { animation: spin 1s linear(0, 1), none 2s; animation-composition: add; transform-box: stroke-box }"
        "#r { animation-name: ghost }",
        '<g id="a"><rect id="r" class="c" width="10" height="10"/><rect style="opacity: calc(1)"/></g>')
    reported = {(item.element, item.message.split(";")[0]) for item in animation.unsupported}
    assert reported == {
        ("<style> @keyframes spin", "property 'filter' is not animated"),
        ("<style> @keyframes spin to", "'transform: rotate3d(1, 0, 0, 40deg)': the 3D transform function rotate3d() "
                                       "is not drawn"),
        ("<style> @keyframes spin to", "'opacity: var(--o)': var() is not evaluated"),
        ("<style> @media (min-width: 10px)", "this media query is not evaluated"),
        ("<style> @media screen .c", "fill: the rasterizer does not apply @media rules, so only their animations are "
                                     "played"),
        ("<style> @supports", "this at-rule is not applied"),
        ("<style> .c:focus-visible:blink", "the pseudo-class ':blink' in '.c:focus-visible:blink' is not matched"),
        ("<style> rect", "'animation: spin 1s linear(0, 1), none 2s': the linear() easing function with stops is not "
                         "evaluated"),
        ("<style> rect", "'animation-composition: add': only 'replace' is played"),
        ("<style> rect", "'transform-box: stroke-box': the stroke-box reference box is not computed"),
        ('<rect id="r">', "animation-name 'ghost' names no @keyframes rule"),
        ("<rect> #2 style", "'opacity: calc(1)': calc() is not evaluated"),
    }


def test_strict_check_refuses_an_unsupported_property(cli, tmp_path):
    fixture = FIXTURES / "css-unsupported-filter.svg"
    scene = write_scene(tmp_path, blob_scene(layers='  - {name: tint, color: "#2a6fdb"}\n').replace(
        str(ROOT / "examples/blob/blob.svg"), str(fixture)))
    code, _, err = cli("check", scene)
    assert code == 0 and "<style> @keyframes tint: property 'filter' is not animated" in err
    code, _, err = cli("--strict", "check", scene)
    assert code == 2 and "--strict: 1 unsupported element(s)" in err and "property 'filter'" in err
