"""SMIL timeline: masks against Chromium's frames of hand-written fixtures, and the timing, interpolation and
sandwich rules of SVG 1.1 one by one, with what is reported as unsupported."""

import copy
import importlib.util
from pathlib import Path
from xml.etree import ElementTree

import imageio.v3 as iio
import numpy as np
import pytest

from fluidymation.errors import InputError
from fluidymation.stages.vector import open_document, renderer_for
from fluidymation.stages.vector.smil import eased, parse_smil
from fluidymation.stages.vector.smil_timing import clock_value
from fluidymation.stages.vector.svg_reader import style_property

from tests.scenes import write_scene

FIXTURES = Path(__file__).parents[1] / "data" / "svg_animated"
_spec = importlib.util.spec_from_file_location("make_references", FIXTURES / "make_references.py")
make_references = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_references)
IOU_MIN = 0.98


def svg(body: str) -> str:
    return (f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="100" '
            f'height="100">{body}</svg>')


def smil(body: str):
    return parse_smil(ElementTree.fromstring(svg(body)), "test.svg")


def intervals(body: str, index: int = 0, time: float = 0.0) -> list[tuple[float, float]]:
    """The active intervals of the ``index``-th animation element, rounded to microseconds."""
    timeline = smil(body).timeline(time)
    return [(round(i.begin, 6), round(i.end, 6)) for i in timeline.intervals[index] if i.begin < 20]


def value_at(body: str, time: float, element_id: str, name: str) -> str | None:
    """The attribute (or style property) ``name`` of element ``element_id`` at ``time``."""
    root = ElementTree.fromstring(svg(body))
    animation = parse_smil(root, "test.svg")
    copies = {}
    shown = copy.deepcopy(root, copies)
    animation.apply(lambda element: copies[id(element)], time)
    element = shown.find(f".//*[@id='{element_id}']")
    return style_property(element, name) or element.get(name)


def number_at(body: str, time: float, element_id: str, name: str) -> float:
    return float(value_at(body, time, element_id, name))


def messages(body: str) -> list[str]:
    return [f"{item.element}: {item.message}" for item in smil(body).unsupported]


# --- against the browser ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("fixture", sorted(path.name for path in FIXTURES.glob("smil-*.svg")))
def test_masks_match_chromium(fixture):
    path = FIXTURES / fixture
    size, times = make_references.reference_spec(path.read_text())
    document = open_document(path)
    renderer = renderer_for(document)
    assert (document.kind, renderer.name) == ("svg", "cairosvg")
    for time in times:
        ours = renderer.render(document, document.layer_names(), time, size)[:, :, 3] >= 128
        reference = iio.imread(make_references.reference_path(path.stem, time)) >= 128
        union = (ours | reference).sum()
        score = 1.0 if union == 0 else (ours & reference).sum() / union
        assert score >= IOU_MIN, f"{fixture} at {time:g} s: IoU {score:.3f}"


# --- timing ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("text,seconds", [("02:30", 150), ("1:02:03.5", 3723.5), ("1.5s", 1.5), ("250ms", 0.25),
                                          ("2", 2), ("1.5min", 90), ("0.5h", 1800), (".5s", 0.5),
                                          ("1:60:00", None), ("abc", None), ("-1s", None)])
def test_clock_values(text, seconds):
    assert clock_value(text) == seconds


def test_begin_and_end_lists():
    assert intervals('<rect><animate attributeName="x" to="9" begin="1s;3s" dur="1s"/></rect>') == [(1, 2), (3, 4)]
    assert intervals('<rect><animate attributeName="x" to="9" dur="2s" end="0.5s;3.5s"/></rect>') == [(0, 0.5)]
    assert intervals('<rect><animate attributeName="x" to="9" begin="0;1s" end="2s" restart="whenNotActive"/>'
                     '</rect>') == [(0, 2)]  # no dur: the end alone bounds it
    assert intervals('<rect><animate attributeName="x" to="9" begin="-0.5s" dur="1s"/></rect>') == [(-0.5, 0.5)]
    assert intervals('<rect><animate attributeName="x" to="9" begin="-2s" dur="1s"/></rect>') == []


def test_indefinite_and_event_begins_never_start():
    assert intervals('<rect><animate attributeName="x" to="9" begin="indefinite" dur="1s"/></rect>') == []
    assert intervals('<rect><animate attributeName="x" to="9" begin="click" dur="1s"/></rect>') == []
    assert intervals('<rect id="r"><animate attributeName="x" to="9" begin="r.click;1s" dur="1s"/></rect>') == [(1, 2)]


def test_syncbases_chain_and_cycle():
    body = ('<rect><animate id="a" attributeName="x" to="9" begin="0;b.end" dur="1s"/>'
            '<animate id="b" attributeName="y" to="9" begin="a.end+0.5s" dur="0.5s"/>'
            '<animate attributeName="width" to="9" begin="b.begin-0.25s" dur="0.1s"/></rect>')
    assert intervals(body, 0)[:3] == [(0, 1), (2, 3), (4, 5)]
    assert intervals(body, 1)[:3] == [(1.5, 2), (3.5, 4), (5.5, 6)]
    assert intervals(body, 2)[:2] == [(1.25, 1.35), (3.25, 3.35)]


def test_repeat_syncbase():
    body = ('<rect><animate id="a" attributeName="x" to="9" dur="1s" repeatCount="3"/>'
            '<animate attributeName="y" to="9" begin="a.repeat(2)+0.1s" dur="1s"/></rect>')
    assert intervals(body, 1) == [(2.1, 3.1)]


def test_a_cycle_of_zero_length_intervals_settles():
    body = ('<rect><animate id="a" attributeName="x" to="9" begin="0;b.end" end="a.begin"/>'
            '<animate id="b" attributeName="y" to="9" begin="a.end" end="b.begin"/></rect>')
    assert intervals(body, 0) == [(0, 0)] and intervals(body, 1) == [(0, 0)]


@pytest.mark.parametrize("restart,expected", [("always", [(0, 0.5), (0.5, 1.5), (2, 3)]),
                                              ("whenNotActive", [(0, 1), (2, 3)]), ("never", [(0, 1)])])
def test_restart(restart, expected):
    body = f'<rect><animate attributeName="x" to="9" begin="0;0.5s;2s" dur="1s" restart="{restart}"/></rect>'
    assert intervals(body) == expected


@pytest.mark.parametrize("attributes,end", [('repeatCount="2.5"', 2.5), ('repeatDur="1.6s"', 1.6),
                                            ('repeatCount="3" repeatDur="2.2s"', 2.2), ('max="0.6s"', 0.6),
                                            ('min="3s"', 3), ('min="2s" max="1s"', 1),
                                            ('repeatCount="indefinite" end="4s"', 4)])
def test_active_duration(attributes, end):
    assert intervals(f'<rect><animate attributeName="x" to="9" dur="1s" {attributes}/></rect>') == [(0, end)]


def test_min_extends_the_interval_with_the_fill():
    body = '<rect id="r" x="0"><animate attributeName="x" from="0" to="10" dur="1s" min="2s" fill="{}"/></rect>'
    assert value_at(body.format("remove"), 1.5, "r", "x") == "0"  # the extra time is filled as fill says
    assert value_at(body.format("freeze"), 1.5, "r", "x") == "10"
    assert value_at(body.format("freeze"), 0.5, "r", "x") == "5"


def test_a_time_far_ahead_does_not_change_nearer_frames(tmp_path):
    path = tmp_path / "cycle.svg"
    path.write_text(svg('<rect width="10" height="10"><animate id="a" attributeName="x" values="0;50" '
                        'begin="0;a.end+0.3s" dur="0.7s"/></rect>'))
    document = open_document(path)
    near = document.isolate(document.layer_names(), 1.2).svg
    document.isolate(document.layer_names(), 500.0)
    assert document.isolate(document.layer_names(), 1.2).svg == near
    assert number_at('<rect id="r"><animate id="a" attributeName="x" values="0;50" begin="0;a.end+0.3s" '
                     'dur="0.5s"/></rect>', 400.25, "r", "x") == pytest.approx(25)


@pytest.mark.parametrize("body,seconds", [
    ('<rect><animate attributeName="x" to="9" begin="0.5s" dur="2s" fill="freeze"/></rect>', 2.5),
    ('<rect><animate attributeName="x" to="9" begin="1s" dur="3s" repeatCount="indefinite"/></rect>', 4),
    ('<rect><animate id="a" attributeName="x" to="9" begin="0;b.end" dur="1s"/>'
     '<animate id="b" attributeName="y" to="9" begin="a.end" dur="0.5s"/></rect>', 1.5),
    ('<rect><animate attributeName="x" to="9" begin="20s" dur="1s"/></rect>', 21),
    ('<rect><set attributeName="x" to="9" begin="0.25s"/></rect>', 0.25),
])
def test_duration_is_the_last_end_or_one_cycle(body, seconds):
    assert smil(body).duration() == pytest.approx(seconds)


# --- interpolation ---------------------------------------------------------------------------------------------


def _bezier_y_at_x(spline, x, steps=200_001):
    s = np.linspace(0, 1, steps)
    curve = [3 * (1 - s) ** 2 * s * a + 3 * (1 - s) * s ** 2 * b + s ** 3 for a, b in ((spline[0], spline[2]),
                                                                                       (spline[1], spline[3]))]
    return float(np.interp(x, curve[0], curve[1]))


@pytest.mark.parametrize("spline", [(0, 0, 1, 1), (0.42, 0, 0.58, 1), (0.25, 0.1, 0.25, 1), (0.9, 0, 0.1, 1)])
def test_key_splines_ease(spline):
    for x in (0.0, 0.1, 0.25, 0.5, 0.8, 1.0):
        assert eased(spline, x) == pytest.approx(_bezier_y_at_x(spline, x), abs=1e-5)


def test_spline_values_per_interval():
    body = ('<rect id="r"><animate attributeName="x" values="0;100;0" keyTimes="0;0.25;1" calcMode="spline" '
            'keySplines="0.42 0 0.58 1;0.9,0,0.1,1" dur="4s"/></rect>')
    assert number_at(body, 0.5, "r", "x") == pytest.approx(50, abs=1e-4)
    assert number_at(body, 2.5, "r", "x") == pytest.approx(100 * (1 - _bezier_y_at_x((0.9, 0, 0.1, 1), 0.5)), abs=1e-3)


def test_paced_spaces_time_by_distance():
    body = ('<rect id="r"><animate attributeName="x" values="0;10;40" calcMode="paced" keyTimes="0;0.9;1" dur="4s"/>'
            '</rect>')  # keyTimes do not apply
    assert [number_at(body, t, "r", "x") for t in (1, 2, 3)] == pytest.approx([10, 20, 30])
    colours = '<rect id="r"><animate attributeName="fill" values="#000;#f00;#ff0" calcMode="paced" dur="2s"/></rect>'
    assert value_at(colours, 1.5, "r", "fill") == "rgb(255,128,0)"


def test_discrete_key_times_and_linear_default():
    body = ('<rect id="r"><animate attributeName="visibility" values="hidden;visible;hidden" keyTimes="0;0.5;0.9" '
            'dur="1s"/></rect>')  # strings are always discrete
    assert [value_at(body, t, "r", "visibility") for t in (0.4, 0.6, 0.95)] == ["hidden", "visible", "hidden"]
    body = '<rect id="r"><animate attributeName="x" from="0" to="10" calcMode="discrete" dur="1s"/></rect>'
    assert [number_at(body, t, "r", "x") for t in (0.4, 0.6)] == [0, 10]
    body = '<rect id="r" x="3"><animate attributeName="x" to="10" calcMode="discrete" dur="1s"/></rect>'
    assert number_at(body, 0.2, "r", "x") == 10  # a discrete to-animation holds its one value throughout


def test_to_by_additive_and_accumulate():
    base = '<rect id="r" width="10"><animate attributeName="width" {} dur="1s" fill="freeze"/></rect>'
    assert number_at(base.format('to="30"'), 0.5, "r", "width") == 20
    assert number_at(base.format('by="10"'), 0.5, "r", "width") == 15
    assert number_at(base.format('from="2" by="10"'), 0.5, "r", "width") == 7
    assert number_at(base.format('values="0;4" additive="sum"'), 0.5, "r", "width") == 12
    repeated = base.format('values="0;10" accumulate="sum" repeatCount="3"')
    assert [number_at(repeated, t, "r", "width") for t in (0.5, 1.5, 2.5, 5)] == [5, 15, 25, 30]
    assert number_at(base.format('values="0;10" repeatCount="2"'), 3, "r", "width") == 10  # frozen on the last


def test_colours_lists_units_and_paths():
    body = '<rect id="r"><animate attributeName="fill" from="#000" to="white" dur="1s"/></rect>'
    assert value_at(body, 0.5, "r", "fill") == "rgb(128,128,128)"
    body = '<rect id="r"><animate attributeName="fill" from="rgb(0,0,0)" to="rgba(0,0,0,0)" dur="1s"/></rect>'
    assert value_at(body, 0.5, "r", "fill") == "rgba(0,0,0,0.5)"
    body = '<circle id="c"><animate attributeName="stroke-dasharray" values="0 10;4,20" dur="1s"/></circle>'
    assert value_at(body, 0.5, "c", "stroke-dasharray") == "2 15"
    body = '<rect id="r"><animate attributeName="width" from="1in" to="48px" dur="1s"/></rect>'
    assert value_at(body, 0.5, "r", "width") == "72px"
    body = ('<path id="p"><animate attributeName="d" from="M0,0 L10,0 a5 5 0 0 1 10 0" '
            'to="M10 10 20 20 a5 5 0 0 1 20 0" dur="1s"/></path>')
    assert value_at(body, 0.5, "p", "d") == "M5 5 L15 10 a5 5 0 0 1 15 0"


def test_transforms_replace_or_append_and_motion_comes_first():
    body = ('<rect id="r" transform="scale(2)"><animateTransform attributeName="transform" type="rotate" '
            'from="0 5 5" to="90 5 5" dur="1s"/>'
            '<animateTransform attributeName="transform" type="translate" by="10" dur="1s" additive="sum"/></rect>')
    assert value_at(body, 0.5, "r", "transform") == "rotate(45 5 5) translate(5 0)"
    body = ('<rect id="r" transform="scale(2)"><animateMotion path="M0,0 L10,0 L10,10" rotate="auto" '
            'dur="2s"/></rect>')
    assert value_at(body, 1.5, "r", "transform") == "translate(10,5) rotate(90) scale(2)"
    body = ('<rect id="r"><animateMotion path="M0,0 L10,0 L10,10" calcMode="linear" keyPoints="0;1;0.75" '
            'keyTimes="0;0.5;1" rotate="auto-reverse" dur="2s"/></rect>')
    assert value_at(body, 1.5, "r", "transform") == "translate(10,7.5) rotate(270)"  # 0.875 of the way


def test_motion_path_from_mpath_and_values():
    body = ('<defs><path id="p" d="M0,0 H20"/></defs><rect id="r"><animateMotion dur="2s">'
            '<mpath xlink:href="#p"/></animateMotion></rect>')
    assert value_at(body, 0.5, "r", "transform") == "translate(5,0)"
    body = '<rect id="r"><animateMotion values="0,0;0,10;30,10" dur="4s" rotate="auto"/></rect>'
    assert value_at(body, 1, "r", "transform") == "translate(0,10)"  # paced: 10 of 40 units at a quarter
    assert value_at(body, 3, "r", "transform") == "translate(20,10)"


def test_sandwich_priority():
    later_begin_wins = ('<rect id="r"><animate attributeName="x" to="20" begin="1s" dur="5s" fill="freeze"/>'
                        '<animate attributeName="x" to="10" begin="0s" dur="5s" fill="freeze"/></rect>')
    assert number_at(later_begin_wins, 6, "r", "x") == 20
    same_begin_document_order = ('<rect id="r"><animate attributeName="x" to="20" dur="1s" fill="freeze"/>'
                                 '<animate attributeName="x" to="10" dur="1s" fill="freeze"/></rect>')
    assert number_at(same_begin_document_order, 2, "r", "x") == 10
    dependent_wins = ('<rect id="r"><set attributeName="x" to="20" begin="a.begin"/>'
                      '<set id="a" attributeName="x" to="10"/></rect>')
    assert number_at(dependent_wins, 1, "r", "x") == 20


def test_properties_go_to_the_style_and_win_over_style_sheets(tmp_path):
    path = tmp_path / "styled.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="20" height="20"><style>rect { opacity: 1 }'
                    '</style><rect width="20" height="20" style="fill: red"><animate attributeName="opacity" '
                    'to="0" dur="1s" fill="freeze"/><set attributeName="fill" to="blue"/></rect></svg>')
    document = open_document(path)
    frame = document.isolate(document.layer_names(), 0.5).svg.decode()
    assert "fill: rgb(0,0,255)" in frame and "opacity: 0.5" in frame
    alpha = renderer_for(document).render(document, document.layer_names(), 2.0, (20, 20))[:, :, 3]
    assert alpha.max() == 0


def test_layer_isolation_holds_over_an_animated_display(tmp_path):
    path = tmp_path / "two.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="20" height="10"><rect width="10" height="10">'
                    '<set attributeName="display" to="inline"/></rect><rect x="10" width="10" height="10"/></svg>')
    document = open_document(path)
    alpha = renderer_for(document).render(document, ["rect 1"], 0.5, (20, 10))[:, :, 3]
    assert alpha[:, :10].max() == 0 and alpha[:, 10:].min() == 255


# --- what is not played ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("body,expected", [
    ('<rect><animate id="w" attributeName="x" to="9" begin="click" dur="1s"/></rect>',
     """<animate id="w" attributeName="x">: begin 'click' waits for an event"""),
    ('<rect><animate attributeName="x" to="9" dur="1s" end="r.mouseover"/></rect>',
     """<animate attributeName="x">: end 'r.mouseover' waits for an event"""),
    ('<rect><animate id="a" attributeName="foo" to="1" dur="1s"/></rect>',
     """<animate id="a" attributeName="foo">: attributeName 'foo' is not an attribute SVG 1.1 animates"""),
    ('<animate href="#nowhere" attributeName="x" to="1" dur="1s"/>', "its target '#nowhere' is not in the file"),
    ('<rect><animate attributeName="x" values="0;1" keyTimes="0;0.5;1" dur="1s"/></rect>',
     "keyTimes has 3 times for 2 values; it is not played"),
    ('<rect><animate attributeName="x" values="0;1" calcMode="spline" dur="1s"/></rect>',
     "calcMode 'spline' without keySplines"),
    ('<path><animate attributeName="d" values="M0,0 L1,1;M0,0 C1,1 2,2 3,3" dur="1s"/></path>',
     "they change discretely, as SVG 1.1 says"),
    ('<path><animate attributeName="d" values="M0,0 L1,1;M0,0 L2,2" calcMode="paced" dur="1s"/></path>',
     "calcMode 'paced' needs a distance between values"),
    ('<rect><animate attributeName="transform" to="scale(2)" dur="1s"/></rect>', "animateTransform does"),
    ('<rect><animateTransform attributeName="transform" type="scale" to="2" dur="1s"/></rect>',
     "a to-animation of a transform"),
    ('<rect><discard begin="1s"/></rect>', "<discard> (SVG 2) is not played"),
    ('<rect><animate attributeName="x" to="9" dur="0s"/></rect>', "dur '0s' is not a valid duration"),
    ('<rect id="r"><animate attributeName="x" to="9" begin="r.end" dur="1s"/></rect>',
     "begin 'r.end' refers to an element that is not an animation"),
    ('<rect><animateMotion path="M0,0 Q" dur="1s"/></rect>', "its motion path is invalid"),
])
def test_what_is_not_played_is_reported(body, expected):
    assert any(expected in message for message in messages(body)), messages(body)


def test_faithful_animations_report_nothing():
    assert messages('<rect id="r"><animate id="a" attributeName="x" values="0;1;0" keyTimes="0;0.3;1" '
                    'calcMode="spline" keySplines="0 0 1 1;0.5 0 0.5 1" begin="0;a.end+1s" dur="1s"/>'
                    '<animateMotion path="M0,0 h10" rotate="auto"/><set attributeName="fill" to="red"/></rect>') == []


def test_an_animated_reference_outside_the_file_is_refused():
    with pytest.raises(InputError, match="outside the document"):
        smil('<use href="#a"><set attributeName="href" to="https://example.com/x.svg#a"/></use>')


def test_strict_check_refuses_an_unsupported_element(cli, tmp_path):
    scene = write_scene(tmp_path, f"version: 1\ninput: {FIXTURES / 'smil-unsupported.svg'}\nfps: 12\nsize: [32, 32]\n"
                                  "layers:\n  - {name: box, select: ['rect 0']}\n")
    code, _, err = cli("check", scene)
    assert code == 0 and """<animate id="wait" attributeName="width">: begin 'click'""" in err
    code, _, err = cli("--strict", "check", scene)
    assert code == 2 and "--strict: 2 unsupported element(s)" in err
    assert """<animate id="a" attributeName="foo">""" in err
