"""Mutators of the raster inputs: recorded exemplars (images, videos, mask folders) read by ``render --until
stylize``, and flow files (``.flo``, ``.npy``) read by ``guides --flow`` and ``exemplar show``.

Seeds: examples/map's crayon painting and segments and tests/data/paper.png, made 24² px; a tiny MP4 of the
crayon frames written by the project's encoder; a rotation flow written by the project's ``.flo`` and ``.npy``
writers.
"""

from __future__ import annotations

import functools
import io
import pickle
import random
import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np
import yaml
from PIL import Image

from tests.fuzz.harness import ROOT, Case, mutate_tree, truncate
from tests.fuzz.packed import flip_bytes

SIDE = 24
QUICK = {"opt_iters": "1", "pm_iters": 1}


def _png(image: Image.Image, **options) -> bytes:
    buffer = io.BytesIO()
    image.save(buffer, format=options.pop("format", "PNG"), **options)
    return buffer.getvalue()


@functools.cache
def exemplar_seeds() -> dict[str, object]:
    """Three 24² frames of the crayon painting (turned a little), its segments, the paper, an MP4 of the frames."""
    from fluidymation.stages.encode import Params, encode_mp4

    crayon = Image.open(ROOT / "examples/map/style/crayon.png").convert("RGB").resize((SIDE, SIDE))
    frames = [crayon.rotate(8 * k, fillcolor=(244, 239, 228)) for k in range(3)]
    segments = Image.open(ROOT / "examples/map/style/crayon-segments.png").convert("RGB").resize(
        (SIDE, SIDE), Image.NEAREST)
    with tempfile.TemporaryDirectory(prefix="fuzz-seed-") as folder:
        video = Path(folder) / "rec.mp4"
        encode_mp4([np.asarray(frame) for frame in frames], video, params=Params(fps=12))
        mp4 = video.read_bytes()
    return {"frames": [_png(frame) for frame in frames], "segments": _png(segments), "mp4": mp4,
            "paper": _png(Image.open(ROOT / "tests/data/paper.png").resize((SIDE, SIDE)))}


LARGE = 12000  # px a side: under PIL's decompression-bomb limit, over a gigabyte once read as float RGB


@functools.cache
def large_png() -> bytes:
    """A grey PNG of :data:`LARGE`² px (about 150 KiB)."""
    return _png(Image.new("L", (LARGE, LARGE), 128), compress_level=9)


def _fixed_crc(png: bytearray) -> bytearray:
    png[29:33] = struct.pack(">L", zlib.crc32(bytes(png[12:29])))
    return png


def mutate_image(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    """An image file's bytes broken or re-encoded: truncated, flipped, huge or zero header dimensions, 1x1,
    16-bit, palette, grey(+alpha), JPEG under a PNG name, float TIFF with NaN, 12000² px."""
    try:
        return _reencoded(rng, data)
    except Exception:  # broken by an earlier mutation, or a mode PIL cannot re-encode (PIL raises many kinds)
        return flip_bytes(rng, data), "bytes flipped"


def _reencoded(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    image = Image.open(io.BytesIO(data))
    image.load()
    choice = rng.randrange(12)
    if choice == 0:
        return truncate(rng, data), "truncated"
    if choice == 1:
        return flip_bytes(rng, data), "bytes flipped"
    if choice == 2:
        width, height = rng.choice([(100000, 100000), (2**31 - 1, 1), (0, 0), (1, 2**31 - 1), (65536, 65536)])
        png = bytearray(data)
        png[16:24] = struct.pack(">LL", width, height)
        return bytes(_fixed_crc(png) if rng.random() < 0.7 else png), f"header says {width}x{height}"
    if choice == 3:
        return _png(image.resize((1, 1))), "1x1"
    if choice == 4:
        grey = np.asarray(image.convert("L"), dtype=np.uint16) * 257
        return _png(Image.fromarray(grey)), "16-bit grey"
    if choice == 5:
        return _png(image.convert("P", palette=Image.ADAPTIVE, colors=rng.choice([2, 16, 256]))), "palette"
    if choice == 6:
        return _png(image.convert(rng.choice(["LA", "L", "RGBA", "1"]))), "other mode"
    if choice == 7:
        return _png(image.convert("RGB"), format="JPEG", quality=rng.choice([1, 90])), "JPEG bytes"
    if choice == 8:
        values = np.asarray(image.convert("L"), dtype=np.float32) / 255
        values.flat[rng.randrange(values.size)] = rng.choice([np.nan, np.inf, -np.inf, 1e30])
        return _png(Image.fromarray(values, mode="F"), format="TIFF"), "float TIFF"
    if choice == 9:
        return _png(image.resize(rng.choice([(SIDE + 1, SIDE), (SIDE, 1), (1, SIDE), (200, 3)]))), "other size"
    if choice == 10:
        return rng.choice([(b"", "empty file"), (large_png(), f"{LARGE}x{LARGE} px")])
    return _png(image, format="GIF", save_all=True, append_images=[image.rotate(30)]), "animated GIF"


def _exemplar_scene(entry: dict, stylizer: str | None = None) -> bytes:
    layer = {"name": "blob", "select": ["blob"], "exemplar": "rec", "params": dict(QUICK)}
    if stylizer:
        layer["stylizer"] = stylizer
    return yaml.safe_dump({"version": 1, "input": str(ROOT / "examples/blob/blob.svg"), "size": [32, 32],
                           "frames": {"start": 0, "end": 1}, "output": {"dir": "out"},
                           "background": {"type": "solid", "color": "#f4efe4"},
                           "exemplars": {"rec": entry}, "layers": [layer]}).encode()


def exemplar_case(rng: random.Random, seeds=None) -> Case:
    seeds = seeds or exemplar_seeds()
    kind = rng.choice(["images", "images", "images", "image", "video"])
    files: dict[str, bytes] = {}
    stylizer = None
    if kind == "images":
        for k, frame in enumerate(seeds["frames"]):
            files[f"rec/{k:02d}.png"] = frame
        entry = {"images": rng.choice(["rec/%02d.png", "rec", "rec/*.png"]), "mask": "full"}
        if rng.random() < 0.4:
            for k, frame in enumerate(seeds["frames"]):
                files[f"masks/{k:02d}.png"] = _png(Image.open(io.BytesIO(frame)).convert("L").point(
                    lambda v: 255 * (v < 200)))
            entry["mask"] = rng.choice(["masks/%02d.png", "masks", "masks/*.png"])
    elif kind == "image":
        files["still.png"] = seeds["frames"][0]
        entry = {"image": "still.png"}
        if rng.random() < 0.5:
            files["segments.png"] = seeds["segments"]
            entry["segments"] = "segments.png"
            stylizer = "still"
        else:
            entry["mask"] = "full"
    else:
        files["rec.mp4"] = seeds["mp4"]
        entry = {"video": "rec.mp4", "mask": rng.choice(["full", "auto"])}
    what = []
    for _ in range(rng.choice([1, 1, 2])):
        name = rng.choice(sorted(files))
        action = rng.random()
        if name.endswith(".mp4"):
            files[name], how = rng.choice([(truncate(rng, files[name]), "truncated"),
                                           (flip_bytes(rng, files[name], 40), "bytes flipped"),
                                           (files[name][:64], "header only"), (b"", "empty"),
                                           (seeds["frames"][0], "a PNG")])
        elif action < 0.75:
            files[name], how = mutate_image(rng, files[name])
        elif action < 0.85 and name.startswith(("rec/", "masks/")):
            del files[name]
            how = "removed"
        elif action < 0.92 and name.startswith(("rec/", "masks/")):
            files[name.replace(".png", "1.png")] = seeds["paper"]
            how = "one more"
        else:
            entry = mutate_tree(rng, entry)
            how = "entry mutated"
        what.append(f"{name}: {how}")
    files["scene.yaml"] = _exemplar_scene(entry, stylizer)
    names = tuple(str(value) for value in (entry.values() if isinstance(entry, dict) else ()) if isinstance(value, str))
    return Case("exemplar", f"{kind}: {', '.join(what)}", files,
                ["-q", "render", "{scene}", "--until", "stylize"], None, ("rec", "masks", *names))


# ---------------------------------------------------------------------------------------------- flows

FLOW_SIDE = 32


def _rotation(side: int) -> np.ndarray:
    yy, xx = np.mgrid[:side, :side].astype(np.float32) - side / 2
    return np.stack([-yy, xx], axis=-1) * np.float32(0.05)


def _npy(array: np.ndarray, allow_pickle: bool = False) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=allow_pickle)
    return buffer.getvalue()


@functools.cache
def flow_seeds() -> dict[str, bytes]:
    """A rotation flow (32² px) as ``.flo`` (written by stages.flow_io.write_flo) and ``.npy``, and the exemplar
    frames for an ``exemplar show`` folder."""
    from fluidymation.stages.flow_io import write_flo

    flow = _rotation(FLOW_SIDE)
    with tempfile.TemporaryDirectory(prefix="fuzz-seed-") as folder:
        write_flo(Path(folder) / "f.flo", flow)
        flo = (Path(folder) / "f.flo").read_bytes()
    return {"flo": flo, "npy": _npy(flow), "small_npy": _npy(_rotation(SIDE)), "frames": exemplar_seeds()["frames"]}


def mutate_flo(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    choice = rng.randrange(7)
    if choice == 0:
        width, height = rng.choice([(2**31 - 1, 2**31 - 1), (-1, 32), (0, 0), (31, 32), (64, 16), (2**16, 2**16)])
        return data[:4] + struct.pack("<ii", width, height) + data[12:], f"header says {width}x{height}"
    if choice == 1:
        return truncate(rng, data), "truncated"
    if choice == 2:
        return data + bytes(rng.choice([1, 8, 4096])), "extra bytes"
    if choice == 3:
        return rng.choice([b"PIEX", b"\x00\x00\x00\x00", b"IEHP"]) + data[4:], "wrong tag"
    if choice == 4:
        values = bytearray(data)
        for _ in range(rng.randint(1, 20)):
            at = 12 + 4 * rng.randrange((len(data) - 12) // 4)
            values[at:at + 4] = struct.pack("<f", rng.choice([np.nan, np.inf, -np.inf, 1e10, 3e38, -0.0]))
        return bytes(values), "odd values"
    if choice == 5:
        return flip_bytes(rng, data), "bytes flipped"
    return b"", "empty file"


def mutate_npy(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    """A ``.npy`` flow with another dtype, shape or header, a pickle inside, NaN or inf values."""
    flow = np.load(io.BytesIO(data))
    choice = rng.randrange(10)
    if choice == 0:
        dtype = rng.choice(["<i4", "<f2", ">f4", "<f8", "<c8", "?", "<u1", "<m8[s]", "S4"])
        return _npy(flow.astype(dtype)), f"dtype {dtype}"
    if choice == 1:
        return _npy(np.array([print, {"a": 1}], dtype=object), allow_pickle=True), "object array (pickle)"
    if choice == 2:
        return pickle.dumps([print, flow[:2]]), "a pickle, not .npy"
    if choice == 3:
        shapes = [flow[..., :1], flow[..., 0], np.concatenate([flow, flow[..., :1]], -1), flow[None], flow[:0],
                  flow.transpose(2, 0, 1), flow.reshape(-1), np.float32(1.0), flow[:, :, :, None]]
        picked = rng.choice(shapes)
        return _npy(np.asarray(picked)), f"shape {np.shape(picked)}"
    if choice == 4:
        header_end = data.index(b"\n") + 1
        header = data[10:header_end].decode("latin1")
        shape = rng.choice(["(100000, 100000, 2)", "(2147483647, 2147483647, 2)", "(-1, 32, 2)", "(32,)", "()"])
        header = header.replace(f"({flow.shape[0]}, {flow.shape[1]}, 2)", shape)
        encoded = header.encode("latin1")
        return data[:8] + struct.pack("<H", len(encoded)) + encoded + data[header_end:], f"header shape {shape}"
    if choice == 5:
        values = flow.copy()
        values.flat[rng.randrange(values.size)] = rng.choice([np.nan, np.inf, -np.inf, 1e38])
        return _npy(values), "NaN or inf"
    if choice == 6:
        return rng.choice([data[:6] + b"\x09\x00" + data[8:], data[:8] + b"\xff\xff" + data[10:],
                           b"\x93NUMPX" + data[6:]]), "header broken"
    if choice == 7:
        buffer = io.BytesIO()
        np.savez(buffer, flow=flow)
        return buffer.getvalue(), "an .npz"
    if choice == 8:
        return _npy(np.asfortranarray(flow.transpose(1, 0, 2))), "Fortran order"
    return truncate(rng, data), "truncated"


def _flow_scene() -> bytes:
    return yaml.safe_dump({"version": 1, "input": str(ROOT / "examples/blob/blob.svg"), "size": [FLOW_SIDE] * 2,
                           "frames": {"start": 0, "end": 2}, "output": {"dir": "out"},
                           "layers": [{"name": "blob", "select": ["blob"]}]}).encode()


def flow_case(rng: random.Random, seeds=None) -> Case:
    seeds = seeds or flow_seeds()
    if rng.random() < 0.3:
        return _show_case(rng, seeds)
    suffix = rng.choice(["flo", "npy"])
    files = {f"flow/{k:05d}.{suffix}": seeds[suffix] for k in range(2)}
    what = []
    for _ in range(rng.choice([1, 1, 2])):
        name = rng.choice(sorted(files))
        if rng.random() < 0.1:
            del files[name]
            what.append(f"{name}: removed")
            continue
        files[name], how = (mutate_flo if suffix == "flo" else mutate_npy)(rng, seeds[suffix])
        what.append(f"{name}: {how}")
    files["scene.yaml"] = _flow_scene()
    pattern = f"flow/%05d.{suffix}"
    return Case("flow", f"guides --flow: {', '.join(what)}", files,
                ["-q", "guides", "{scene}", "--layer", "blob", "--flow", pattern], None, (pattern,))


def _show_case(rng: random.Random, seeds: dict) -> Case:
    """An ``exemplar show`` folder (rgb/, mask/, flow/) with a flow or a frame broken."""
    files = {}
    for k, frame in enumerate(seeds["frames"]):
        files[f"ex/rgb/{k:05d}.png"] = frame
        files[f"ex/mask/{k:05d}.png"] = _png(Image.open(io.BytesIO(frame)).convert("L"))
        files[f"ex/flow/{k:05d}.npy"] = seeds["small_npy"]
    name = rng.choice(sorted(files))
    if name.endswith(".npy"):
        files[name], how = mutate_npy(rng, files[name])
    elif rng.random() < 0.2:
        del files[name]
        how = "removed"
    else:
        files[name], how = mutate_image(rng, files[name])
    return Case("flow", f"exemplar show: {name}: {how}", files,
                ["-q", "exemplar", "show", "{case}/ex", "-o", "{case}/sheet.png"], None, ("ex",))
