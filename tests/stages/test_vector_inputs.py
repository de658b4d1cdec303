"""Vector inputs: exact geometry, and agreement with the lottie package's own rendering."""

import io
import json
from pathlib import Path

import imageio.v3 as iio
import lottie.objects
import numpy as np
import pytest
from lottie.exporters.cairo import export_png

from fluidymation.stages.vector import open_document, renderer_for

DATA = Path(__file__).parent.parent / "data" / "lottie"
EXAMPLES = Path(__file__).parents[2] / "examples"


def coverage(document, names, frame, size=None, fps=None):
    """Coverage of ``names`` at scene ``frame`` (at ``fps``, else the file's own), drawn by the default renderer."""
    fps = fps or document.native_fps or 24
    size = size or (round(document.width), round(document.height))
    return renderer_for(document).render(document, names, frame / fps, size)[:, :, 3] / 255.0


def box(mask):
    ys, xs = np.nonzero(mask)
    return xs.min(), xs.max() + 1, ys.min(), ys.max() + 1


def svg_circle(tmp_path, radius, size=200):
    path = tmp_path / "circle.svg"
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}">'
                    f'<g id="disc"><circle cx="{size / 2}" cy="{size / 2}" r="{radius}" fill="#123456"/></g></svg>')
    return path


@pytest.mark.parametrize("radius", [7.5, 20, 61])
def test_svg_circle_covers_pi_r_squared(tmp_path, radius):
    document = open_document(svg_circle(tmp_path, radius))
    area = coverage(document, ["disc"], 0).sum()
    assert area == pytest.approx(np.pi * radius**2, rel=0.01)


def test_circle_area_scales_with_output_size(tmp_path):
    document = open_document(svg_circle(tmp_path, 20, size=100))
    area = coverage(document, ["disc"], 0, size=(300, 300)).sum()
    assert area == pytest.approx(np.pi * 60**2, rel=0.01)


def test_lottie_circle_area_and_keyframed_position():
    document = open_document(DATA / "shapes_keyframe.json")
    assert coverage(document, ["disc"], 0).sum() == pytest.approx(np.pi * 20**2, rel=0.01)
    assert box(coverage(document, ["square"], 0) >= 0.5) == (10, 30, 10, 30)
    assert box(coverage(document, ["square"], 5) >= 0.5) == (38, 58, 10, 30)
    assert box(coverage(document, ["square"], 11) >= 0.5) == (66, 86, 10, 30)


def test_lottie_keyframe_follows_scene_fps():
    document = open_document(DATA / "shapes_keyframe.json")  # 12 fps file: its frame 5 is frame 10 at 24 fps
    assert box(coverage(document, ["square"], 10, fps=24) >= 0.5) == (38, 58, 10, 30)


def test_parented_layer_moves_with_its_parents():
    document = open_document(DATA / "parenting.json")
    assert box(coverage(document, ["head"], 5) >= 0.5) == (44, 60, 23, 39)
    assert box(coverage(document, ["torso"], 5) >= 0.5) == (42, 62, 41, 71)
    assert coverage(document, ["head"], 5)[60, 52] == 0  # the torso is not drawn with the head


def test_trim_path_draws_on():
    document = open_document(DATA / "trim_path.json")
    assert coverage(document, ["line"], 0).sum() < 1
    assert box(coverage(document, ["line"], 5) >= 0.5) == (16, 48, 44, 52)
    assert box(coverage(document, ["line"], 10) >= 0.5) == (16, 80, 44, 52)


def test_track_matte_is_applied_and_matte_source_is_not_drawn():
    document = open_document(DATA / "matte.json")
    stripes = coverage(document, ["stripes"], 0) >= 0.5
    assert box(stripes) == (24, 72, 24, 72)
    assert stripes.sum() == pytest.approx(np.pi * 24**2, rel=0.02)


def test_precomp_is_one_layer_unless_split():
    whole = open_document(DATA / "precomp.json")
    assert whole.layer_names() == ["ground", "leaves"]
    split = open_document(DATA / "precomp.json", split=("leaves",))
    assert split.layer_names() == ["ground", "leaves/leaf_b", "leaves/leaf_a"]
    leaf_a = coverage(split, ["leaves/leaf_a"], 0) >= 0.5
    assert box(leaf_a) == (24, 56, 56, 88)
    both = coverage(whole, ["leaves"], 0) >= 0.5
    assert (both & leaf_a).sum() == leaf_a.sum() and both.sum() > leaf_a.sum() * 1.5


def test_packed_forms_match_plain_json():
    plain = open_document(DATA / "parenting.json")
    tgs = open_document(DATA / "parenting.tgs")
    assert np.array_equal(coverage(plain, ["head"], 5), coverage(tgs, ["head"], 5))
    dot = open_document(DATA / "precomp.lottie")
    assert np.array_equal(coverage(open_document(DATA / "precomp.json"), ["ground"], 3), coverage(dot, ["ground"], 3))


def test_svg_layers_are_top_level_groups_by_label_then_id(tmp_path):
    path = tmp_path / "two.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'
                    ' width="40" height="20"><rect width="40" height="20" fill="#fff"/>'
                    '<g id="g1" inkscape:label="Left"><rect width="20" height="20" fill="#f00"/></g>'
                    '<g id="right"><rect x="20" width="20" height="20" fill="#00f"/></g></svg>')
    document = open_document(path)
    assert document.layer_names() == ["rect 0", "Left", "right"]  # the background rect beside the groups too
    assert coverage(document, ["Left"], 0).sum() == pytest.approx(400)
    assert coverage(document, ["Left", "right"], 0).sum() == pytest.approx(800)
    assert coverage(document, ["rect 0"], 0).sum() == pytest.approx(800)


def test_svg_groups_and_shapes_beside_them_are_numbered_apart(tmp_path):
    path = tmp_path / "mixed.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="40" height="10"><g><rect width="10" height="10"/>'
                    '</g><circle cx="15" cy="5" r="5"/><g><rect x="20" width="10" height="10"/></g>'
                    '<rect x="30" width="10" height="10"/></svg>')
    document = open_document(path)
    assert document.layer_names() == ["group 0", "circle 0", "group 1", "rect 1"]
    assert coverage(document, ["rect 1"], 0)[:, 30:].sum() == pytest.approx(100)
    assert coverage(document, ["rect 1"], 0)[:, :30].sum() == 0


def test_svg_without_groups_has_a_layer_per_top_level_element(tmp_path):
    path = tmp_path / "loose.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="40" height="10"><title>loose</title>'
                    '<defs><rect id="unused" width="40" height="10"/></defs><rect id="left" width="10" height="10"/>'
                    '<circle cx="15" cy="5" r="5"/><circle cx="25" cy="5" r="5"/>'
                    '<path d="M30,0 h10 v10 h-10 z"/></svg>')
    document = open_document(path)
    assert document.layer_names() == ["left", "circle 1", "circle 2", "path 3"]
    alone = coverage(document, ["circle 2"], 0)
    assert alone[:, 20:30].sum() == pytest.approx(np.pi * 25, rel=0.05)
    assert alone[:, :20].sum() == alone[:, 30:].sum() == 0
    assert coverage(document, document.layer_names(), 0).sum() == pytest.approx(200 + 2 * np.pi * 25, rel=0.02)


def test_svg_filter_primitives_cairosvg_leaves_out_are_reported(tmp_path):
    path = tmp_path / "soft.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><filter id="soft">'
                    '<feGaussianBlur stdDeviation="2"/><feColorMatrix values="1 0 0 0 0"/><feOffset dx="1"/></filter>'
                    '<filter id="shift"><feOffset dx="1"/></filter>'
                    '<rect width="5" height="5" filter="url(#soft)"/></svg>')
    assert [(item.element, item.message) for item in open_document(path).unsupported] == [
        ('<filter id="soft">', "cairosvg does not draw <feColorMatrix>, <feGaussianBlur>: what the filter applies to "
                               "is drawn without them")]


def test_svg_sequence_in_numeric_order(tmp_path):
    for index in (0, 1, 2, 10):
        (tmp_path / f"f{index}.svg").write_text(
            f'<svg xmlns="http://www.w3.org/2000/svg" width="40" height="10"><g id="bar">'
            f'<rect width="{index + 1}" height="10"/></g></svg>')
    document = open_document(tmp_path / "f%d.svg", fps=24)
    assert document.frame_range(24) == (0, 4)
    assert [coverage(document, ["bar"], f).sum() for f in range(4)] == pytest.approx([10, 20, 30, 110])


def test_smil_example_grows():
    document = open_document(EXAMPLES / "blob" / "blob.svg")
    areas = [coverage(document, ["blob"], frame, size=(64, 64), fps=24).sum() for frame in (0, 24)]
    assert areas[1] > areas[0] * 1.2


# --- agreement with the lottie package's own rendering of a layer alone -------------------

def lottie_reference(path, layer_name, frame):
    """The layer rendered by lottie's own PNG exporter, other layers removed or emptied."""
    data = json.loads(path.read_text())
    keep = _needed_layers(data["layers"], layer_name)
    animation = lottie.objects.Animation.load(data)
    for layer in list(animation.layers):
        if layer.name == layer_name or layer.index in keep["matte"]:
            continue
        if layer.index in keep["parents"]:
            if hasattr(layer, "shapes"):
                layer.shapes = []
        else:
            animation.layers.remove(layer)
    buffer = io.BytesIO()
    export_png(animation, buffer, frame)
    return iio.imread(buffer.getvalue())[:, :, 3] / 255.0


def soft_iou(ours, reference):
    """IoU of soft coverage: a pixel an edge cuts exactly in half counts half in both, whichever way it rounds."""
    return np.minimum(ours, reference).sum() / max(np.maximum(ours, reference).sum(), 1e-9)


def _needed_layers(layers, name):
    by_index = {layer.get("ind"): layer for layer in layers}
    target = next(layer for layer in layers if layer.get("nm") == name)
    parents, parent = set(), target.get("parent")
    while parent is not None:
        parents.add(parent)
        parent = by_index[parent].get("parent")
    position = layers.index(target)
    matte = {layers[position - 1].get("ind")} if target.get("tt") and position else set()
    return {"parents": parents, "matte": matte}


CASES = [("shapes_keyframe.json", "square"), ("shapes_keyframe.json", "disc"), ("parenting.json", "head"),
         ("parenting.json", "torso"), ("precomp.json", "leaves"), ("precomp.json", "ground"),
         ("trim_path.json", "line"), ("mask.json", "masked_square"), ("matte.json", "stripes")]


@pytest.mark.parametrize("filename,layer", CASES)
def test_masks_agree_with_lottie_rendering(filename, layer):
    document = open_document(DATA / filename)
    for frame in (0, 5, 11):
        ours = coverage(document, [layer], frame)
        reference = lottie_reference(DATA / filename, layer, frame)
        if not (ours.any() or reference.any()):
            continue
        assert soft_iou(ours, reference) >= 0.99, (filename, layer, frame)


@pytest.mark.parametrize("layer", ["body", "arm"])
def test_wave_example_agrees_with_lottie_rendering(layer):
    path = EXAMPLES / "wave" / "wave.json"
    document = open_document(path)
    for frame in (0, 12, 30):
        assert soft_iou(coverage(document, [layer], frame), lottie_reference(path, layer, frame)) >= 0.99


def test_svg_sequence_files_have_their_css_transforms_resolved(tmp_path):
    """cairosvg alone reads rotate(90deg) as no rotation; the CSS timeline resolves it in every file."""
    for index in range(2):
        (tmp_path / f"f{index}.svg").write_text(
            '<svg xmlns="http://www.w3.org/2000/svg" width="40" height="40"><style>rect{transform:rotate(90deg);'
            f'transform-origin:20px 20px}}</style><g id="bar"><rect y="16" width="{10 + 10 * index}" height="8"/>'
            '</g></svg>')
    document = open_document(tmp_path / "f%d.svg", fps=24)
    assert not document.unsupported
    turned = coverage(document, ["bar"], 1)
    assert turned[:20, 16:24].sum() == pytest.approx(160) and turned.sum() == pytest.approx(160)


def test_svg_sequence_files_with_animations_are_listed(tmp_path):
    (tmp_path / "f0.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><rect width="5" '
                                     'height="5"><animate attributeName="width" to="10" dur="1s"/></rect></svg>')
    assert [(item.element, item.message) for item in open_document(tmp_path / "f%d.svg", fps=24).unsupported] == [
        ("f0.svg: SMIL animations", "the files of a sequence are stills: their animations are shown as at time 0")]
