import numpy as np
import pytest

from fluidymation.engine.vector_motion import vector_flow
from fluidymation.stages.vector import open_document
from fluidymation.stages.vector.svg_geometry import outlines

from tests.scenes import assert_turning, gear_path

FPS = 24.0
SIZE = (64, 64)


def _write(tmp_path, body, view="0 0 64 64"):
    path = tmp_path / "shape.svg"
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64" viewBox="{view}">{body}</svg>')
    return open_document(path, fps=FPS)


def _flow(document, frame, size=SIZE):
    names = document.layer_names()
    elements, unread = document.moving_elements(names, (frame - 1) / FPS, frame / FPS, size)
    flow, owned = vector_flow(elements, (size[1], size[0]))
    return flow, owned, unread


@pytest.mark.parametrize("shape", ["disk", "gear"])
def test_a_smil_rotation_reads_omega_r_along_the_tangent(tmp_path, shape):
    drawn = ('<circle cx="32" cy="32" r="24"/>' if shape == "disk" else f'<path d="{gear_path((32, 32), 18, 26)}"/>')
    document = _write(tmp_path, f'<g id="wheel">{drawn}<animateTransform attributeName="transform" type="rotate" '
                                'from="0 32 32" to="360 32 32" dur="3s" repeatCount="indefinite"/></g>')
    flow, owned, unread = _flow(document, 5)
    assert unread == []
    assert_turning(flow, owned, (32, 32), 360 / (3 * FPS))


def test_a_css_rotation_in_a_scaled_viewbox_reads_in_output_pixels(tmp_path):
    document = _write(tmp_path, '<style>#gear { transform-origin: 16px 16px; animation: spin 2s linear infinite } '
                                '@keyframes spin { to { transform: rotate(-360deg) } }</style>'
                                f'<path id="gear" d="{gear_path((16, 16), 9, 13)}"/>', view="0 0 32 32")
    flow, owned, unread = _flow(document, 3, size=(128, 128))
    assert unread == []
    assert_turning(flow, owned, (64, 64), 360 / (2 * FPS), clockwise=False)


def test_a_scaling_square_reads_the_analytic_field(tmp_path):
    document = _write(tmp_path, '<rect x="12" y="12" width="40" height="40"><animateTransform '
                                'attributeName="transform" type="scale" from="1" to="1.5" dur="1s" fill="freeze"/></rect>')
    flow, owned, _ = _flow(document, 6)
    yy, xx = np.nonzero(owned)
    now, before = 1 + 0.5 * 6 / FPS, 1 + 0.5 * 5 / FPS  # scaling about the origin
    expected = np.column_stack([xx + 0.5, yy + 0.5]) * (1.0 - before / now)
    np.testing.assert_allclose(flow[yy, xx], expected, atol=1e-3)


def test_a_path_morph_moves_with_its_vertices(tmp_path):
    document = _write(tmp_path, '<path d="M10,10 L40,10 L40,40 L10,40 Z"><animate attributeName="d" dur="1s" '
                                'values="M10,10 L40,10 L40,40 L10,40 Z;M10,10 L58,10 L58,40 L10,40 Z" '
                                'fill="freeze"/></path>')
    flow, owned, unread = _flow(document, 12)
    assert unread == []
    step = 18 / FPS  # the right edge's speed, px/frame; the left edge stands
    assert flow[25, 45, 0] == pytest.approx(step * (45.5 - 10) / (10 + 30 + 18 * 12 / FPS - 10), rel=0.05)
    assert abs(flow[25, 11, 0]) < 0.05 and np.abs(flow[owned][:, 1]).max() < 1e-3


def test_dashed_strokes_hidden_layers_and_other_elements_are_named_or_left_out(tmp_path):
    document = _write(tmp_path, '<g id="a"><circle cx="20" cy="20" r="8" stroke="red" stroke-dasharray="2 1"/>'
                                '<text>hi</text></g><g id="b"><rect width="10" height="10" fill="none"/></g>')
    found, unread = outlines(document.static_tree(["a"], 0.0), SIZE)
    assert [outline.key for outline in found] == [(0, 0)]
    assert unread == ["<circle> at (0, 0) (its dashed stroke)", "<text> at (0, 1)"]
    found, unread = outlines(document.static_tree(["b"], 0.0), SIZE)
    assert found == [] and unread == []


def test_elements_it_cannot_read_are_named_not_fatal(tmp_path):
    document = _write(tmp_path, '<path d="M 1"/><rect width="5" height="5" transform="rotate(oops)"/>'
                                '<circle cx="1e38" cy="0" r="1e38"/><ellipse cx="10" cy="10" rx="4" ry="3"/>')
    found, unread = outlines(document.static_tree(document.layer_names(), 0.0), SIZE)
    assert [outline.key for outline in found] == [(3,)]
    assert len(unread) == 3 and unread[0].startswith("<path> at (0,) (") and "<rect> at (1,)" in unread[1]
    assert unread[2] == "<circle> at (2,) (coordinates out of range)"


@pytest.mark.parametrize("view, aspect", [("0 0 0 10", ""), ("a b c d", ""), ("0 0 32 32", ' preserveAspectRatio=""'),
                                          ("0 0 32 32", ' preserveAspectRatio="bogus"')])
def test_odd_viewports_do_not_stop_it(tmp_path, view, aspect):
    path = tmp_path / "odd.svg"
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64" viewBox="{view}"{aspect}>'
                    '<rect width="8" height="8"/></svg>')
    document = open_document(path, fps=FPS)
    found, _ = outlines(document.static_tree(document.layer_names(), 0.0), SIZE)
    assert len(found) == 1


def test_transform_lists_and_inherited_strokes(tmp_path):
    document = _write(tmp_path, '<g transform="translate(10 0) scale(2)" stroke="red" stroke-width="3">'
                                '<rect width="4" height="4"/></g>')
    found, unread = outlines(document.static_tree(document.layer_names(), 0.0), SIZE)
    np.testing.assert_allclose(found[0].rings[0][:4], [(10, 0), (18, 0), (18, 8), (10, 8)])
    assert unread == [] and [outline.key for outline in found] == [(0, 0), (0, 0, -1)]
    # the band 3 px wide, scaled by 2: 3 px either side of the square's edges x = 10 and 18
    spans = sorted((ring[:, 0].min(), ring[:, 0].max()) for ring in found[1].rings)
    np.testing.assert_allclose(spans, [(7, 21), (13, 15)], atol=0.05)


def test_a_turning_stroked_ring_reads_omega_r(tmp_path):
    document = _write(tmp_path, '<g id="ring"><circle cx="32" cy="32" r="20" fill="none" stroke="black" '
                                'stroke-width="6"/><animateTransform attributeName="transform" type="rotate" '
                                'from="0 32 32" to="360 32 32" dur="3s" repeatCount="indefinite"/></g>'
                                '<g id="arc"><polyline points="10,50 30,60 50,50" fill="none" stroke="black" '
                                'stroke-width="4"/><animateTransform attributeName="transform" type="rotate" '
                                'from="0 32 32" to="360 32 32" dur="3s" repeatCount="indefinite"/></g>')
    for layer in ("ring", "arc"):
        elements, unread = document.moving_elements([layer], 4 / FPS, 5 / FPS, SIZE)
        flow, owned = vector_flow(elements, (SIZE[1], SIZE[0]))
        assert unread == [] and owned.sum() > 100
        assert_turning(flow, owned, (32, 32), 360 / (3 * FPS))


def test_geometry_a_css_animation_sets_in_style_is_read_there(tmp_path):
    document = _write(tmp_path, '<style>.grow { animation: grow 1s linear infinite } '
                                '@keyframes grow { from { r: 4px } to { r: 16px } }</style>'
                                '<circle class="grow" cx="32" cy="32" r="10"/>')
    found, unread = outlines(document.static_tree(document.layer_names(), 0.25), SIZE)
    radius = np.hypot(*(found[0].rings[0] - 32).T)
    assert unread == [] and radius.max() == pytest.approx(7.0, abs=0.05)  # 4 + 12 · 0.25, not the attribute's 10
