"""The Lottie reader: .json, dotLottie .lottie and Telegram .tgs files, read safely.

A :class:`LottieDocument` isolates layers for its renderers: every other layer is turned
into a null layer that keeps its index, parent and transform, so parenting still works; a
track-matte source needed by a kept layer is kept too. A precomp layer named in ``split``
is replaced by its children, named ``precomp/child``.
"""

from __future__ import annotations

import base64
import copy
import fnmatch
import json
import math
import zipfile
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import NamedTuple

import lottie.objects

from fluidymation.errors import InputError
from fluidymation.stages.vector.base import Reader, VectorDocument, VectorLayer, frames_in
from fluidymation.stages.vector.safety import (
    gunzip_limited,
    read_file,
    read_zip_member,
    safe_zip_member_names,
)

_PRECOMP, _NULL = 0, 3
_MAX_DENOMINATOR = 10**6
_IMAGE_TYPES = {"png": "image/png", "jpg": "image/jpeg", "jpeg": "image/jpeg", "webp": "image/webp",
                "gif": "image/gif", "svg": "image/svg+xml"}


@dataclass(frozen=True)
class _Unit:
    """Where a layer lives: top-level layer ``layer``; ``child`` of that precomp or ``group`` of that shape layer."""

    layer: int
    child: int | None = None
    group: int | None = None


class LottieFrame(NamedTuple):
    """Layers of a Lottie document isolated at a time: the animation in which only they draw, and its frame."""

    animation: lottie.objects.Animation
    frame: float


class LottieDocument(VectorDocument):
    """A Lottie animation (``data``, its JSON) whose layers can be drawn alone.

    With ``groups_as_layers`` the groups of top-level shape layers are the layers (an
    imported SMIL SVG).
    """

    def __init__(self, path: Path, data: dict, *, kind: str, reader: Reader, split: tuple[str, ...] = (),
                 native_fps: float | None = None, groups_as_layers: bool = False):
        self.path = path
        self.kind = kind
        self.reader, self.reader_version = reader.name, reader.version
        self.files = [path]
        self.data = data
        animation = _load_animation(data, str(path))
        self.width, self.height = float(animation.width), float(animation.height)
        self.lottie_fps = float(animation.frame_rate)
        self.native_fps = native_fps
        self.in_point, self.out_point = float(animation.in_point), float(animation.out_point)
        self._units = _units(data, split, groups_as_layers)
        names_bottom_up = list(reversed(list(self._units)))
        self.layers = [VectorLayer(name, z) for z, name in enumerate(names_bottom_up)]
        self._animations: dict[tuple[str, ...], lottie.objects.Animation] = {}

    def frame_range(self, fps: float) -> tuple[int, int]:
        start = math.floor(self.in_point * fps / self.lottie_fps + 1e-6)
        end = frames_in(self.out_point / self.lottie_fps, fps)
        return start, max(end, start + 1)

    def lottie_frame(self, time_seconds: float) -> float:
        """The Lottie frame shown at ``time_seconds``: the time times the file's frame rate.

        Scene frame k at f fps arrives as the float k/f. The product is taken on the
        fraction nearest that float with a denominator up to 10**6, which is k/f itself, so
        for whole-number rates it is k·fr/f to the bit and a scene frame that falls on a
        file frame lands on it exactly (layer in and out points, hold keyframes), where the
        float product alone can miss it by a unit in the last place.
        """
        time = Fraction(time_seconds).limit_denominator(_MAX_DENOMINATOR)
        return float(time * Fraction(self.lottie_fps))

    def isolate(self, names, time_seconds) -> LottieFrame:
        key = tuple(sorted(names))
        if key not in self._animations:
            isolated = _isolate(self.data, [self._units[name] for name in key])
            self._animations[key] = _load_animation(isolated, str(self.path))
        return LottieFrame(self._animations[key], self.lottie_frame(time_seconds))


def open_lottie(path: Path, *, split: tuple[str, ...] = (), fps: float | None = None) -> LottieDocument:
    """Open a .json, .lottie or .tgs file (``fps`` is not needed: the file has its own)."""
    suffix = path.suffix.lower()
    raw = read_file(path)
    if suffix == ".tgs":
        data = _parse_json(gunzip_limited(raw, str(path)), str(path))
    elif suffix == ".lottie":
        data = _read_dotlottie(raw, path)
    else:
        data = _parse_json(raw, str(path))
    _check_structure(data, str(path))
    _check_assets(data, str(path))
    return LottieDocument(path, data, kind={".tgs": "tgs", ".lottie": "dotlottie"}.get(suffix, "lottie"),
                          reader=READER, split=split, native_fps=float(data["fr"]))


READER = Reader("lottie", 1, (".json", ".lottie", ".tgs"), open_lottie)


def _parse_json(raw: bytes, source: str) -> dict:
    try:
        data = json.loads(raw)
    except UnicodeDecodeError:
        raise InputError(f"{source}: not a text file; expected Lottie JSON") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{source}, line {exc.lineno}, column {exc.colno}: malformed JSON ({exc.msg})") from None
    if not isinstance(data, dict):
        raise InputError(f"{source}: expected a Lottie animation (a JSON object), got a JSON {type(data).__name__}")
    return data


def _read_dotlottie(raw: bytes, path: Path) -> dict:
    import io

    source = str(path)
    try:
        archive = zipfile.ZipFile(io.BytesIO(raw))
    except zipfile.BadZipFile:
        raise InputError(f"{source}: not a dotLottie file (not a zip archive)") from None
    with archive:
        names = safe_zip_member_names(archive, source)
        manifest = _parse_json(read_zip_member(archive, "manifest.json", source), f"{source}:manifest.json") \
            if "manifest.json" in names else {}
        animations = manifest.get("animations") if isinstance(manifest.get("animations"), list) else []
        first = animations[0].get("id") if animations and isinstance(animations[0], dict) else None
        candidates = [f"animations/{first}.json"] if first else []
        candidates += sorted(n for n in names if n.startswith("animations/") and n.endswith(".json"))
        member = next((n for n in candidates if n in names), None)
        if member is None:
            raise InputError(f"{source}: the dotLottie archive holds no animations/*.json")
        data = _parse_json(read_zip_member(archive, member, source), f"{source}:{member}")
        _embed_archive_images(data, archive, names, source)
    return data


def _embed_archive_images(data: dict, archive: zipfile.ZipFile, names: list[str], source: str) -> None:
    """Turn image assets stored inside a dotLottie archive into data: URIs."""
    for asset in data.get("assets") or []:
        if not isinstance(asset, dict) or "p" not in asset or asset.get("e") == 1:
            continue
        member = (str(asset.get("u") or "").lstrip("/") + str(asset["p"])).lstrip("/")
        if member not in names and f"images/{asset['p']}" in names:
            member = f"images/{asset['p']}"
        if member in names:
            mime = _IMAGE_TYPES.get(member.rsplit(".", 1)[-1].lower(), "application/octet-stream")
            encoded = base64.b64encode(read_zip_member(archive, member, source)).decode("ascii")
            asset.update({"u": "", "p": f"data:{mime};base64,{encoded}", "e": 1})


def _check_structure(data: dict, source: str) -> None:
    for key in ("w", "h", "fr", "ip", "op"):
        value = data.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(f"{source}: not a valid Lottie animation: '{key}' must be a number, got {value!r}")
    if data["w"] <= 0 or data["h"] <= 0 or data["fr"] <= 0:
        raise InputError(f"{source}: not a valid Lottie animation: w, h and fr must be positive")
    if data["op"] <= data["ip"]:
        raise InputError(f"{source}: the animation has no frames (op {data['op']} <= ip {data['ip']})")
    if not isinstance(data.get("layers"), list):
        raise InputError(f"{source}: not a valid Lottie animation: 'layers' must be a list")
    for index, layer in enumerate(data["layers"]):
        if not isinstance(layer, dict) or not isinstance(layer.get("ty"), int):
            raise InputError(f"{source}: layers[{index}] is not a Lottie layer (needs an integer 'ty')")


def _check_assets(data: dict, source: str) -> None:
    """Refuse image assets that point at files or URLs: only embedded data: URIs are allowed."""
    for index, asset in enumerate(data.get("assets") or []):
        if not isinstance(asset, dict) or "p" not in asset or "layers" in asset:
            continue
        reference = str(asset.get("p"))
        if asset.get("e") == 1 or reference.startswith("data:"):
            continue
        where = (str(asset.get("u") or "") + reference) or "(empty)"
        raise InputError(f"{source}: assets[{index}] (id '{asset.get('id')}') refers to the external image "
                         f"'{where}'; Fluidymation never reads files named inside an input: embed the image")


def _load_animation(data: dict, source: str) -> lottie.objects.Animation:
    try:
        return lottie.objects.Animation.load(data)
    except Exception as exc:  # the lottie loader raises many types on malformed input
        raise InputError(f"{source}: not a valid Lottie animation ({type(exc).__name__}: {exc})") from None


def _units(data: dict, split: tuple[str, ...], groups_as_layers: bool) -> dict[str, _Unit]:
    """Layer name -> where it lives, top of the stack first (Lottie order)."""
    units: dict[str, _Unit] = {}
    precomps = {asset.get("id"): asset for asset in data.get("assets") or [] if isinstance(asset, dict) and "layers" in asset}
    for index, layer in enumerate(data["layers"]):
        name = str(layer.get("nm") or f"layer {index}")
        if groups_as_layers and layer["ty"] == 4:
            for group_index, shape in enumerate(layer.get("shapes") or []):
                if shape.get("ty") == "gr":
                    units.setdefault(str(shape.get("nm") or f"group {group_index}"), _Unit(index, group=group_index))
            continue
        if layer["ty"] == _PRECOMP and any(fnmatch.fnmatchcase(name, pattern) for pattern in split):
            children = precomps.get(layer.get("refId"), {}).get("layers") or []
            for child_index, child in enumerate(children):
                units.setdefault(f"{name}/{child.get('nm') or f'layer {child_index}'}", _Unit(index, child=child_index))
            continue
        units.setdefault(name, _Unit(index))
    return units


def _isolate(data: dict, keep: list[_Unit]) -> dict:
    """A copy of ``data`` in which only the ``keep`` units draw anything."""
    data = copy.deepcopy(data)
    layers = data["layers"]
    whole = {unit.layer for unit in keep if unit.child is None and unit.group is None}
    partial = {unit.layer for unit in keep} - whole
    needed = whole | partial
    needed |= {index - 1 for index in needed if index > 0 and layers[index].get("tt")}
    for index, layer in enumerate(layers):
        if index not in needed:
            layers[index] = _as_null(layer)
        elif index in partial:
            _keep_parts(data, layer, [u for u in keep if u.layer == index], index)
    return data


def _keep_parts(data: dict, layer: dict, keep: list[_Unit], index: int) -> None:
    groups = {unit.group for unit in keep if unit.group is not None}
    if groups:
        layer["shapes"] = [shape for i, shape in enumerate(layer.get("shapes") or [])
                           if i in groups or shape.get("ty") != "gr"]
    children = {unit.child for unit in keep if unit.child is not None}
    if children:
        asset = next(a for a in data["assets"] if a.get("id") == layer.get("refId"))
        private = copy.deepcopy(asset)
        private["id"] = f"{asset['id']}::isolated{index}"
        kept = {c for c in children} | {c - 1 for c in children if c > 0 and private["layers"][c].get("tt")}
        private["layers"] = [child if i in kept else _as_null(child) for i, child in enumerate(private["layers"])]
        data["assets"].append(private)
        layer["refId"] = private["id"]


def _as_null(layer: dict) -> dict:
    """A null layer that keeps ``layer``'s index, parent, timing and transform."""
    kept = {key: layer[key] for key in ("ind", "parent", "ks", "ip", "op", "st", "sr", "nm") if key in layer}
    return kept | {"ty": _NULL, "ddd": 0}
