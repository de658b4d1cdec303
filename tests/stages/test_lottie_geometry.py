"""Motion read from a Lottie file's geometry (``flow: vector``): turns, scales, morphs, parenting, precomps,
masks and mattes, against their analytic fields; what is not read is named; coverage agrees with ThorVG."""

import json
import math

import numpy as np
import pytest

from fluidymation.engine.vector_motion import coverage, vector_flow
from fluidymation.stages.vector import open_document, renderer_for

from tests.scenes import assert_turning, gear_points, lottie_path, still
from tests.stages.test_lottie_player import DATA, iou

FPS = 24.0
SIZE = (64, 64)


def linear(*keys):
    """An animated property through ``(frame, value)`` keys, linear between them."""
    return {"a": 1, "k": [{"t": t, "s": np.atleast_1d(value).tolist(), "o": {"x": [0], "y": [0]},
                           "i": {"x": [1], "y": [1]}} for t, value in keys]}


def transform(**properties):
    base = {"a": still([0, 0]), "p": still([0, 0]), "s": still([100, 100]), "r": still(0), "o": still(100)}
    return base | properties


def shape_layer(name, shapes, ind=1, **extra):
    return {"ty": 4, "nm": name, "ind": ind, "ip": 0, "op": 240, "st": 0, "ks": transform(), "shapes": shapes} | extra


PIXEL = ("data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmM"
         "IQAAAABJRU5ErkJggg==")  # a 1×1 PNG
FILL = {"ty": "fl", "c": still([0.2, 0.4, 0.8, 1]), "o": still(100), "r": 1}


def write(tmp_path, layers, assets=(), size=SIZE):
    path = tmp_path / "shapes.json"
    path.write_text(json.dumps({"v": "5.7.0", "fr": FPS, "ip": 0, "op": 240, "w": size[0], "h": size[1],
                                "layers": layers, "assets": list(assets)}))
    return open_document(path)


def flow_at(document, frame, size=SIZE, names=None):
    elements, unread = document.moving_elements(names or document.layer_names(), (frame - 1) / FPS, frame / FPS,
                                                size)
    flow, owned = vector_flow(elements, (size[1], size[0]))
    return flow, owned, unread


def pixel_centres(owned):
    yy, xx = np.nonzero(owned)
    return yy, xx, np.column_stack([xx + 0.5, yy + 0.5])


TURN = {"a": still([32, 32]), "p": still([32, 32]), "r": linear((0, 0), (72, 360))}  # once every 3 s


@pytest.mark.parametrize("drawn", ["disk", "gear"])
def test_a_layer_rotation_reads_omega_r_along_the_tangent(tmp_path, drawn):
    outline = ({"ty": "el", "p": still([32, 32]), "s": still([48, 48])} if drawn == "disk" else
               {"ty": "sh", "ks": still(lottie_path(gear_points((32, 32), 18, 26)))})
    document = write(tmp_path, [shape_layer("wheel", [outline, FILL], ks=transform(**TURN))])
    flow, owned, unread = flow_at(document, 5)
    assert unread == [] and owned.sum() > 1000
    assert_turning(flow, owned, (32, 32), 360 / 72)


def test_a_group_rotation_turns_the_other_way_at_its_own_rate(tmp_path):
    group = {"ty": "gr", "it": [{"ty": "sh", "ks": still(lottie_path(gear_points((0, 0), 9, 13)))}, FILL,
                                {"ty": "tr", **transform(p=still([16, 16]), r=linear((0, 0), (48, -360)))}]}
    document = write(tmp_path, [shape_layer("gear", [group])], size=(32, 32))
    flow, owned, unread = flow_at(document, 3, size=(128, 128))  # the 32-px canvas fitted into 128 px
    assert unread == []
    assert_turning(flow, owned, (64, 64), 360 / 48, clockwise=False)


def test_a_scaling_square_reads_the_analytic_field(tmp_path):
    square = {"ty": "rc", "p": still([32, 32]), "s": still([40, 40]), "r": still(0)}
    document = write(tmp_path, [shape_layer("square", [square, FILL], ks=transform(s=linear((0, 100), (24, 150))))])
    flow, owned, unread = flow_at(document, 6)
    yy, xx, centres = pixel_centres(owned)
    now, before = 1 + 0.5 * 6 / 24, 1 + 0.5 * 5 / 24  # scaling about the origin
    assert unread == [] and len(yy) > 1000
    np.testing.assert_allclose(flow[yy, xx], centres * (1.0 - before / now), atol=1e-3)


def test_a_path_morph_moves_with_its_vertices(tmp_path):
    morph = {"ty": "sh", "ks": {"a": 1, "k": [
        {"t": 0, "s": [lottie_path([(10, 10), (40, 10), (40, 40), (10, 40)])], "o": {"x": [0], "y": [0]},
         "i": {"x": [1], "y": [1]}},
        {"t": 24, "s": [lottie_path([(10, 10), (58, 10), (58, 40), (10, 40)])]}]}}
    document = write(tmp_path, [shape_layer("morph", [morph, FILL])])
    flow, owned, unread = flow_at(document, 12)
    assert unread == []
    step = 18 / 24  # the right edge's speed, px/frame; the left edge stands
    width = 30 + 18 * 12 / 24
    assert flow[25, 45, 0] == pytest.approx(step * (45.5 - 10) / width, rel=0.05)
    assert abs(flow[25, 11, 0]) < 0.05 and np.abs(flow[owned][:, 1]).max() < 1e-3


def test_a_rotating_child_on_a_moving_parent_moves_by_both(tmp_path):
    parent = {"ty": 3, "nm": "rig", "ind": 1, "ip": 0, "op": 240, "st": 0,
              "ks": transform(p=linear((0, [16, 32]), (24, [40, 32])))}
    child = shape_layer("arm", [{"ty": "rc", "p": still([8, 0]), "s": still([24, 8]), "r": still(0)}, FILL], ind=2,
                        parent=1, ks=transform(r=linear((0, 0), (24, 90))))
    document = write(tmp_path, [child, parent])
    frame = 10
    flow, owned, unread = flow_at(document, frame, names=["arm"])
    yy, xx, centres = pixel_centres(owned)
    assert unread == [] and len(yy) > 100
    pivot_now, pivot_before = np.array([16 + frame, 32.0]), np.array([16 + frame - 1, 32.0])
    step = math.radians(90 / 24)
    back = np.array([[math.cos(step), math.sin(step)], [-math.sin(step), math.cos(step)]])  # a turn of −step
    before = (centres - pivot_now) @ back.T + pivot_before
    np.testing.assert_allclose(flow[yy, xx], centres - before, atol=2e-3)


def test_a_time_remapped_precomp_moves_at_the_remapped_rate(tmp_path):
    inner = shape_layer("dot", [{"ty": "el", "p": still([0, 0]), "s": still([12, 12])}, FILL],
                        ks=transform(p=linear((0, [10, 32]), (40, [50, 32]))))  # 1 px per inner frame
    holder = {"ty": 0, "nm": "slow", "ind": 1, "refId": "dots", "ip": 0, "op": 240, "st": 0, "w": 64, "h": 64,
              "ks": transform(), "tm": linear((0, 0.0), (48, 1.0))}  # 24 inner frames over 48: half speed
    document = write(tmp_path, [holder], assets=[{"id": "dots", "layers": [inner]}])
    flow, owned, unread = flow_at(document, 20)
    assert unread == [] and owned.sum() > 80
    np.testing.assert_allclose(flow[owned], np.tile([0.5, 0.0], (owned.sum(), 1)), atol=1e-4)


def test_masks_and_mattes_cut_the_coverage(tmp_path):
    square = {"ty": "rc", "p": still([32, 32]), "s": still([40, 40]), "r": still(0)}
    masked = shape_layer("masked", [square, FILL], masksProperties=[
        {"mode": "s", "inv": False, "pt": still(lottie_path([(12, 12), (32, 12), (32, 32), (12, 32)]))}])
    document = write(tmp_path, [masked])
    _, owned, unread = flow_at(document, 3)
    assert unread == [] and owned.sum() == 40 * 40 - 20 * 20 and not owned[20, 20]
    matte = shape_layer("matte", [{"ty": "rc", "p": still([32, 16]), "s": still([64, 32]), "r": still(0)}, FILL],
                        ind=1, td=1)
    document = write(tmp_path, [matte, shape_layer("under", [square, FILL], ind=2, tt=1)])
    _, owned, unread = flow_at(document, 3, names=["under"])
    assert unread == [] and owned.sum() == 40 * 20 and owned[12:32, 12:52].all()


def test_what_is_drawn_but_not_read_is_named(tmp_path):
    stroke = {"ty": "st", "c": still([0, 0, 0, 1]), "o": still(100), "w": still(2),
              "d": [{"n": "d", "v": still(4)}, {"n": "g", "v": still(2)}]}
    spinning = {"a": 0, "k": 0, "x": "time * 360"}
    layers = [shape_layer("outlined", [{"ty": "el", "p": still([20, 20]), "s": still([10, 10])}, stroke], ind=1),
              shape_layer("scripted", [{"ty": "el", "p": still([40, 40]), "s": still([10, 10])}, FILL], ind=2,
                          ks=transform(r=spinning)),
              {"ty": 2, "nm": "photo", "ind": 3, "refId": "img", "ip": 0, "op": 240, "st": 0, "ks": transform()}]
    document = write(tmp_path, layers, assets=[{"id": "img", "w": 1, "h": 1, "u": "", "e": 1, "p": PIXEL}])
    elements, unread = document.moving_elements(document.layer_names(), 0.0, 1 / FPS, SIZE)
    assert elements == []
    assert unread == ["layers[0] 'outlined' shapes[1] '' (a dashed stroke)", "layers[1] 'scripted' (an expression)",
                      "layers[2] 'photo' (an image layer)"]


@pytest.mark.parametrize("hostile", [
    {"ks": {"a": 0, "k": "nonsense"}}, {"ks": {"a": 1, "k": [{"t": 0, "s": [1e400]}]}},
    {"ks": {"a": 1, "k": [{"t": 0}, {"t": 0}]}}, {"ks": still({"v": [[1, 2]], "i": [[0]], "o": [], "c": True})},
    {"ks": still(lottie_path([(1e7, 0), (0, 1e7), (0, 0)]))}])  # the reader refuses coordinates beyond 1e7
def test_hostile_values_are_named_not_fatal(tmp_path, hostile):
    document = write(tmp_path, [shape_layer("bad", [{"ty": "sh", **hostile}, FILL])])
    elements, unread = document.moving_elements(document.layer_names(), 0.0, 1 / FPS, SIZE)
    assert elements == [] and len(unread) == 1 and unread[0].startswith("layers[0] 'bad' shapes[1] '' (")


def test_a_parent_cycle_is_named_not_followed(tmp_path):
    document = write(tmp_path, [shape_layer("loop", [{"ty": "el", "p": still([9, 9]), "s": still([9, 9])}, FILL],
                                            ind=7, parent=7)])
    elements, unread = document.moving_elements(["loop"], 0.0, 1 / FPS, SIZE)
    assert elements == [] and unread == ["layers[0] 'loop' (a parent chain longer than 32 (a cycle?))"]


@pytest.mark.parametrize("fixture, frame", [("shapes_keyframe.json", 5), ("parenting.json", 5),
                                            ("precomp.lottie", 4), ("time_remap.json", 6), ("mask.json", 3),
                                            ("mask_subtract.json", 3), ("matte.json", 3), ("motion_30fps.json", 7)])
def test_outlines_cover_what_thorvg_draws(fixture, frame):
    document = open_document(DATA / fixture)
    size = (2 * round(document.width), 2 * round(document.height))
    seconds = frame / document.lottie_fps
    for name in document.layer_names():
        elements, unread = document.moving_elements([name], seconds - 1 / document.lottie_fps, seconds, size)
        assert unread == []
        ours = np.zeros((size[1], size[0]), bool)
        for element in elements:
            ours |= coverage(element, ours.shape)
        drawn = renderer_for(document).render(document, [name], seconds, size)[:, :, 3] / 255.0
        assert iou(ours, drawn) > 0.98, name


def test_nothing_is_owned_outside_a_precomps_bounds_or_the_canvas(tmp_path):
    wide = shape_layer("wide", [{"ty": "rc", "p": still([32, 16]), "s": still([80, 20]), "r": still(0)}, FILL])
    holder = {"ty": 0, "nm": "box", "ind": 1, "refId": "inner", "ip": 0, "op": 240, "st": 0, "w": 40, "h": 32,
              "ks": transform(p=still([12, 0]))}  # the precomp's bounds: x 12..52 of the canvas
    document = write(tmp_path, [holder], assets=[{"id": "inner", "layers": [wide]}], size=(64, 32))
    _, owned, unread = flow_at(document, 3, size=(64, 64))  # the 64×32 canvas sits at y 16..48
    assert unread == []
    expected = np.zeros((64, 64), bool)
    expected[16 + 6:16 + 26, 12:52] = True
    np.testing.assert_array_equal(owned, expected)
    tall = shape_layer("tall", [{"ty": "rc", "p": still([32, 16]), "s": still([20, 60]), "r": still(0)}, FILL])
    document = write(tmp_path, [tall], size=(64, 32))
    _, owned, _ = flow_at(document, 3, size=(64, 64))
    expected[:] = False
    expected[16:48, 22:42] = True  # the rectangle spans y −14..46 of the canvas: cut to its 0..32
    np.testing.assert_array_equal(owned, expected)


def test_skew_split_positions_easing_stars_and_round_rectangles_agree_with_thorvg(tmp_path):
    eased = {"o": {"x": [0.7], "y": [0.1]}, "i": {"x": [0.2], "y": [0.9]}}
    split = {"s": True, "x": {"a": 1, "k": [{"t": 0, "s": [20], **eased}, {"t": 12, "s": [44]}]},
             "y": {"a": 1, "k": [{"t": 0, "s": [20], **eased}, {"t": 12, "s": [40]}]}}
    star = {"ty": "sr", "sy": 1, "pt": still(5), "p": still([0, 0]), "r": still(10), "ir": still(6), "or": still(14),
            "is": still(0), "os": still(0)}
    polygon = {"ty": "sr", "sy": 2, "pt": still(6), "p": still([0, 18]), "r": still(0), "or": still(8), "os": still(0)}
    rounded = {"ty": "rc", "p": still([-16, 0]), "s": still([14, 20]), "r": still(5), "d": 3}
    layer = shape_layer("mixed", [star, polygon, rounded, FILL], ks=transform(
        p=split, s=still([120, 80]), r=linear((0, 0), (12, 60)), sk=still(20), sa=still(30)))
    document = write(tmp_path, [layer])
    size = (128, 128)
    for frame in (3, 6, 9):
        elements, unread = document.moving_elements(["mixed"], (frame - 1) / FPS, frame / FPS, size)
        assert unread == []
        ours = np.zeros(size, bool)
        for element in elements:
            ours |= coverage(element, size)
        drawn = renderer_for(document).render(document, ["mixed"], frame / FPS, size)[:, :, 3] / 255.0
        assert iou(ours, drawn) > 0.99, frame


STROKE = {"ty": "st", "c": still([0.1, 0.1, 0.1, 1]), "o": still(100), "w": still(6), "lc": 1, "lj": 1}


@pytest.mark.parametrize("outline", ["ring", "arc"])
def test_a_turning_stroke_reads_omega_r_and_covers_what_thorvg_draws(tmp_path, outline):
    if outline == "ring":
        drawn = {"ty": "el", "p": still([32, 32]), "s": still([40, 40])}
    else:  # an open polyline of a half circle
        angles = np.linspace(0, np.pi, 13)
        drawn = {"ty": "sh", "ks": still(lottie_path(np.column_stack([32 + 20 * np.cos(angles),
                                                                       32 + 20 * np.sin(angles)]), closed=False))}
    document = write(tmp_path, [shape_layer("wheel", [drawn, STROKE], ks=transform(**TURN))])
    flow, owned, unread = flow_at(document, 5)
    assert unread == [] and owned.sum() > 200
    assert_turning(flow, owned, (32, 32), 360 / 72)
    size = (128, 128)
    elements, _ = document.moving_elements(["wheel"], 4 / FPS, 5 / FPS, size)
    ours = np.zeros(size, bool)
    for element in elements:
        ours |= coverage(element, size)
    drawn_alpha = renderer_for(document).render(document, ["wheel"], 5 / FPS, size)[:, :, 3] / 255.0
    assert iou(ours, drawn_alpha) > 0.97  # measured 0.986 and 0.992: unmitred joins against the player's


def test_a_trim_path_outside_a_group_leaves_the_groups_strokes_to_the_masks(tmp_path):
    group = {"ty": "gr", "nm": "arc", "it": [{"ty": "el", "p": still([32, 32]), "s": still([40, 40])}, STROKE,
                                             {"ty": "tr", **transform()}]}
    trim = {"ty": "tm", "nm": "trim", "s": still(0), "e": still(50), "o": still(0)}
    document = write(tmp_path, [shape_layer("trimmed", [group, trim])])
    elements, unread = document.moving_elements(["trimmed"], 0.0, 1 / FPS, SIZE)
    assert elements == [] and unread == ["layers[0] 'trimmed' shapes[0] 'arc' it[1] '' (strokes layers[0] 'trimmed' "
                                         "shapes (a trim path))"]
