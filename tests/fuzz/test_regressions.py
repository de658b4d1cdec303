"""What the readers' fuzzing found (tests/fuzz/harness.py), one small case each: exit code 2 with a message naming
the file and the key, element or member (or success), where each used to be an internal error (exit 1), a hang or
an unbounded use of memory."""

import gzip
import io
import json
import pickle

import imageio.v3 as iio
import numpy as np
import pytest

from tests.fuzz.packed import _bomb_zip, _encrypted, _members, _method, _zip
from tests.fuzz.rasters import _fixed_crc, exemplar_seeds, large_png
from tests.scenes import ROOT, blob_scene, write_scene

LOTTIE = ROOT / "examples/wave/wave.json"


def refused(cli, scene, *fragments):
    code, out, err = cli("-q", "check", scene)
    assert code == 2, err
    assert err.startswith("error:") and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, err
    return err


@pytest.mark.parametrize("text", ["x: " + "[" * 5000 + "1" + "]" * 5000 + "\n",
                                  "x: " + "[" * 150 + "1" + "]" * 150 + "\n"])
def test_scene_nested_too_deeply(cli, tmp_path, text):  # was RecursionError in pipeline/yaml_lines.py
    refused(cli, write_scene(tmp_path, blob_scene() + text), "scene.yaml", "nested")


def test_required_value_written_as_null(cli, tmp_path):  # was TypeError in pipeline/scene.py (layer name None)
    scene = blob_scene(layers="  - {name: null}\n")
    refused(cli, write_scene(tmp_path, scene), "scene.yaml", "layers[0].name", "is required")


def test_null_takes_the_default(cli, tmp_path):  # frames.start: null was TypeError comparing None with an int
    scene = blob_scene(size=32).replace("frames: {start: 0, end: 4}", "frames: {start: null, end: 2}")
    code, out, err = cli("-q", "check", write_scene(tmp_path, scene))
    assert code == 0, err
    assert "frames:  0:2" in out


@pytest.mark.parametrize("value,fragment", [('"a\\0b.png"', "NUL character"), ("x" * 5000 + ".png", "too long")])
def test_unusable_file_names(cli, tmp_path, value, fragment):  # were ValueError / OSError from pathlib
    scene = blob_scene(layers="  - {name: blob, stylizer: keyframes, keyframes: {0: %s}}\n" % value)
    refused(cli, write_scene(tmp_path, scene), "scene.yaml", "layers[0].keyframes", fragment)


def test_lottie_nested_too_deeply(cli, tmp_path):  # was RecursionError in json.loads
    (tmp_path / "deep.json").write_text('{"layers": ' + "[" * 100000 + "]" * 100000 + "}")
    write_scene(tmp_path, "input: deep.json\n")
    refused(cli, tmp_path / "scene.yaml", "deep.json", "nested too deeply")


@pytest.mark.parametrize("where", ["shape type", "font name"])
def test_lottie_unhashable_values(cli, tmp_path, where):  # was TypeError: unhashable type (lottie_reader.py)
    data = json.loads(LOTTIE.read_text())
    if where == "shape type":
        data["layers"][0]["shapes"][0]["ty"] = ["gr"]
    else:
        data["fonts"] = {"list": [{"fName": ["Sans"], "fFamily": {"a": 1}}]}
        data["chars"] = [{"fFamily": ["Sans"]}]
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    code, out, err = cli("-q", "check", tmp_path / "scene.yaml")
    assert code in (0, 2) and "internal error" not in err, err


def test_svg_nan_length(cli, tmp_path):  # was cairocffi.CairoError (invalid matrix) from cairosvg's ellipse
    (tmp_path / "nan.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32">'
                                      '<ellipse id="e" cx="16" cy="16" rx="8" ry="nan"/></svg>')
    write_scene(tmp_path, "input: nan.svg\n")
    refused(cli, tmp_path / "scene.yaml", "nan.svg", "cannot be rendered as SVG")


@pytest.mark.parametrize("key", ["ind", "tp", "refId"])
def test_lottie_reference_that_is_a_list(cli, tmp_path, key):  # was TypeError: unhashable (lottie_reader.py)
    data = json.loads(LOTTIE.read_text())
    data["layers"][0][key] = [1]
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    refused(cli, tmp_path / "scene.yaml", "anim.json", f"layers[0].{key} must be a number or text")


@pytest.mark.parametrize("name,where,path", [
    ("matte.json", ["layers", 0, "shapes", 0, "it", 0, "p", "k", 0], "layers[0].shapes[0].it[0].p.k[0]"),  # a point
    ("parenting.json", ["layers", 2, "ks", "p", "k", 0], "layers[2].ks.p.k[0]"),  # a keyframe
])
def test_lottie_null_in_a_list(cli, tmp_path, name, where, path):  # ThorVG 1.0 hung loading them: exit 2 after 120 s
    data = json.loads((ROOT / "tests/data/lottie" / name).read_text())
    parent = data
    for key in where[:-1]:
        parent = parent[key]
    parent[where[-1]] = None
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    refused(cli, tmp_path / "scene.yaml", "anim.json", f"{path} is null")


def test_svg_endless_css_animation(cli, tmp_path):  # was OverflowError in frames_in (stages/vector/base.py)
    (tmp_path / "long.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32"><style>@keyframes a { to { opacity: 0 } }'
        " rect { animation: a 1s; animation-iteration-count: 1e308 }</style>"
        '<g id="g"><rect width="8" height="8"/></g></svg>')
    write_scene(tmp_path, "input: long.svg\n")
    refused(cli, tmp_path / "scene.yaml", "long.svg", "too long to count its frames")


@pytest.mark.parametrize("svg", ['<ellipse cx="16" cy="16" rx="8" ry="1e308"/>',
                                 '<ellipse cx="16" cy="16" rx="8" ry="32"><animate attributeName="ry" from="-1e308" '
                                 'to="46" dur="1s" fill="freeze"/></ellipse>'])
def test_svg_radius_beyond_reason(tmp_path, svg):  # cairo's arc looped for ever (a subprocess: a hang is a failure)
    import subprocess
    import sys

    (tmp_path / "huge.svg").write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="32" height="32">{svg}</svg>')
    write_scene(tmp_path, "input: huge.svg\nframes: {start: 0, end: 2}\n")
    done = subprocess.run([sys.executable, "-m", "fluidymation", "-q", "check", str(tmp_path / "scene.yaml")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stderr
    assert "huge.svg" in done.stderr and 'ry="' in done.stderr and "radius beyond" in done.stderr, done.stderr


def _dotlottie(tmp_path, archive: bytes):
    (tmp_path / "anim.lottie").write_bytes(archive)
    return write_scene(tmp_path, "input: anim.lottie\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")


@pytest.mark.parametrize("damage,fragment", [(lambda data: _method(data, 99), "compressed by a method"),
                                             (_encrypted, "is encrypted"),
                                             (lambda data: _bomb_zip("animations/anim.json", declared=10), "damaged")])
def test_dotlottie_member_unreadable(cli, tmp_path, damage, fragment):  # were NotImplementedError, RuntimeError,
    # BadZipFile (bad CRC) and zlib.error from zipfile (stages/vector/safety.py read_zip_member)
    archive = damage((ROOT / "tests/data/lottie/precomp.lottie").read_bytes())
    refused(cli, _dotlottie(tmp_path, archive), "anim.lottie", "archive member", fragment)


def test_tgs_corrupt_deflate_stream(cli, tmp_path):  # was zlib.error from gzip (stages/vector/safety.py)
    data = bytearray(gzip.compress(b'{"v": "5.5.2", "layers": []}' * 50, mtime=0))
    data[12:16] = b"\xff\xff\xff\xff"
    (tmp_path / "anim.tgs").write_bytes(bytes(data))
    write_scene(tmp_path, "input: anim.tgs\n")
    refused(cli, tmp_path / "scene.yaml", "anim.tgs", "not valid gzip data")


def _npy_bytes(array: np.ndarray, allow_pickle: bool = False) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=allow_pickle)
    return buffer.getvalue()


def _npz_bytes(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, flow=array)
    return buffer.getvalue()


def _npy_header_shape(flow: np.ndarray, shape: str) -> bytes:
    """``flow`` as .npy bytes whose header claims ``shape``."""
    return _npy_bytes(flow).replace(str(flow.shape).encode(), shape.encode(), 1)


FLOW = np.zeros((24, 24, 2), np.float32)


@pytest.mark.parametrize("content,fragment", [
    (pickle.dumps([print]), "not a readable .npy array"),  # was ValueError from np.load (pickled data)
    (_npy_bytes(np.array([print], dtype=object), allow_pickle=True), "got dtype object"),  # ValueError: object arrays
    (_npy_header_shape(FLOW, "(99999, 99999, 2)"), "the masks have 24x24"),  # was MemoryError
    (_npy_header_shape(FLOW, "(24, 24, 2, 1)"), "must have shape (H, W, 2)"),  # was IndexError in _flow_colours
    (_npy_bytes(FLOW.astype(np.complex64)), "must hold floats"),  # was TypeError (hypot of complex)
    (_npy_bytes(FLOW)[:-7], "the file has"),  # was ValueError: failed to read all data
    (_npz_bytes(FLOW), "not a readable .npy array"),  # was KeyError / AttributeError: an NpzFile
])
def test_exemplar_show_flow_files(cli, tmp_path, content, fragment):  # np.load was unchecked in exemplar show
    for folder in ("rgb", "mask", "flow"):
        (tmp_path / "ex" / folder).mkdir(parents=True)
    iio.imwrite(tmp_path / "ex/rgb/00000.png", np.full((24, 24, 3), 200, np.uint8))
    iio.imwrite(tmp_path / "ex/mask/00000.png", np.full((24, 24), 255, np.uint8))
    (tmp_path / "ex/flow/00000.npy").write_bytes(content)
    code, _, err = cli("-q", "exemplar", "show", tmp_path / "ex", "-o", tmp_path / "sheet.png")
    assert code == 2 and "00000.npy" in err and fragment in err and "Traceback" not in err, err


def test_exemplar_show_mask_of_another_size(cli, tmp_path):  # was IndexError (boolean index)
    for folder in ("rgb", "mask"):
        (tmp_path / "ex" / folder).mkdir(parents=True)
    iio.imwrite(tmp_path / "ex/rgb/00000.png", np.full((24, 24, 3), 200, np.uint8))
    iio.imwrite(tmp_path / "ex/mask/00000.png", np.full((1, 24), 255, np.uint8))
    code, _, err = cli("-q", "exemplar", "show", tmp_path / "ex", "-o", tmp_path / "sheet.png")
    assert code == 2 and "mask/00000.png" in err and "the mask is 24x1" in err, err


@pytest.mark.parametrize("content", [_npz_bytes(np.zeros((32, 32, 2), np.float32)),  # was AttributeError: NpzFile
                                     _npy_header_shape(np.zeros((32, 32, 2), np.float32), "(99999, 99999, 2)")])
def test_guides_given_flow_npy(cli, tmp_path, content):  # the latter was MemoryError in np.load
    (tmp_path / "flow").mkdir()
    for index in range(2):
        (tmp_path / "flow" / f"{index:05d}.npy").write_bytes(content)
    scene = write_scene(tmp_path, f"input: {ROOT / 'examples/blob/blob.svg'}\nsize: [32, 32]\n"
                                  "frames: {start: 0, end: 2}\nlayers:\n  - {name: blob, select: [blob]}\n")
    code, _, err = cli("-q", "guides", scene, "--layer", "blob", "--flow", tmp_path / "flow/%05d.npy")
    assert code == 2 and "00000.npy" in err and "Traceback" not in err, err


def test_exemplar_segments_that_are_no_file(cli, tmp_path):  # was FileNotFoundError in pipeline/exemplars.py
    iio.imwrite(tmp_path / "still.png", np.full((24, 24, 3), 200, np.uint8))
    scene = blob_scene(size=32, frames=(0, 1)).replace(
        "  ink: {builtin", "  still: {image: still.png, segments: '*'}\n  ink: {builtin")
    scene = scene.replace("exemplar: ink", "exemplar: still")
    code, _, err = cli("-q", "render", write_scene(tmp_path, scene), "--until", "stylize")
    assert code == 2 and "exemplars.still.segments" in err and "is not a file" in err, err


def test_exemplar_pattern_matching_a_folder(cli, tmp_path):  # a folder matched by mask: '*' was read as an image
    (tmp_path / "rec").mkdir()
    iio.imwrite(tmp_path / "rec/00.png", np.full((24, 24, 3), 200, np.uint8))
    (tmp_path / "masks/sub.png").mkdir(parents=True)
    iio.imwrite(tmp_path / "masks/00.png", np.full((24, 24), 255, np.uint8))
    scene = blob_scene(size=32, frames=(0, 1)).replace(
        "  ink: {builtin", "  rec: {images: rec, mask: 'masks/*.png'}\n  ink: {builtin")
    code, _, err = cli("-q", "render", write_scene(tmp_path, scene.replace("exemplar: ink", "exemplar: rec")),
                       "--until", "stylize")
    assert code == 0, err


def _with_header_size(png: bytes, width: int, height: int) -> bytes:
    data = bytearray(png)
    data[16:24] = width.to_bytes(4, "big") + height.to_bytes(4, "big")
    return bytes(_fixed_crc(data))


@pytest.mark.parametrize("declared", [False, True])
def test_exemplar_image_too_large(cli, tmp_path, declared):  # a 12000² PNG took 199 s and 18 GB resident
    image = large_png() if not declared else _with_header_size(iio.imwrite("<bytes>", np.zeros((4, 4), np.uint8),
                                                                            extension=".png"), 65536, 65536)
    (tmp_path / "still.png").write_bytes(image)
    scene = blob_scene(size=32, frames=(0, 1)).replace(
        "  ink: {builtin", "  still: {image: still.png, mask: full}\n  ink: {builtin")
    code, _, err = cli("-q", "render", write_scene(tmp_path, scene.replace("exemplar: ink", "exemplar: still")),
                       "--until", "stylize")
    assert code == 2 and "still.png" in err and "over the limit of 32 megapixels" in err, err


def test_dotlottie_zip_of_an_unknown_version(cli, tmp_path):  # was NotImplementedError from zipfile.ZipFile
    archive = bytearray((ROOT / "tests/data/lottie/precomp.lottie").read_bytes())
    central = archive.find(b"PK\x01\x02")
    archive[central + 6] = 230  # "version needed to extract": 23.0
    refused(cli, _dotlottie(tmp_path, bytes(archive)), "anim.lottie", "zipfile cannot read", "version 23.0")


def test_dotlottie_assets_that_are_no_list(cli, tmp_path):  # was TypeError in lottie_reader.py _image_assets
    animation = json.loads((ROOT / "tests/data/lottie/precomp.json").read_text())
    animation["assets"] = 1
    archive = _zip({"manifest.json": b'{"animations": [{"id": "anim"}]}',
                    "animations/anim.json": json.dumps(animation).encode()})
    refused(cli, _dotlottie(tmp_path, archive), "anim.lottie", "'assets' must be a list of objects")


def test_lottie_slot_id_that_is_a_list(cli, tmp_path):  # was TypeError: unhashable (lottie_reader.py _inline_slots)
    data = json.loads(LOTTIE.read_text())
    data["slots"] = {"colour": {"p": {"a": 0, "k": [1, 0, 0, 1]}}}
    data["layers"][0]["ks"]["o"]["sid"] = ["colour"]
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    code, out, err = cli("-q", "check", tmp_path / "scene.yaml")
    assert code == 0, err


def test_lottie_path_tangent_beyond_reason(tmp_path):  # ThorVG trimmed the path for ever: exit 2 after 60 s
    import subprocess
    import sys

    data = json.loads((ROOT / "tests/data/lottie/trim_path.json").read_text())
    data["layers"][0]["shapes"][0]["it"][0]["ks"]["k"]["o"][0][1] = 2**31
    (tmp_path / "anim.json").write_text(json.dumps(data))
    write_scene(tmp_path, "input: anim.json\nsize: [32, 32]\nframes: {start: 0, end: 2}\n")
    done = subprocess.run([sys.executable, "-m", "fluidymation", "-q", "check", str(tmp_path / "scene.yaml")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stderr
    assert "anim.json" in done.stderr and "layers[0].shapes[0].it[0].ks.k.o[0][1] is 2147483648" in done.stderr


def test_dotlottie_theme_rule_type_that_is_a_list(cli, tmp_path):  # was TypeError: unhashable (_apply_theme)
    members = _members((ROOT / "tests/data/lottie/themed.lottie").read_bytes())
    theme = json.loads(members["t/moved.json"])
    theme["rules"][0]["type"] = ["Color"]
    members["t/moved.json"] = json.dumps(theme).encode()
    code, out, err = cli("-q", "check", _dotlottie(tmp_path, _zip(members)))
    assert code == 0 and "a rule of type ['Color'], which is not applied" in err, err


def test_recorded_video_that_cannot_be_decoded(cli, tmp_path):  # ffmpeg's pipes were left open (ResourceWarning)
    (tmp_path / "rec.mp4").write_bytes(exemplar_seeds()["mp4"][:200])
    scene = blob_scene(size=32, frames=(0, 1)).replace(
        "  ink: {builtin", "  rec: {video: rec.mp4, mask: full}\n  ink: {builtin")
    code, _, err = cli("-q", "render", write_scene(tmp_path, scene.replace("exemplar: ink", "exemplar: rec")),
                       "--until", "stylize")
    assert code == 2 and "rec.mp4: cannot decode the video" in err, err


def test_dotlottie_member_name_not_utf8(cli, tmp_path):  # was UnicodeDecodeError from zipfile.ZipFile
    archive = _zip({"manifest.json": b"{}", "animations/an\u00efm.json": LOTTIE.read_bytes()})
    archive = archive.replace("\u00ef".encode(), b"\xb0\xaf")  # the names' UTF-8 flag stays set
    refused(cli, _dotlottie(tmp_path, archive), "anim.lottie", "zipfile cannot read", "can't decode byte 0xb0")


def test_dotlottie_central_directory_offset_too_large(cli, tmp_path):  # was ValueError (negative seek) in zipfile
    archive = bytearray((ROOT / "tests/data/lottie/precomp.lottie").read_bytes())
    end = archive.rfind(b"PK\x05\x06")
    offset = int.from_bytes(archive[end + 16:end + 20], "little") + 4_000_000
    archive[end + 16:end + 20] = offset.to_bytes(4, "little")
    refused(cli, _dotlottie(tmp_path, bytes(archive)), "anim.lottie", "archive member", "negative seek value")


def test_an_image_path_that_is_a_folder_is_named_as_a_folder(tmp_path):
    from fluidymation.errors import InputError
    from fluidymation.stages.files import read_image

    with pytest.raises(InputError, match="a folder, not an image file"):
        read_image(tmp_path)


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_a_float_image_with_non_finite_values_is_refused_naming_it(tmp_path, value):
    """A float TIFF under a PNG name (imageio reads it by its content through Pillow)."""
    from PIL import Image

    from fluidymation.errors import InputError
    from fluidymation.stages.files import read_image

    values = np.full((4, 4), 0.5, np.float32)
    values[1, 2] = value
    Image.fromarray(values, mode="F").save(tmp_path / "seg.png", format="TIFF")
    with pytest.raises(InputError, match="seg.png: the image holds values that are not finite"):
        read_image(tmp_path / "seg.png", channels=4)


def test_a_float_image_beyond_one_is_clipped(tmp_path):
    from PIL import Image

    from fluidymation.stages.files import read_image

    Image.fromarray(np.array([[2.0, -1.0]], np.float32), mode="F").save(tmp_path / "bright.png", format="TIFF")
    assert read_image(tmp_path / "bright.png").ravel().tolist() == [1.0, 0.0]
