"""The Lottie reader: .json, dotLottie .lottie and Telegram .tgs files, read safely.

A :class:`LottieDocument` isolates layers for its renderers by editing the JSON: every
other layer is marked hidden (``hd``), so it still parents the layers linked to it and
expressions still find it, and a kept layer's track-matte source stays as it is (a matte
source is never drawn itself). A precomp layer named in ``split`` is replaced by its
children, named ``precomp/child``, isolated the same way inside a private copy of its
precomposition. Image assets are embedded as ``data:`` URIs, read from the dotLottie
archive or from files beside the input, so the player never opens a file itself.
What the player (ThorVG) does not draw as the file means is listed in ``unsupported``.
"""

from __future__ import annotations

import base64
import fnmatch
import json
import math
import zipfile
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import NamedTuple

from fluidymation.errors import InputError
from fluidymation.stages.vector.base import Reader, Unsupported, VectorDocument, VectorLayer, frames_in
from fluidymation.stages.vector.safety import (
    file_beside,
    gunzip_limited,
    read_file,
    read_zip_member,
    safe_zip_member_names,
)

_PRECOMP, _TEXT = 0, 5
_MAX_DENOMINATOR = 10**6
_MAX_PATH_COORDINATE = 1e7  # px
_IMAGE_TYPES = {"png": "image/png", "jpg": "image/jpeg", "jpeg": "image/jpeg", "webp": "image/webp",
                "gif": "image/gif", "svg": "image/svg+xml"}
_PLAYER_IMAGE_TYPES = {"image/png", "image/jpeg", "image/webp", "image/svg+xml"}
# What ThorVG 1.0 does not draw (its Lottie parser skips these; checked in its source and on test files).
_IGNORED_SHAPES = {"mm": "merge paths", "tw": "twist", "zz": "zig zag"}
_MERGE_AS_DRAWN = {1, 2}  # merge and add: a group's paths filled together, as the player draws them anyway
_DRAWN_SHAPES = {"gr", "rc", "el", "tr", "fl", "st", "sh", "sr", "rd", "gf", "gs", "tm", "rp", "pb", "op"}
_UNDRAWN_LAYERS = {7: "video placeholder", 8: "image sequence", 9: "video", 10: "image placeholder",
                   12: "adjustment layer", 13: "camera", 14: "light"}
_DRAWN_EFFECTS = {20: "tint", 21: "fill", 22: "stroke", 23: "tritone", 25: "drop shadow", 29: "gaussian blur"}
_DOTLOTTIE_ANIMATIONS, _DOTLOTTIE_IMAGES = ("animations", "a"), ("images", "i")
_THEME_RULE_TYPES = {"Color", "Scalar", "Position", "Vector"}
_CUSTOM_EFFECT = 5  # an effect group: expression controls (drawn as nothing anyway) or a plug-in effect


@dataclass(frozen=True)
class _Unit:
    """Where a layer lives: top-level layer ``layer``, or ``child`` of that precomp."""

    layer: int
    child: int | None = None


class PlayerFrame(NamedTuple):
    """Layers of a Lottie document isolated for a player: the JSON in which only they draw, and the frame to show,
    counted from the animation's in-point (as players count)."""

    json: bytes
    frame: float


class LottieDocument(VectorDocument):
    """A Lottie animation (``data``, its JSON) whose layers can be drawn alone.

    ``files`` are the file itself and the image files beside it that it uses.
    """

    def __init__(self, path: Path, data: dict, *, kind: str, reader: Reader, split: tuple[str, ...] = (),
                 native_fps: float | None = None, images: tuple[Path, ...] = (),
                 unsupported: tuple[Unsupported, ...] = (), choices: dict[str, str] | None = None):
        self.path = path
        self.choices = choices or {}
        self.kind = kind
        self.reader, self.reader_version = reader.name, reader.version
        self.files = [path, *images]
        self.data = data
        self.unsupported = unsupported
        self.width, self.height = float(data["w"]), float(data["h"])
        self.lottie_fps = float(data["fr"])
        self.native_fps = native_fps
        self.in_point, self.out_point = float(data["ip"]), float(data["op"])
        self._units = _units(data, split)
        names_bottom_up = list(reversed(list(self._units)))
        self.layers = [VectorLayer(name, z) for z, name in enumerate(names_bottom_up)]
        self._isolated: dict[tuple[str, ...], bytes] = {}

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

    def isolate(self, names, time_seconds) -> PlayerFrame:
        key = tuple(sorted(names))
        if key not in self._isolated:
            isolated = _isolate(self.data, [unit for name in key for unit in self._units[name]])
            self._isolated[key] = json.dumps(isolated, separators=(",", ":")).encode()
        return PlayerFrame(self._isolated[key], self.lottie_frame(time_seconds) - self.in_point)

    def moving_elements(self, names, before_seconds, now_seconds, size):
        from fluidymation.stages.vector.lottie_geometry import moving_elements

        units: dict[int, set[int] | None] = {}
        for unit in (unit for name in names for unit in self._units[name]):
            if unit.child is None:
                units[unit.layer] = None
            elif units.get(unit.layer, set()) is not None:
                units.setdefault(unit.layer, set()).add(unit.child)
        return moving_elements(self.data, list(units.items()), self.lottie_frame(before_seconds),
                               self.lottie_frame(now_seconds), tuple(size))


def open_lottie(path: Path, *, split: tuple[str, ...] = (), fps: float | None = None,
                animation: str | None = None, theme: str | None = None) -> LottieDocument:
    """Open a .json, .lottie or .tgs file (``fps`` is not needed: the file has its own).

    Of a dotLottie archive, ``animation`` picks an animation of its manifest by id (default
    the first) and ``theme`` a theme by id (default the animation's ``initialTheme``).
    """
    suffix = path.suffix.lower()
    raw = read_file(path)
    theme_rules_skipped, choices = [], {}
    if suffix != ".lottie" and (animation is not None or theme is not None):
        option = "animation" if animation is not None else "theme"
        raise InputError(f"{path}: the scene's '{option}' picks an animation or theme of a dotLottie archive "
                         f"(.lottie); this input has only one animation and no themes")
    if suffix == ".tgs":
        data = _parse_json(gunzip_limited(raw, str(path)), str(path))
    elif suffix == ".lottie":
        data, theme_rules_skipped, choices = _read_dotlottie(raw, path, animation, theme)
    else:
        data = _parse_json(raw, str(path))
    _check_structure(data, str(path))
    _inline_slots(data)
    images = _embed_images_beside(data, path)
    return LottieDocument(path, data, kind={".tgs": "tgs", ".lottie": "dotlottie"}.get(suffix, "lottie"),
                          reader=READER, split=split, native_fps=float(data["fr"]), images=images,
                          unsupported=tuple(theme_rules_skipped + _unsupported(data)), choices=choices)


READER = Reader("lottie", 2, (".json", ".lottie", ".tgs"), open_lottie, options=("animation", "theme"))


def _parse_json(raw: bytes, source: str) -> dict:
    try:
        data = json.loads(raw)
    except UnicodeDecodeError:
        raise InputError(f"{source}: not a text file; expected Lottie JSON") from None
    except RecursionError:
        raise InputError(f"{source}: malformed JSON (values nested too deeply)") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{source}, line {exc.lineno}, column {exc.colno}: malformed JSON ({exc.msg})") from None
    if not isinstance(data, dict):
        raise InputError(f"{source}: expected a Lottie animation (a JSON object), got a JSON {type(data).__name__}")
    return data


def _read_dotlottie(raw: bytes, path: Path, animation: str | None,
                    theme: str | None) -> tuple[dict, list[Unsupported], dict[str, str]]:
    """An animation of a dotLottie archive: ``animation`` by id, else the manifest's first (else the first by name).

    Both layouts are read: version 1 (``animations/``, ``images/``) and 2 (``a/``, ``i/``,
    themes in ``t/``). The theme ``theme``, else the animation's ``initialTheme``, is
    applied (:func:`_apply_theme`). Returned with the animation are the theme's rules that
    are not applied and the animation and theme chosen (by id).
    """
    import io

    source = str(path)
    try:
        archive = zipfile.ZipFile(io.BytesIO(raw))
    except zipfile.BadZipFile:
        raise InputError(f"{source}: not a dotLottie file (not a zip archive)") from None
    except (NotImplementedError, UnicodeDecodeError) as exc:  # "zip file version 9.9", a member name not UTF-8
        raise InputError(f"{source}: a zip archive Python's zipfile cannot read ({exc})") from None
    with archive:
        names = safe_zip_member_names(archive, source)
        manifest = _parse_json(read_zip_member(archive, "manifest.json", source), f"{source}:manifest.json") \
            if "manifest.json" in names else {}
        listed = [entry for entry in _list(manifest.get("animations")) if isinstance(entry, dict)
                  and isinstance(entry.get("id"), str)]
        entry, member = _pick_animation(listed, names, animation, source)
        data = _parse_json(read_zip_member(archive, member, source), f"{source}:{member}")
        _embed_archive_images(data, archive, names, source)
        chosen = _member_id(member)
        choices = {"animation": chosen}
        skipped = []
        where = "the scene's theme" if theme is not None else "the manifest's initial theme"
        if theme is None and isinstance(entry.get("initialTheme"), str):
            theme = entry["initialTheme"]
        if theme is not None:
            theme_member = f"t/{theme}.json"
            if theme_member not in names:
                held = ", ".join(_member_id(n) for n in names if n.startswith("t/") and n.endswith(".json")) or "none"
                raise InputError(f"{source}: {where} '{theme}' is not in the archive ({theme_member}; "
                                 f"its themes: {held})")
            rules = _parse_json(read_zip_member(archive, theme_member, source), f"{source}:{theme_member}")
            skipped = _apply_theme(data, rules, theme, chosen)
            choices["theme"] = theme
    return data, skipped, choices


def _pick_animation(listed: list[dict], names: list[str], animation: str | None, source: str) -> tuple[dict, str]:
    """The manifest entry (empty when the manifest does not list it) and archive member of the animation to read:
    ``animation`` by id, else the manifest's first, else the first stored by name."""
    stored = sorted(n for n in names if n.split("/")[0] in _DOTLOTTIE_ANIMATIONS and n.endswith(".json")
                    and n.count("/") == 1)
    if animation is not None:
        member = next((m for m in stored if _member_id(m) == animation), None)
        if member is None:
            held = ", ".join(_member_id(m) for m in stored) or "none"
            raise InputError(f"{source}: the scene's animation '{animation}' is not in the archive "
                             f"(its animations: {held})")
        return next((entry for entry in listed if entry["id"] == animation), {}), member
    first = listed[0] if listed else {}
    candidates = [f"{folder}/{first['id']}.json" for folder in _DOTLOTTIE_ANIMATIONS] if first else []
    member = next((n for n in candidates + stored if n in names), None)
    if member is None:
        raise InputError(f"{source}: the dotLottie archive holds no animations/*.json (or a/*.json)")
    return (first if first and _member_id(member) == first["id"] else {}), member


def _member_id(member: str) -> str:
    """The id of an archive member ``folder/<id>.json``."""
    return member.split("/", 1)[1][: -len(".json")]


def _apply_theme(data: dict, theme: dict, name: str, animation: str) -> list[Unsupported]:
    """Give the animation's slots (the properties with a ``sid``) the theme's values; returns the rules skipped.

    Colour, scalar, position and vector rules are applied, with a value or keyframes;
    other types (gradient, image, text) are listed as unsupported.
    """
    values, skipped = {}, []
    for index, rule in enumerate(_list(theme.get("rules"))):
        if not isinstance(rule, dict) or not isinstance(rule.get("id"), str):
            continue
        if isinstance(rule.get("animations"), list) and animation not in rule["animations"]:
            continue
        if isinstance(rule.get("type"), str) and rule["type"] in _THEME_RULE_TYPES \
                and ("value" in rule or isinstance(rule.get("keyframes"), list)):
            values[rule["id"]] = _theme_property(rule)
        else:
            skipped.append(Unsupported(f"theme '{name}' rules[{index}] '{rule['id']}'",
                                       f"a rule of type {rule.get('type')}, which is not applied"))
    data["slots"] = dict(_dict(data.get("slots"))) | {sid: {"p": value} for sid, value in values.items()}
    return skipped


def _inline_slots(data: dict) -> None:
    """Put each slot's value (the file's ``slots``, a theme's) into the properties that name it, and drop ``slots``.

    The player then never applies slots itself (ThorVG 1.0 crashes on a position slot).
    """
    slots = {sid: slot["p"] for sid, slot in _dict(data.pop("slots", None)).items()
             if isinstance(slot, dict) and isinstance(slot.get("p"), dict)}
    if not slots:
        return
    stack = [data]
    while stack:
        node = stack.pop()
        children = node.values() if isinstance(node, dict) else node
        for child in children:
            if isinstance(child, dict) and isinstance(child.get("sid"), str) and child["sid"] in slots:
                value = slots[child["sid"]]
                for key in ("a", "k"):
                    child.pop(key, None)
                child.update(value)
            if isinstance(child, (dict, list)):
                stack.append(child)


def _theme_property(rule: dict) -> dict:
    """A theme rule as the Lottie property its slot takes: a static value or keyframes."""
    if "value" in rule:
        return {"a": 0, "k": rule["value"]}
    keyframes = []
    for key in rule["keyframes"]:
        value = key.get("value")
        keyframe = {"t": key.get("frame", 0), "s": value if isinstance(value, list) else [value]}
        if key.get("inTangent") is not None and key.get("outTangent") is not None:
            keyframe |= {"i": key["inTangent"], "o": key["outTangent"]}
        if key.get("hold"):
            keyframe["h"] = 1
        keyframes.append(keyframe)
    return {"a": 1, "k": keyframes}


def _embed_archive_images(data: dict, archive: zipfile.ZipFile, names: list[str], source: str) -> None:
    """Turn image assets stored inside a dotLottie archive into data: URIs."""
    for asset in _image_assets(data):
        if asset.get("e") == 1 or str(asset["p"]).startswith("data:"):
            continue
        named = (str(asset.get("u") or "").lstrip("/") + str(asset["p"])).lstrip("/")
        member = next((m for m in (named, *(f"{folder}/{asset['p']}" for folder in _DOTLOTTIE_IMAGES))
                       if m in names), None)
        if member is not None:
            _embed(asset, read_zip_member(archive, member, source), member)


def _embed_images_beside(data: dict, path: Path) -> tuple[Path, ...]:
    """Embed the image assets that name files beside the input (an After Effects export's ``images/``).

    Returns the files read. URLs and paths leaving the input's folder are refused.
    """
    files = []
    for index, asset in enumerate(data.get("assets") or []):
        if not _is_image(asset):
            continue
        reference = str(asset["p"])
        if reference.startswith("data:"):
            asset["e"] = 1  # players read a data: URI only when the asset says it is embedded
            continue
        if asset.get("e") == 1:
            raise InputError(f"{path}: assets[{index}] (id '{asset.get('id')}') is marked embedded but holds no "
                             "data: URI")
        image = file_beside(path.parent, str(asset.get("u") or "") + reference, str(path),
                            f"assets[{index}] (id '{asset.get('id')}')", "image")
        _embed(asset, read_file(image), image.name)
        files.append(image)
    return tuple(dict.fromkeys(files))


def _embed(asset: dict, content: bytes, name: str) -> None:
    mime = _IMAGE_TYPES.get(name.rsplit(".", 1)[-1].lower(), "application/octet-stream")
    asset.update({"u": "", "p": f"data:{mime};base64,{base64.b64encode(content).decode('ascii')}", "e": 1})


def _is_image(asset) -> bool:
    return isinstance(asset, dict) and "p" in asset and "layers" not in asset


def _image_assets(data: dict) -> list[dict]:
    """The image assets of ``data`` (none when 'assets' is not a list: :func:`_check_structure` says so)."""
    return [asset for asset in _list(data.get("assets")) if _is_image(asset)]


def _check_structure(data: dict, source: str) -> None:
    for key in ("w", "h", "fr", "ip", "op"):
        value = data.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(f"{source}: not a valid Lottie animation: '{key}' must be a number, got {value!r}")
    if data["w"] <= 0 or data["h"] <= 0 or data["fr"] <= 0:
        raise InputError(f"{source}: not a valid Lottie animation: w, h and fr must be positive")
    if data["op"] <= data["ip"]:
        raise InputError(f"{source}: the animation has no frames (op {data['op']} <= ip {data['ip']})")
    _check_layers(data.get("layers"), "layers", source)
    assets = data.get("assets", [])
    if not isinstance(assets, list) or not all(isinstance(asset, dict) for asset in assets):
        raise InputError(f"{source}: not a valid Lottie animation: 'assets' must be a list of objects")
    for index, asset in enumerate(assets):
        _check_references(asset, ("id",), f"assets[{index}]", source)
        if "layers" in asset:
            _check_layers(asset["layers"], f"assets[{index}].layers", source)
    _check_items(data, source)


def _check_items(data: dict, source: str) -> None:
    """No ``null`` item in a list (a point, a colour, keyframes, shapes): no Lottie list holds one, and ThorVG 1.0
    hangs loading some (a point's first coordinate, a keyframe). No path coordinate beyond
    :data:`_MAX_PATH_COORDINATE`: ThorVG 1.0 trims a path with a tangent of 2**31 for ever."""
    pending = [(data, "")]
    while pending:
        value, where = pending.pop()
        if isinstance(value, list) and None in value:
            raise InputError(f"{source}: not a valid Lottie animation: {where}[{value.index(None)}] is null")
        if isinstance(value, dict) and all(key in value for key in ("v", "i", "o")):
            _check_path_coordinates(value, where, source)
        for key, item in value.items() if isinstance(value, dict) else enumerate(value):
            if isinstance(item, (dict, list)):
                pending.append((item, f"{where}[{key}]" if isinstance(key, int) else f"{where}.{key}".lstrip(".")))


def _check_path_coordinates(path: dict, where: str, source: str) -> None:
    """A bezier path's vertices and tangents (``v``, ``i``, ``o``) are finite and within :data:`_MAX_PATH_COORDINATE`."""
    for key in ("v", "i", "o"):
        for index, point in enumerate(_list(path[key])):
            for axis, number in enumerate(_list(point)):
                if isinstance(number, (int, float)) and not isinstance(number, bool) \
                        and not abs(number) <= _MAX_PATH_COORDINATE:
                    raise InputError(f"{source}: not a valid Lottie animation: {where}.{key}[{index}][{axis}] is "
                                     f"{number!r}, beyond {_MAX_PATH_COORDINATE:g} px: it cannot be drawn")


def _check_layers(layers, where: str, source: str) -> None:
    if not isinstance(layers, list):
        raise InputError(f"{source}: not a valid Lottie animation: '{where}' must be a list")
    for index, layer in enumerate(layers):
        if not isinstance(layer, dict) or isinstance(layer.get("ty"), bool) or not isinstance(layer.get("ty"), int):
            raise InputError(f"{source}: {where}[{index}] is not a Lottie layer (needs an integer 'ty')")
        _check_references(layer, ("ind", "parent", "tp", "refId"), f"{where}[{index}]", source)


def _check_references(item: dict, keys: tuple[str, ...], where: str, source: str) -> None:
    """The keys by which layers and assets refer to each other are plain values (they are looked up)."""
    for key in keys:
        value = item.get(key)
        if isinstance(value, (list, dict)):
            raise InputError(f"{source}: not a valid Lottie animation: {where}.{key} must be a number or text, "
                             f"got a JSON {'list' if isinstance(value, list) else 'object'}")


def _units(data: dict, split: tuple[str, ...]) -> dict[str, list[_Unit]]:
    """Layer name -> where its layers live, top of the stack first (Lottie order).

    Layers that share a name are one layer of the document (a user cannot tell them apart).
    """
    units: dict[str, list[_Unit]] = {}
    precomps = {asset.get("id"): asset for asset in data.get("assets") or [] if "layers" in asset}
    for index, layer in enumerate(data["layers"]):
        name = str(layer.get("nm") or f"layer {index}")
        if layer["ty"] == _PRECOMP and any(fnmatch.fnmatchcase(name, pattern) for pattern in split):
            children = precomps.get(layer.get("refId"), {}).get("layers") or []
            for child_index, child in enumerate(children):
                child_name = f"{name}/{child.get('nm') or f'layer {child_index}'}"
                units.setdefault(child_name, []).append(_Unit(index, child=child_index))
            continue
        units.setdefault(name, []).append(_Unit(index))
    return units


def _isolate(data: dict, keep: list[_Unit]) -> dict:
    """A copy of ``data`` in which only the ``keep`` units draw: every other layer is hidden.

    Kept layers keep their track-matte sources (which are never drawn themselves). Only
    what changes is copied: the rest is shared with ``data``, which is never modified.
    """
    layers = data["layers"]
    whole = {unit.layer for unit in keep if unit.child is None}
    partial = {unit.layer for unit in keep} - whole
    needed = _with_matte_sources(layers, whole | partial)
    isolated = dict(data, layers=[layer if index in needed else _hidden(layer) for index, layer in enumerate(layers)],
                    assets=list(data.get("assets") or []))
    for index in sorted(partial):
        isolated["layers"][index] = _keep_children(isolated, layers[index], {u.child for u in keep if u.layer == index},
                                                   index)
    return isolated


def _keep_children(isolated: dict, layer: dict, children: set[int], index: int) -> dict:
    """The precomp ``layer`` drawing only its ``children`` (``split``), isolated in a private copy of the precomp.

    The copy is added to ``isolated``'s assets.
    """
    asset = next(a for a in isolated["assets"] if a.get("id") == layer.get("refId"))
    kept = _with_matte_sources(asset["layers"], children)
    private = dict(asset, id=f"{asset['id']}::isolated{index}",
                   layers=[child if i in kept else _hidden(child) for i, child in enumerate(asset["layers"])])
    isolated["assets"].append(private)
    return dict(layer, refId=private["id"])


def _with_matte_sources(layers: list[dict], indices: set[int]) -> set[int]:
    """``indices`` and the track-matte sources they need, chained mattes too.

    A matted layer (``tt``) takes its matte from the layer whose ``ind`` is its ``tp``
    (Lottie 5.12 and later), else from the layer just above it.
    """
    by_ind = {layer.get("ind"): i for i, layer in enumerate(layers) if "ind" in layer}
    needed, unvisited = set(indices), list(indices)
    while unvisited:
        index = unvisited.pop()
        layer = layers[index]
        if not layer.get("tt"):
            continue
        source = by_ind.get(layer["tp"]) if "tp" in layer else index - 1
        if source is not None and source >= 0 and source not in needed:
            needed.add(source)
            unvisited.append(source)
    return needed


def _hidden(layer: dict) -> dict:
    """``layer`` marked hidden: players draw nothing of it, but it still parents others and expressions find it."""
    return dict(layer, hd=True)


def _unsupported(data: dict) -> list[Unsupported]:
    """What the player does not draw as the file means, each named where it is in the file."""
    found = []
    for index, asset in enumerate(data.get("assets") or []):
        if isinstance(asset, dict) and "layers" in asset:
            found += _unsupported_layers(asset["layers"], f"assets[{index}] '{asset.get('id')}' ", data)
        elif _is_image(asset) and str(asset["p"]).startswith("data:"):
            mime = str(asset["p"])[5:].split(";")[0]
            if mime not in _PLAYER_IMAGE_TYPES:
                found.append(Unsupported(f"assets[{index}] '{asset.get('id')}'",
                                         f"a {mime} image, which the player does not draw"))
    return _unsupported_layers(data["layers"], "", data) + found


def _unsupported_layers(layers: list, where: str, data: dict) -> list[Unsupported]:
    found = []
    for index, layer in enumerate(layers):
        name = f"{where}layers[{index}] '{layer.get('nm', '')}'"
        kind = layer.get("ty")
        if kind in _UNDRAWN_LAYERS:
            found.append(Unsupported(name, f"a {_UNDRAWN_LAYERS[kind]}, which the player does not draw"))
        if layer.get("ddd") == 1:
            found.append(Unsupported(name, "a 3D layer: the player's 3D transform is partial"))
        if layer.get("sy"):
            found.append(Unsupported(name, "layer styles, which the player does not draw"))
        for effect_index, effect in enumerate(_list(layer.get("ef"))):
            if isinstance(effect, dict) and effect.get("en", 1) and not _drawn_effect(effect):
                found.append(Unsupported(f"{name} ef[{effect_index}] '{effect.get('nm', '')}'",
                                         f"effect type {effect.get('ty')}, which the player does not draw"))
        found += _unsupported_shapes(_list(layer.get("shapes")), f"{name} shapes")
        if kind == _TEXT:
            found += _unsupported_text(layer, name, data)
    return found


def _drawn_effect(effect: dict) -> bool:
    """Whether the player draws ``effect``, or there is nothing to draw (expression controls)."""
    if effect.get("ty") == _CUSTOM_EFFECT:
        match_name = str(effect.get("mn", ""))
        return match_name.startswith("Pseudo/") or (match_name.startswith("ADBE ") and "Control" in match_name)
    return effect.get("ty") in _DRAWN_EFFECTS


def _unsupported_shapes(shapes: list, where: str) -> list[Unsupported]:
    found = []
    for index, shape in enumerate(shapes):
        if not isinstance(shape, dict) or shape.get("hd"):
            continue
        name, kind = f"{where}[{index}] '{shape.get('nm', '')}'", shape.get("ty")
        if not isinstance(kind, str):  # a list or mapping cannot be looked up; no such shape type either
            found.append(Unsupported(name, f"shape type {kind!r}, unknown to the player: not drawn"))
            continue
        if kind == "mm" and shape.get("mm", 1) in _MERGE_AS_DRAWN:
            continue
        if kind in _IGNORED_SHAPES:
            found.append(Unsupported(name, f"{_IGNORED_SHAPES[kind]}, which the player ignores: the shapes are "
                                           "drawn without it"))
        elif kind not in _DRAWN_SHAPES:
            found.append(Unsupported(name, f"shape type {kind!r}, unknown to the player: not drawn"))
        if kind == "gr":
            found += _unsupported_shapes(_list(shape.get("it")), f"{name} it")
    return found


def _unsupported_text(layer: dict, name: str, data: dict) -> list[Unsupported]:
    """Text in a font the player cannot draw: one the file neither embeds (``data:font/ttf``) nor gives glyphs of."""
    fonts = {str(font.get("fName")): font for font in _list(_dict(data.get("fonts")).get("list"))
             if isinstance(font, dict)}
    families = {str(char.get("fFamily")) for char in _list(data.get("chars")) if isinstance(char, dict)}
    keyframes = _list(_dict(_dict(layer.get("t")).get("d")).get("k"))
    missing = []
    for font_name in dict.fromkeys(str(_dict(key.get("s")).get("f")) for key in keyframes if isinstance(key, dict)):
        font = _dict(fonts.get(font_name))
        embedded = str(font.get("fPath", "")).startswith("data:font/ttf")
        if not embedded and str(font.get("fFamily")) not in families:
            missing.append(font_name)
    return [Unsupported(name, f"text in the font '{font_name}', which the file neither embeds nor gives glyphs of: "
                              "the player draws no text") for font_name in missing]


def _list(value) -> list:
    return value if isinstance(value, list) else []


def _dict(value) -> dict:
    return value if isinstance(value, dict) else {}
