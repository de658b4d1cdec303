"""Mutators of the packed and multi-file vector inputs: dotLottie archives, Telegram ``.tgs`` stickers and numbered
SVG sequences, seeded from tests/data/lottie and examples/squiggle/frames."""

from __future__ import annotations

import functools
import gzip
import io
import json
import random
import struct
import xml.etree.ElementTree as ET
import zipfile
import zlib

from tests.fuzz.harness import (ROOT, Case, _mutate_svg_tree, deepen, lottie_seeds, mutate_tree, small_scene,
                                truncate)

LOTTIE_DATA = ROOT / "tests/data/lottie"
DOT_PNG = LOTTIE_DATA / "image_beside/images/dot.png"
BOMB_BYTES = 200 * 2**20  # what a bomb unpacks to: past the readers' 64 MiB limit


def dotlottie_seeds() -> list[tuple[str, bytes]]:
    return [(path.name, path.read_bytes()) for path in sorted(LOTTIE_DATA.glob("*.lottie"))]


def tgs_seeds() -> list[tuple[str, bytes]]:
    """parenting.tgs and the gzip of each Lottie JSON seed."""
    packed = [(f"{name}.tgs", gzip.compress(data, mtime=0)) for name, data in lottie_seeds()]
    return [("parenting.tgs", (LOTTIE_DATA / "parenting.tgs").read_bytes()), *packed]


def svgseq_seeds() -> list[tuple[str, list[bytes]]]:
    """The squiggle example's frames, and the animated SVG fixtures' first five as a sequence of stills."""
    squiggle = [path.read_bytes() for path in sorted((ROOT / "examples/squiggle/frames").glob("*.svg"))]
    fixtures = [path.read_bytes() for path in sorted((ROOT / "tests/data/svg_animated").glob("*.svg"))[:5]]
    return [("squiggle", squiggle), ("svg_animated", fixtures)]


# ---------------------------------------------------------------------------------------------- bytes


def flip_bytes(rng: random.Random, data: bytes, count: int | None = None) -> bytes:
    """``data`` with a few bytes replaced at random."""
    data = bytearray(data)
    for _ in range(count or rng.randint(1, 8)):
        if data:
            data[rng.randrange(len(data))] = rng.randrange(256)
    return bytes(data)


@functools.cache
def deflated_zeros() -> bytes:
    """:data:`BOMB_BYTES` zero bytes, raw-deflated (about 200 KiB)."""
    packer = zlib.compressobj(9, zlib.DEFLATED, -15)
    chunk = bytes(2**20)
    return b"".join(packer.compress(chunk) for _ in range(BOMB_BYTES // 2**20)) + packer.flush()


@functools.cache
def gzip_bomb() -> bytes:
    """A gzip stream of :data:`BOMB_BYTES` bytes: a JSON list of spaces."""
    packer = zlib.compressobj(9, zlib.DEFLATED, 31)
    chunk = b" " * 2**20
    return packer.compress(b"[") + b"".join(packer.compress(chunk) for _ in range(BOMB_BYTES // 2**20)) + \
        packer.compress(b"]") + packer.flush()


# ---------------------------------------------------------------------------------------------- dotLottie


def _members(data: bytes) -> dict[str, bytes]:
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        return {info.filename: archive.read(info) for info in archive.infolist()}


def _zip(members: dict[str, bytes], method: int = zipfile.ZIP_DEFLATED) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", method) as archive:
        for name, data in members.items():
            archive.writestr(zipfile.ZipInfo(name, (1980, 1, 1, 0, 0, 0)), data, compress_type=method)
    return buffer.getvalue()


def _bomb_zip(name: str, declared: int | None = None) -> bytes:
    """A zip whose member ``name`` inflates to :data:`BOMB_BYTES` zeros; its headers say ``declared`` bytes
    (default the truth)."""
    body = deflated_zeros()
    size = BOMB_BYTES if declared is None else declared
    crc = _zeros_crc()
    encoded = name.encode()
    local = struct.pack("<4s5H3L2H", b"PK\x03\x04", 20, 0, 8, 0, 33, crc, len(body), size, len(encoded), 0)
    central = struct.pack("<4s6H3L5H2L", b"PK\x01\x02", 20, 20, 0, 8, 0, 33, crc, len(body), size, len(encoded),
                          0, 0, 0, 0, 0, 0)
    end = struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, 1, 1, len(central) + len(encoded),
                      len(local) + len(encoded) + len(body), 0)
    return local + encoded + body + central + encoded + end


@functools.cache
def _zeros_crc() -> int:
    crc, chunk = 0, bytes(2**20)
    for _ in range(BOMB_BYTES // 2**20):
        crc = zlib.crc32(chunk, crc)
    return crc


def _with_declared_size(data: bytes, size: int) -> bytes:
    """``data`` (a zip) with every member's uncompressed size in the central directory set to ``size``."""
    data = bytearray(data)
    position = data.find(b"PK\x01\x02")
    while position >= 0:
        data[position + 24:position + 28] = struct.pack("<L", size & 0xFFFFFFFF)
        position = data.find(b"PK\x01\x02", position + 4)
    return bytes(data)


def _image_asset(reference: str) -> dict:
    return {"id": "img", "w": 8, "h": 8, "u": "", "p": reference, "e": 0}


def _dotlottie_json_mutation(rng: random.Random, members: dict[str, bytes]) -> tuple[dict[str, bytes], str]:
    name = rng.choice([n for n in members if n.endswith(".json")])
    tree = mutate_tree(rng, json.loads(members[name]), deep=True)
    try:
        members[name] = deepen(rng, json.dumps(tree, allow_nan=True)).encode()
    except (RecursionError, ValueError):
        pass
    return members, f"{name} tree mutation"


def _dotlottie_member_mutation(rng: random.Random, members: dict[str, bytes]) -> tuple[dict[str, bytes], str]:
    """A member renamed or added with a name that leaves the archive, an image asset, a duplicate, a folder."""
    animations = [n for n in members if n.startswith(("a/", "animations/"))]
    target = rng.choice(animations)
    action = rng.randrange(6)
    if action == 0:
        bad = rng.choice(["../secret.json", "/etc/hostname", "animations/../../secret.json", "C:\\x.json",
                          "a/..\\..\\x.json", "animations/\u0000.json", "animations/" + "x" * 300 + ".json"])
        members[bad] = members[target]
        return members, f"member named {bad[:40]!r}"
    if action == 1:
        members[target.split("/")[0] + "/"] = b""
        return members, "folder member"
    data = json.loads(members[target])
    reference = rng.choice(["images/dot.png", "i/dot.png", "dot.png", "../secret.png", "/etc/hostname",
                            "http://example.invalid/x.png", "i/missing.png", "data:image/png;base64,!!"])
    data.setdefault("assets", []).append(_image_asset(reference))
    members[target] = json.dumps(data).encode()
    if action < 5:
        members[rng.choice(["images/dot.png", "i/dot.png", "i/../../secret.png"])] = \
            rng.choice([DOT_PNG.read_bytes(), truncate(rng, DOT_PNG.read_bytes()), b""])
    return members, f"image asset {reference!r}"


def dotlottie_case(rng: random.Random, seeds=None, masks: bool = False) -> Case:
    seeds = seeds or dotlottie_seeds()
    name, data = rng.choice(seeds)
    members = _members(data)
    kind = rng.random()
    if kind < 0.45:
        members, what = _dotlottie_json_mutation(rng, members)
        packed = _zip(members, rng.choice([zipfile.ZIP_DEFLATED, zipfile.ZIP_STORED, zipfile.ZIP_BZIP2,
                                           zipfile.ZIP_LZMA]))
    elif kind < 0.65:
        members, what = _dotlottie_member_mutation(rng, members)
        packed = _zip(members)
    elif kind < 0.8:
        packed, what = rng.choice([(truncate(rng, data), "truncated"), (flip_bytes(rng, data), "bytes flipped"),
                                   (data[:30] + flip_bytes(rng, data[30:], 40), "many bytes flipped"),
                                   (b"PK\x05\x06" + bytes(18), "empty archive"), (b"", "empty file"),
                                   (data + data, "archive twice"), (json.dumps({}).encode(), "JSON, not a zip")])
    else:
        member = rng.choice([n for n in members if n.endswith(".json")])
        packed, what = rng.choice([
            (_bomb_zip(member), f"{member} inflates to 200 MiB"),
            (_bomb_zip(member, declared=rng.choice([0, 10, 2**32 - 1])), f"{member} lies about its size"),
            (_with_declared_size(data, rng.choice([2**32 - 1, 2**31, 0])), "declared sizes changed"),
            (_encrypted(data), "members marked encrypted"),
            (_method(data, rng.choice([1, 6, 9, 97, 99])), "unknown compression method")])
    scene = {"animation": rng.choice(["first", "second", "themed", "../x", ""])} if rng.random() < 0.15 else {}
    if rng.random() < 0.1:
        scene["theme"] = rng.choice(["moved", "recoloured", "../../secret", "nope"])
    argv = ["-q", "masks", "{scene}", "--frames", "0:1"] if masks else ["-q", "check", "{scene}"]
    return Case("dotlottie", f"{name}: {what}", {"anim.lottie": packed, "scene.yaml": small_scene("anim.lottie", scene)},
                argv, "anim.lottie")


def _encrypted(data: bytes) -> bytes:
    """``data`` (a zip) with the encryption flag set on every member."""
    data = bytearray(data)
    for tag, offset in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        position = data.find(tag)
        while position >= 0:
            data[position + offset] |= 1
            position = data.find(tag, position + 4)
    return bytes(data)


def _method(data: bytes, method: int) -> bytes:
    """``data`` (a zip) with every member's compression method set to ``method``."""
    data = bytearray(data)
    for tag, offset in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
        position = data.find(tag)
        while position >= 0:
            data[position + offset:position + offset + 2] = struct.pack("<H", method)
            position = data.find(tag, position + 4)
    return bytes(data)


# ---------------------------------------------------------------------------------------------- tgs


def tgs_case(rng: random.Random, seeds=None, masks: bool = False) -> Case:
    seeds = seeds or tgs_seeds()
    name, data = rng.choice(seeds)
    kind = rng.random()
    if kind < 0.6:
        tree = mutate_tree(rng, json.loads(gzip.decompress(data)), deep=True)
        try:
            text = deepen(rng, json.dumps(tree, allow_nan=True)).encode()
        except (RecursionError, ValueError):
            text = gzip.decompress(data)
        packed, what = gzip.compress(text, mtime=0), "tree mutation"
    else:
        text = gzip.decompress(data)
        packed, what = rng.choice([
            (truncate(rng, data), "truncated"), (flip_bytes(rng, data), "bytes flipped"),
            (data[:-8] + flip_bytes(rng, data[-8:], 2), "trailer flipped"), (data + data, "two members"),
            (data + b"garbage", "trailing garbage"), (text, "not gzipped"), (b"", "empty file"),
            (gzip.compress(b"", mtime=0), "empty stream"), (gzip.compress(b"\xff\xfe" + text, mtime=0), "not UTF-8"),
            (gzip_bomb(), "inflates to 200 MiB"),
            (gzip.compress(b"[" * 100000 + b"]" * 100000, mtime=0), "nested 100000 deep"),
            (gzip.compress(truncate(rng, text), mtime=0), "truncated JSON")])
    argv = ["-q", "masks", "{scene}", "--frames", "0:1"] if masks else ["-q", "check", "{scene}"]
    return Case("tgs", f"{name}: {what}", {"anim.tgs": packed, "scene.yaml": small_scene("anim.tgs")}, argv,
                "anim.tgs")


# ---------------------------------------------------------------------------------------------- SVG sequences


def _parsed(data: bytes) -> ET.Element | None:
    try:
        return ET.fromstring(data)
    except ET.ParseError:
        return None  # a frame broken by an earlier mutation


def svgseq_case(rng: random.Random, seeds=None, masks: bool = False) -> Case:
    seeds = seeds or svgseq_seeds()
    name, frames = rng.choice(seeds)
    frames = list(frames)
    what = []
    for _ in range(rng.choice([1, 1, 2])):
        index = rng.choice([k for k, data in enumerate(frames) if data is not None])
        action = rng.random()
        if action < 0.55 and (root := _parsed(frames[index])) is not None:
            what.append(f"frame {index}: {_mutate_svg_tree(rng, root)}")
            frames[index] = ET.tostring(root)
        elif action < 0.75:
            frames[index] = rng.choice([truncate(rng, frames[index]), b"", b"\x89PNG\r\n\x1a\n",
                                        frames[index].replace(b"<svg", b"<!DOCTYPE svg [<!ENTITY x 'y'>]><svg", 1)])
            what.append(f"frame {index}: text mutation")
        elif action < 0.9:
            frames[index] = rng.choice(seeds)[1][0]
            what.append(f"frame {index}: from the other sequence")
        else:
            frames[index] = None
            what.append(f"frame {index}: missing")
    files = {f"frames/{k:04d}.svg": data for k, data in enumerate(frames) if data is not None}
    pattern = rng.choice(["frames/%04d.svg"] * 6 + ["frames/*.svg", "frames/%d.svg", "frames/%08d.svg",
                                                    "frames/%04d.svg/", "../frames/%04d.svg", "frames/[.svg"])
    if rng.random() < 0.1:
        files["frames/0001.svg.bak"] = b"not svg"
        files[f"frames/{len(frames) + 7:04d}.svg"] = frames[0] or b""
    extra = {"frames": {"start": 0, "end": len(frames)}} if rng.random() < 0.7 else {}
    if rng.random() < 0.15:
        extra["fps"] = rng.choice([0.001, 1e9, 1, 60])
    argv = ["-q", "check", "{scene}"]
    if masks:
        argv = ["-q", "masks", "{scene}", "--frames", "0:2"]
    files["scene.yaml"] = small_scene(pattern, extra)
    return Case("svgseq", f"{name}: {', '.join(what)}", files, argv, pattern, ("frames",))
