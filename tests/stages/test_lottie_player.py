"""The ThorVG Lottie renderer: one fixture per feature, rlottie as an independent oracle, crash isolation.

rlottie draws integer frames only and, on these fixtures, ignores subtract masks, hidden
groups, dashes, time remapping, expressions and text; where it does, exact geometry is
checked instead (tests/data/lottie/README.md gives each fixture's numbers).
"""

import json
import pickle
import re
import shutil
import struct
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from rlottie_python import LottieAnimation

from fluidymation.errors import InputError
from fluidymation.stages.vector import open_document, renderer_for
from fluidymation.stages.vector import thorvg_worker
from fluidymation.stages.vector.thorvg_renderer import ThorVGRenderer

DATA = Path(__file__).parent.parent / "data" / "lottie"
EXAMPLES = Path(__file__).parents[2] / "examples"


def coverage(document, names, frame, *, fps=None, size=None, renderer=None):
    """Coverage of ``names`` at scene ``frame`` (at ``fps``, else the file's own rate)."""
    renderer = renderer or renderer_for(document)
    size = size or (round(document.width), round(document.height))
    return renderer.render(document, names, frame / (fps or document.lottie_fps), size)[:, :, 3] / 255.0


def oracle(document, names, frame, size):
    """rlottie's coverage of the same isolated JSON at file frame ``frame``, at ``size``."""
    isolated = document.isolate(names, frame / document.lottie_fps)
    width, height = size
    buffer = LottieAnimation.from_data(isolated.json.decode()).lottie_animation_render(
        frame_num=round(isolated.frame), width=width, height=height)
    return np.frombuffer(buffer, np.uint8).reshape(height, width, 4)[:, :, 3] / 255.0


def box(coverage_map):
    ys, xs = np.nonzero(coverage_map >= 0.5)
    return int(xs.min()), int(xs.max()) + 1, int(ys.min()), int(ys.max()) + 1


def iou(a, b):
    a, b = a >= 0.5, b >= 0.5
    return (a & b).sum() / (a | b).sum() if (a | b).any() else 1.0


def agreement(document, names, frame):
    """IoU with rlottie at four times the file's size (the players' edges differ by a pixel here and there)."""
    size = (4 * round(document.width), 4 * round(document.height))
    return iou(coverage(document, names, frame, size=size), oracle(document, names, frame, size))


# --- agreement with rlottie -------------------------------------------------------------------------------------

ORACLE_CASES = [("shapes_keyframe.json", ["square"]), ("shapes_keyframe.json", ["disc"]),
                ("parenting.json", ["head"]), ("parenting.json", ["torso"]), ("parenting.tgs", ["head"]),
                ("precomp.json", ["leaves"]), ("precomp.lottie", ["ground"]), ("trim_path.json", ["line"]),
                ("mask.json", ["masked_square"]), ("matte.json", ["stripes"]), ("motion_30fps.json", ["mover"]),
                ("image_beside/anim.json", ["picture"]), ("two_animations.lottie", ["first square"])]


@pytest.mark.parametrize("filename,names", ORACLE_CASES)
def test_layers_agree_with_rlottie(filename, names):
    document = open_document(DATA / filename)
    for frame in (0, 5, 11):
        assert agreement(document, names, frame) >= 0.98, frame


def test_split_children_agree_with_rlottie():
    document = open_document(DATA / "precomp.json", split=("leaves",))
    for name in ("leaves/leaf_a", "leaves/leaf_b"):
        for frame in (0, 5):
            assert agreement(document, [name], frame) >= 0.98


def test_wave_example_agrees_with_rlottie():
    document = open_document(EXAMPLES / "wave" / "wave.json")
    for name in document.layer_names():
        for frame in (0, 12, 30):
            assert agreement(document, [name], frame) >= 0.98


# --- features, by geometry --------------------------------------------------------------------------------------

def test_a_subtract_mask_cuts_a_hole():
    ring = coverage(open_document(DATA / "mask_subtract.json"), ["ring"], 0)
    assert box(ring) == (16, 80, 16, 80)
    assert (ring >= 0.5).sum() == 64 * 64 - 32 * 32 and ring[48, 48] == 0


def test_track_matte_kinds(tmp_path):
    """Alpha matte: the stripes inside the disc; inverted alpha matte (tt 2): outside it; a matte named by tp."""
    data = json.loads((DATA / "matte.json").read_text())
    inside = coverage(open_document(DATA / "matte.json"), ["stripes"], 0)
    data["layers"][1]["tt"] = 2
    (tmp_path / "inverted.json").write_text(json.dumps(data))
    outside = coverage(open_document(tmp_path / "inverted.json"), ["stripes"], 0)
    assert np.allclose(inside + outside, 1, atol=0.01)
    data["layers"][1] |= {"tt": 1, "tp": 1}
    data["layers"].insert(1, data["layers"][0] | {"ind": 3, "nm": "other", "td": 0, "hd": False})
    (tmp_path / "tp.json").write_text(json.dumps(data))
    assert np.array_equal(coverage(open_document(tmp_path / "tp.json"), ["stripes"], 0), inside)


def test_hidden_groups_and_layers_draw_nothing():
    document = open_document(DATA / "hidden.json")
    assert box(coverage(document, ["shapes"], 0)) == (16, 32, 40, 56)
    assert coverage(document, ["hidden layer"], 0).sum() == 0


def test_dashes_draw_dashes():
    dashed = coverage(open_document(DATA / "dashes.json"), ["dashed"], 0) >= 0.5
    assert box(dashed) == (16, 72, 44, 52) and dashed.sum() == 4 * 8 * 8
    assert [dashed[48, x] for x in (20, 28, 36, 44, 52, 60, 68)] == [True, False] * 3 + [True]


def test_time_remap_holds_the_precomps_frame():
    document = open_document(DATA / "time_remap.json")
    assert {box(coverage(document, ["held"], frame)) for frame in range(12)} == {(20, 36, 40, 56)}


def test_expressions_are_evaluated():
    document = open_document(DATA / "expression.json")
    assert box(coverage(document, ["spinner"], 0)) == (16, 80, 44, 52)
    assert box(coverage(document, ["spinner"], 6)) == (44, 52, 16, 80)  # 0.5 s: turned 90 degrees


def test_text_is_drawn_with_the_files_glyphs():
    label = coverage(open_document(DATA / "text.json"), ["label"], 0) >= 0.5
    assert box(label) == (20, 45, 35, 70) and label.sum() == 2 * 5 * 35  # two 5x35 bars, 20 px apart
    assert not label[50, 30]


def test_a_30fps_file_at_24fps_moves_evenly():
    """Scene frame k at 24 fps is file frame 1.25 k: the square advances 2.5 px a frame, no half-frame jitter."""
    document = open_document(DATA / "motion_30fps.json")
    centres = []
    for k in range(20):
        cover = coverage(document, ["mover"], k, fps=24)
        centres.append((cover.sum(axis=0) * np.arange(cover.shape[1])).sum() / cover.sum() + 0.5)
    assert np.allclose(np.diff(centres), 2.5, atol=0.02)
    assert centres[0] == pytest.approx(16, abs=0.02)


def test_fitted_as_the_svg_path_fits():
    """A wider output: the composition scaled to fit the height and centred, as lottie-svg (cairosvg) drew it."""
    document = open_document(DATA / "parenting.json")
    wide = coverage(document, ["torso"], 5, size=(192, 96))
    assert box(wide) == (42 + 48, 62 + 48, 41, 71)
    tall = coverage(document, ["torso"], 5, size=(96, 192))
    assert box(tall) == (42, 62, 41 + 48, 71 + 48)
    assert box(coverage(document, ["torso"], 5, size=(192, 192))) == (84, 124, 82, 142)


def test_a_worker_keeps_few_animations_and_forgets_the_oldest(monkeypatch):
    monkeypatch.setattr("fluidymation.stages.vector.thorvg_renderer.LOADED_PER_WORKER", 1)
    renderer, document = ThorVGRenderer(), open_document(DATA / "parenting.json")
    first = [renderer.render(document, [name], 0.4, (96, 96)) for name in ("head", "torso")]
    again = [renderer.render(document, [name], 0.4, (96, 96)) for name in ("head", "torso")]
    assert all(np.array_equal(a, b) for a, b in zip(first, again))
    assert list(renderer._workers[document].loaded) == [("torso",)]


def test_a_copied_renderer_starts_its_own_worker():
    """Plans are pickled to spawned jobs: the copy leaves the worker behind and starts one of its own."""
    renderer, document = ThorVGRenderer(frame_timeout=5), open_document(DATA / "parenting.json")
    here = renderer.render(document, ["head"], 0.4, (96, 96))
    copy = pickle.loads(pickle.dumps(renderer))
    assert copy.frame_timeout == 5 and not copy._workers
    assert np.array_equal(copy.render(document, ["head"], 0.4, (96, 96)), here)


def test_rendering_is_deterministic():
    document = open_document(DATA / "precomp.json")
    first = ThorVGRenderer().render(document, ["leaves"], 0.4, (128, 128))
    again = ThorVGRenderer().render(open_document(DATA / "precomp.json"), ["leaves"], 0.4, (128, 128))
    assert np.array_equal(first, again) and first.dtype == np.uint8 and first.shape == (128, 128, 4)
    assert (first[:, :, :3] <= first[:, :, 3:]).all()  # premultiplied


def test_layers_sharing_a_name_are_one_layer(tmp_path):
    data = json.loads((DATA / "shapes_keyframe.json").read_text())
    data["layers"][1]["nm"] = "square"
    (tmp_path / "anim.json").write_text(json.dumps(data))
    document = open_document(tmp_path / "anim.json")
    assert document.layer_names() == ["square"]
    both = coverage(open_document(DATA / "shapes_keyframe.json"), ["square", "disc"], 0)
    assert np.array_equal(coverage(document, ["square"], 0), both)


# --- packed forms -----------------------------------------------------------------------------------------------

def test_dotlottie_with_two_animations_shows_the_first():
    document = open_document(DATA / "two_animations.lottie")
    assert document.layer_names() == ["first square"]
    assert box(coverage(document, ["first square"], 0)) == (16, 32, 16, 32)


def test_dotlottie_initial_theme_is_applied():
    document = open_document(DATA / "themed.lottie")
    rgba = ThorVGRenderer().render(document, ["square"], 0, (96, 96))
    assert box(rgba[:, :, 3] / 255) == (64, 80, 64, 80) and tuple(rgba[72, 72]) == (230, 26, 26, 255)
    assert [(item.element, item.message) for item in document.unsupported] == [
        ("theme 'moved' rules[2] 'logo'", "a rule of type Image, which is not applied")]


def test_dotlottie_animation_and_theme_are_picked_by_id():
    second = open_document(DATA / "two_animations.lottie", animation="second")
    assert second.layer_names() == ["second square"] and second.choices == {"animation": "second"}
    assert box(coverage(second, ["second square"], 0)) == (64, 80, 64, 80)
    recoloured = open_document(DATA / "themed.lottie", theme="recoloured")
    assert recoloured.choices == {"animation": "themed", "theme": "recoloured"} and not recoloured.unsupported
    rgba = ThorVGRenderer().render(recoloured, ["square"], 0, (96, 96))
    assert box(rgba[:, :, 3] / 255) == (16, 32, 16, 32) and tuple(rgba[24, 24]) == (26, 204, 26, 255)


@pytest.mark.parametrize("path, options, message", [
    ("two_animations.lottie", {"animation": "third"}, "animation 'third' is not in the archive (its animations: "
                                                      "first, second)"),
    ("themed.lottie", {"theme": "dark"}, "the scene's theme 'dark' is not in the archive (t/dark.json; its themes: "
                                         "moved, recoloured)"),
    ("parenting.json", {"theme": "dark"}, "the scene's 'theme' picks an animation or theme of a dotLottie archive"),
])
def test_dotlottie_choices_that_do_not_exist_are_refused(path, options, message):
    with pytest.raises(InputError, match=re.escape(message)):
        open_document(DATA / path, **options)


def test_the_files_own_slots_are_used(tmp_path):
    """Inlined by the reader: ThorVG 1.0 crashes applying a position slot itself."""
    with zipfile.ZipFile(DATA / "themed.lottie") as archive:
        data = json.loads(archive.read("a/themed.json"))
    data["slots"] = {"squarePosition": {"p": {"a": 0, "k": [40, 72]}}}
    (tmp_path / "anim.json").write_text(json.dumps(data))
    assert box(coverage(open_document(tmp_path / "anim.json"), ["square"], 0)) == (32, 48, 64, 80)


def test_tgs_matches_plain_json():
    plain, sticker = open_document(DATA / "parenting.json"), open_document(DATA / "parenting.tgs")
    assert np.array_equal(coverage(plain, ["head"], 5), coverage(sticker, ["head"], 5))


# --- image assets beside the file -------------------------------------------------------------------------------

def test_image_beside_the_file_is_read_and_listed():
    document = open_document(DATA / "image_beside" / "anim.json")
    assert document.files == [DATA / "image_beside" / "anim.json", (DATA / "image_beside/images/dot.png").resolve()]
    assert box(coverage(document, ["picture"], 0)) == (16, 48, 40, 72)


@pytest.mark.parametrize("folder,name,message", [
    ("../", "dot.png", "outside the input's folder"),
    ("", "/etc/passwd", "outside the input's folder"),
    ("https://example.com/", "dot.png", "refers to the external image 'https://example.com/dot.png', a URL"),
    ("images/", "missing.png", "which is not a file"),
])
def test_image_assets_elsewhere_are_refused(tmp_path, folder, name, message):
    shutil.copytree(DATA / "image_beside", tmp_path / "in")
    shutil.copy(DATA / "image_beside/images/dot.png", tmp_path / "dot.png")
    data = json.loads((tmp_path / "in/anim.json").read_text())
    data["assets"][0] |= {"u": folder, "p": name}
    (tmp_path / "in/anim.json").write_text(json.dumps(data))
    with pytest.raises(InputError, match=r"anim.json: assets\[0\] \(id 'dot'\) " + ".*" + message.replace("(", r"\(")):
        open_document(tmp_path / "in/anim.json")


def test_a_link_out_of_the_folder_is_refused(tmp_path):
    shutil.copytree(DATA / "image_beside", tmp_path / "in")
    shutil.copy(DATA / "image_beside/images/dot.png", tmp_path / "secret.png")
    (tmp_path / "in/images/dot.png").unlink()
    (tmp_path / "in/images/dot.png").symlink_to(tmp_path / "secret.png")
    with pytest.raises(InputError, match="outside the input's folder"):
        open_document(tmp_path / "in/anim.json")


# --- what the player does not draw ------------------------------------------------------------------------------

def test_what_the_player_ignores_is_listed(tmp_path):
    data = json.loads((DATA / "shapes_keyframe.json").read_text())
    square = data["layers"][0]
    square["shapes"][0]["it"].insert(1, {"ty": "mm", "nm": "Merge Paths 1", "mm": 3})
    square["ef"] = [{"ty": 27, "nm": "Glow", "en": 1}, {"ty": 5, "nm": "Slider", "mn": "ADBE Slider Control", "en": 1}]
    data["layers"].append({"ty": 13, "nm": "Camera 1", "ind": 9, "ip": 0, "op": 12, "st": 0})
    (tmp_path / "anim.json").write_text(json.dumps(data))
    found = {(item.element, item.message) for item in open_document(tmp_path / "anim.json").unsupported}
    assert found == {
        ("layers[0] 'square' ef[0] 'Glow'", "effect type 27, which the player does not draw"),
        ("layers[0] 'square' shapes[0] 'square group' it[1] 'Merge Paths 1'",
         "merge paths, which the player ignores: the shapes are drawn without it"),
        ("layers[2] 'Camera 1'", "a camera, which the player does not draw"),
    }
    assert open_document(DATA / "text.json").unsupported == ()


def test_text_without_glyphs_or_an_embedded_font_is_listed(tmp_path):
    data = json.loads((DATA / "text.json").read_text())
    data["chars"] = []
    (tmp_path / "anim.json").write_text(json.dumps(data))
    [item] = open_document(tmp_path / "anim.json").unsupported
    assert item.element == "layers[0] 'label'" and "font 'TestSans-Regular'" in item.message


def test_check_warns_and_strict_refuses(cli, tmp_path):
    data = json.loads((DATA / "shapes_keyframe.json").read_text())
    data["layers"][0]["ef"] = [{"ty": 27, "nm": "Glow", "en": 1}]
    (tmp_path / "anim.json").write_text(json.dumps(data))
    (tmp_path / "scene.yaml").write_text("input: anim.json\nlayers:\n  - {name: square}\n")
    code, _, err = cli("check", tmp_path / "scene.yaml")
    assert code == 0 and "warning: unsupported: " in err and "layers[0] 'square' ef[0] 'Glow'" in err
    code, _, err = cli("--strict", "check", tmp_path / "scene.yaml")
    assert code == 2 and "--strict: 1 unsupported element(s)" in err


# --- a crash or hang of the player ------------------------------------------------------------------------------

def faulty_worker(render_body: str) -> tuple[str, ...]:
    """The real worker (its setup and protocol) with ``Player.render`` replaced by ``render_body``."""
    folder = str(Path(thorvg_worker.__file__).parent)
    code = (f"import os, resource, signal, struct, sys, time; sys.path.insert(0, {folder!r}); "
            f"import thorvg_worker as w; w.Player.render = lambda self, key, frame, width, height: {render_body}; "
            "w.main()")
    return (sys.executable, "-c", code)


def test_a_crash_becomes_an_input_error_naming_file_and_frame():
    renderer = ThorVGRenderer(command=faulty_worker("os.kill(os.getpid(), signal.SIGSEGV)"))
    document = open_document(DATA / "shapes_keyframe.json")
    with pytest.raises(InputError, match=r"shapes_keyframe.json: frame 6 \(0.500 s\): the Lottie player crashed "
                                         r"while drawing \(signal SIGSEGV\)"):
        renderer.render(document, ["square"], 0.5, (96, 96))


def test_a_hang_is_stopped_at_the_timeout():
    renderer = ThorVGRenderer(frame_timeout=1, command=faulty_worker("time.sleep(600)"))
    with pytest.raises(InputError, match=r"frame 3 \(0.250 s\): the Lottie player did not finish drawing in time"):
        renderer.render(open_document(DATA / "shapes_keyframe.json"), ["square"], 0.25, (96, 96))


def test_the_worker_writes_no_core_dump():
    renderer = ThorVGRenderer(command=faulty_worker("struct.pack('>qq', *resource.getrlimit(resource.RLIMIT_CORE))"))
    limits = renderer.render(open_document(DATA / "shapes_keyframe.json"), ["square"], 0, (1, 4))
    assert struct.unpack(">qq", limits.tobytes()) == (0, 0)


def test_a_crashed_worker_is_replaced_on_the_next_render():
    renderer = ThorVGRenderer()
    document = open_document(DATA / "shapes_keyframe.json")
    first = renderer.render(document, ["square"], 0, (96, 96))
    renderer._workers[document].process.kill()
    renderer._workers[document].process.wait()
    assert np.array_equal(renderer.render(document, ["square"], 0, (96, 96)), first)


def test_a_crash_during_render_exits_2_and_keeps_finished_frames(cli, tmp_path, monkeypatch):
    crashing = ThorVGRenderer(command=faulty_worker(
        "os.kill(os.getpid(), signal.SIGSEGV) if frame >= 4 else bytes(width * height * 4)"))
    monkeypatch.setattr("fluidymation.stages.vector.RENDERERS", (crashing,))
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"input: {DATA / 'shapes_keyframe.json'}\nlayers:\n  - {{name: square}}\n")
    code, _, err = cli("masks", scene, "-o", tmp_path / "masks")
    assert code == 2
    assert "shapes_keyframe.json: frame 4 (0.333 s): the Lottie player crashed while drawing (signal SIGSEGV)" in err
    assert sorted(p.name for p in (tmp_path / "masks" / "square").iterdir()) == [f"{k:05d}.png" for k in range(4)]
