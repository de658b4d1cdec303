"""Write the Lottie fixtures of tests/stages/test_lottie_player.py (one per feature; README.md gives the geometry).

Plain Python, deterministic (fixed zip timestamps, PNG written by hand), so re-running it
gives byte-identical files.  Run:  python tests/data/lottie/make_player_fixtures.py
"""

import json
import struct
import zipfile
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def static(value):
    return {"a": 0, "k": value}


def linear(*keys):
    """Linear keyframes from (frame, value) pairs; the last holds."""
    frames = [{"t": t, "s": v if isinstance(v, list) else [v], "i": {"x": [1], "y": [1]}, "o": {"x": [0], "y": [0]}}
              for t, v in keys[:-1]]
    last_t, last_v = keys[-1]
    return {"a": 1, "k": frames + [{"t": last_t, "s": last_v if isinstance(last_v, list) else [last_v]}]}


def transform(position=(0, 0), **extra):
    return {"o": static(100), "r": static(0), "p": static([*position, 0]), "a": static([0, 0, 0]),
            "s": static([100, 100, 100]), **extra}


def group(name, *items):
    return {"ty": "gr", "nm": name, "it": [*items, {"ty": "tr", "p": static([0, 0]), "a": static([0, 0]),
                                                   "s": static([100, 100]), "r": static(0), "o": static(100)}]}


def rect(centre, size, name="rect"):
    return {"ty": "rc", "nm": name, "d": 1, "p": static(list(centre)), "s": static(list(size)), "r": static(0)}


def ellipse(centre, diameter, name="ellipse"):
    return {"ty": "el", "nm": name, "d": 1, "p": static(list(centre)), "s": static([diameter, diameter])}


def fill(rgb=(0.2, 0.5, 0.8), name="fill"):
    return {"ty": "fl", "nm": name, "c": static([*rgb, 1]), "o": static(100), "r": 1}


def path(points, closed=True, name="path"):
    zeros = [[0, 0] for _ in points]
    return {"c": closed, "v": [list(p) for p in points], "i": zeros, "o": zeros, "nm": name}


def shape_layer(index, name, shapes, position=(0, 0), **extra):
    return {"ddd": 0, "ind": index, "ty": 4, "nm": name, "sr": 1, "ao": 0, "bm": 0, "ip": 0, "op": 1000, "st": 0,
            "ks": transform(position), "shapes": shapes, **extra}


def animation(name, layers, *, size=(96, 96), fr=12, op=12, **extra):
    return {"v": "5.7.0", "nm": name, "fr": fr, "ip": 0, "op": op, "w": size[0], "h": size[1], "ddd": 0,
            "assets": [], "layers": layers, **extra}


def mask(points, mode, name):
    return {"nm": name, "mode": mode, "inv": False, "pt": static(path(points)), "o": static(100), "x": static(0)}


def square(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


FIXTURES = {
    # a 64x64 square minus a subtracted 32x32 centre: a ring of 3072 px
    "mask_subtract.json": animation("mask subtract", [
        shape_layer(1, "ring", [group("square", rect((48, 48), (64, 64)), fill())],
                    masksProperties=[mask(square(32, 32, 64, 64), "s", "hole")])]),
    # two groups, one hidden; a hidden layer
    "hidden.json": animation("hidden", [
        shape_layer(1, "hidden layer", [group("everything", rect((48, 48), (96, 96)), fill())], hd=True),
        shape_layer(2, "shapes", [group("shown", rect((24, 48), (16, 16)), fill()),
                                  {**group("not shown", rect((72, 48), (16, 16)), fill()), "hd": True}])]),
    # a horizontal line 64 px long, 8 px wide, dashed 8 on, 8 off: four dashes
    "dashes.json": animation("dashes", [
        shape_layer(1, "dashed", [group("line", {"ty": "sh", "nm": "line", "ks": static(path([(16, 48), (80, 48)],
                                                                                            closed=False))},
                                        {"ty": "st", "nm": "stroke", "c": static([0, 0, 0, 1]), "o": static(100),
                                         "w": static(8), "lc": 1, "lj": 1, "ml": 4,
                                         "d": [{"n": "d", "nm": "dash", "v": static(8)},
                                               {"n": "g", "nm": "gap", "v": static(8)},
                                               {"n": "o", "nm": "offset", "v": static(0)}]})])]),
    # a precomp whose child moves 4 px a frame, time-remapped to hold its frame 3 (0.25 s)
    "time_remap.json": animation("time remap", [
        {"ddd": 0, "ind": 1, "ty": 0, "nm": "held", "refId": "moving", "sr": 1, "ao": 0, "bm": 0, "ip": 0, "op": 12,
         "st": 0, "w": 96, "h": 96, "ks": transform(), "tm": static(0.25)}],
        assets=[{"id": "moving", "nm": "moving comp", "layers": [
            {**shape_layer(1, "block", [group("block", rect((0, 0), (16, 16)), fill())]),
             "ks": transform(p=linear((0, [16, 48, 0]), (12, [64, 48, 0])))}]}]),
    # 30 fps: a disc of diameter 16 moving right 2 px a frame, from centre x 16 at frame 0 (a disc, not a square:
    # ThorVG draws an axis-aligned rectangle snapped to whole pixels)
    "motion_30fps.json": animation("motion 30 fps", [
        {**shape_layer(1, "mover", [group("disc", ellipse((0, 0), 16), fill())]),
         "ks": transform(p=linear((0, [16, 48, 0]), (30, [76, 48, 0])))}], fr=30, op=30),
    # rotation by an expression: 180 degrees a second about the bar's centre
    "expression.json": animation("expression", [
        {**shape_layer(1, "spinner", [group("bar", rect((0, 0), (64, 8)), fill())]),
         "ks": transform((48, 48), r={"a": 0, "k": 0, "x": "var $bm_rt;\n$bm_rt = time * 180;"})}]),
    # text drawn with the file's glyphs: "II" in a font whose "I" is a 10x70 bar, advance 40, at size 50
    "text.json": animation("text", [
        {"ddd": 0, "ind": 1, "ty": 5, "nm": "label", "sr": 1, "ao": 0, "bm": 0, "ip": 0, "op": 12, "st": 0,
         "ks": transform((20, 70)),
         "t": {"d": {"k": [{"s": {"s": 50, "f": "TestSans-Regular", "t": "II", "j": 0, "tr": 0, "lh": 60, "ls": 0,
                                  "fc": [0, 0, 0]}, "t": 0}]},
               "p": {}, "m": {"g": 1, "a": static([0, 0])}, "a": []}}],
        fonts={"list": [{"fName": "TestSans-Regular", "fFamily": "Test Sans", "fStyle": "Regular", "ascent": 70}]},
        chars=[{"ch": "I", "size": 50, "style": "Regular", "w": 40, "fFamily": "Test Sans",
                "data": {"shapes": [{"ty": "gr", "nm": "I", "it": [
                    {"ty": "sh", "nm": "I", "ks": static(path(square(0, -70, 10, 0)))}]}]}}]),
    # an image layer whose asset is images/dot.png beside the file (a 32x32 opaque square)
    "image_beside/anim.json": animation("image beside", [
        {"ddd": 0, "ind": 1, "ty": 2, "nm": "picture", "refId": "dot", "sr": 1, "ao": 0, "bm": 0, "ip": 0, "op": 12,
         "st": 0, "ks": transform((16, 40))}],
        assets=[{"id": "dot", "w": 32, "h": 32, "u": "images/", "p": "dot.png", "e": 0}]),
}

# the two animations of two_animations.lottie: "first" (listed first) and "second"
FIRST = animation("first", [shape_layer(1, "first square", [group("square", rect((24, 24), (16, 16)), fill())])])
SECOND = animation("second", [shape_layer(1, "second square", [group("square", rect((72, 72), (16, 16)), fill())])])


# themed.lottie (dotLottie 2 layout): a square whose position and colour are slots; its initial theme "moved"
# sets them (and holds an image rule, which is not applied)
THEMED = animation("themed", [shape_layer(1, "square", [group(
    "square", {**rect((24, 24), (16, 16)), "p": {"a": 0, "k": [24, 24], "sid": "squarePosition"}},
    {**fill(), "c": {"a": 0, "k": [0.2, 0.5, 0.8, 1], "sid": "squareColour"}})])])
MOVED = {"rules": [{"id": "squarePosition", "type": "Position", "value": [72, 72]},
                   {"id": "squareColour", "type": "Color", "value": [0.9, 0.1, 0.1, 1]},
                   {"id": "logo", "type": "Image", "value": {"id": "img", "width": 8, "height": 8}}]}
#: its second theme "recoloured" sets only the colour
RECOLOURED = {"rules": [{"id": "squareColour", "type": "Color", "value": [0.1, 0.8, 0.1, 1]}]}


def png(width, height, rgba):
    """A PNG of one colour, written by hand so the bytes never depend on an image library's version."""
    raw = b"".join(b"\x00" + bytes(rgba) * width for _ in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def write_dotlottie(target, animations):
    manifest = {"version": "1", "generator": "make_player_fixtures.py",
                "animations": [{"id": name, "speed": 1, "loop": True} for name, _ in animations]}
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, content in [("manifest.json", manifest)] + [(f"animations/{n}.json", a) for n, a in animations]:
            info = zipfile.ZipInfo(name, date_time=ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, json.dumps(content, separators=(",", ":")))


def write_dotlottie_v2(target, name, data, themes):
    manifest = {"version": "2", "generator": "make_player_fixtures.py",
                "animations": [{"id": name, "initialTheme": next(iter(themes))}],
                "themes": [{"id": theme} for theme in themes]}
    members = [("manifest.json", manifest), (f"a/{name}.json", data)] + [(f"t/{t}.json", r) for t, r in themes.items()]
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        for member, content in members:
            info = zipfile.ZipInfo(member, date_time=ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, json.dumps(content, separators=(",", ":")))


def main():
    for name, data in FIXTURES.items():
        target = HERE / name
        target.parent.mkdir(exist_ok=True)
        target.write_text(json.dumps(data, indent=1) + "\n")
    (HERE / "image_beside" / "images").mkdir(exist_ok=True)
    (HERE / "image_beside" / "images" / "dot.png").write_bytes(png(32, 32, (200, 40, 40, 255)))
    write_dotlottie(HERE / "two_animations.lottie", [("first", FIRST), ("second", SECOND)])
    write_dotlottie_v2(HERE / "themed.lottie", "themed", THEMED, {"moved": MOVED, "recoloured": RECOLOURED})


if __name__ == "__main__":
    main()
