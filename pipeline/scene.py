"""The scene file: schema (version 1), validation, and the resolved :class:`Scene`.

A scene names a vector animation, the frame range, output size and folder, the
exemplars, and the scene layers (each a selection of vector layers). Paths are resolved
relative to the scene file. Every error names the file, the line and the key path.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from fluidymation.errors import SceneError
from fluidymation.pipeline.schema import HEX_COLOR, Checker
from fluidymation.pipeline.stylizers import stylizer_names
from fluidymation.pipeline.yaml_lines import KeyPath, LocatedYaml, load_yaml

SCENE_VERSION = 1
MAX_SIZE = 16384
MAX_FRAMES = 100_000
MAX_FPS = 1000.0

BACKGROUND_TYPES = ("synthesized", "solid", "image")
BLEND_MODES = ("multiply", "over")
PREVIEW_FORMATS = ("gif", "webp")
EXEMPLAR_KINDS = ("builtin", "video", "images", "image")
_LAYER_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\- ]*$")

_TOP_KEYS = ("version", "input", "animation", "theme", "fps", "frames", "size", "scale", "seed", "split", "output",
             "background", "exemplars", "defaults", "layers")
_LAYER_KEYS = ("name", "select", "color", "exemplar", "stylizer", "colorize", "blend", "opacity", "flow", "params",
               "keyframes", "segments", "segment_map")
_DEFAULT_KEYS = ("exemplar", "stylizer", "colorize", "blend", "opacity", "flow", "params", "segments")
#: Where a layer's regions come from for the ``still`` stylizer: its fill colours, or its mask as one region.
SEGMENT_SOURCES = ("by-color", "mask")
#: Where a layer's motion comes from: the vector geometry, or the masks (paper appendix A).
FLOW_SOURCES = ("vector", "masks")
_EXEMPLAR_KEYS = ("builtin", "video", "images", "image", "segments", "mask", "flow", "scale", "step", "frames", "reverse",
                  "seed", "size", "color", "wetness")


@dataclass(frozen=True)
class FrameRange:
    """Scene frames ``start`` (inclusive) to ``end`` (exclusive)."""

    start: int
    end: int | None  # None: up to the end of the animation

    def __str__(self):
        return f"{self.start}:{'' if self.end is None else self.end}"


@dataclass(frozen=True)
class OutputSpec:
    dir: Path
    video: str
    frames: bool = False        # also the composite as frames/00000.png ...
    preview: str | None = None  # also an animated preview next to the video: "gif" or "webp"
    crf: int = 18               # H.264 quality: 0 lossless ... 51 worst


@dataclass(frozen=True)
class LayerSpec:
    """One scene layer: vector layers merged into one mask sequence, and how to paint it."""

    name: str
    select: tuple[str, ...]
    color: str | None
    exemplar: str | None
    stylizer: str
    colorize: str | None  # None: the stylizer's default (pipeline.parameters.layer_colorize)
    blend: str
    opacity: float
    params: dict = field(default_factory=dict)
    #: Where in the scene file each of ``params`` was given (its key path), for error messages.
    param_paths: dict = field(default_factory=dict, compare=False)
    #: Where the layer's motion comes from: ``vector`` (the geometry; docs/guides.md) or ``masks``.
    flow: str = "vector"
    #: Painted keyframes: (scene frame, image path) pairs in frame order (docs/keyframes.md).
    keyframes: tuple[tuple[int, Path], ...] = ()
    #: The layer's regions for region-matching stylizers: ``by-color`` (its fill colours) or ``mask`` (docs/still.md).
    segments: str = "by-color"
    #: Layer fill colour → exemplar region colour, both '#rrggbb', overriding the nearest-colour match.
    segment_map: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Scene:
    path: Path
    input: Path
    animation: str | None  # a dotLottie's animation and theme, by id (None: its first / its initial one)
    theme: str | None
    fps: float | None
    frames: FrameRange | None
    size: tuple[int, int] | None
    scale: float | None
    seed: int
    split: tuple[str, ...]
    output: OutputSpec
    background: dict
    exemplars: dict
    layers: tuple[LayerSpec, ...] | None  # None: one scene layer per vector layer
    defaults: LayerSpec
    doc: LocatedYaml = field(compare=False, repr=False)

    def error(self, path: KeyPath, message: str) -> SceneError:
        """A SceneError at ``path`` of the scene file: ``scene.yaml, line 12: layers[0].params.w_temp: message``."""
        return Checker(self.doc).error(path, message)

    def layer(self, name: str) -> LayerSpec:
        """The scene layer called ``name`` (only for scenes that list their layers)."""
        for spec in self.layers or ():
            if spec.name == name:
                return spec
        raise KeyError(name)


def load_scene(path: str | Path) -> Scene:
    """Load and validate the scene file at ``path``; raise SceneError on any problem."""
    path = Path(path)
    if path.is_dir():
        raise SceneError(f"{path}: is a folder; give the scene's .yaml file")
    doc = load_yaml(path)
    check = Checker(doc)
    check.mapping((), _TOP_KEYS, required=True)
    version = check.integer(("version",), SCENE_VERSION, minimum=1)
    if version > SCENE_VERSION:
        raise check.error(("version",), f"version {version} is newer than this fluidymation understands "
                          f"(up to {SCENE_VERSION}); upgrade fluidymation")
    if check.has(("size",)) and check.has(("scale",)):
        raise check.error(("scale",), "give either size or scale, not both")
    exemplars = _exemplars(check)
    defaults = _layer(check, ("defaults",), _DEFAULT_KEYS, exemplars, base=None)
    return Scene(
        path=path.resolve(),
        input=check.path(("input",)),
        animation=check.text(("animation",), None),
        theme=check.text(("theme",), None),
        fps=check.number(("fps",), None, above=0, maximum=MAX_FPS),
        frames=_frames(check),
        size=_size(check),
        scale=check.number(("scale",), None, above=0, maximum=64),
        seed=check.integer(("seed",), 0, minimum=0, maximum=2**31 - 1),
        split=tuple(check.text_list(("split",), None) or ()),
        output=_output(check, path),
        background=_background(check),
        exemplars=exemplars,
        layers=_layers(check, exemplars, defaults),
        defaults=defaults,
        doc=doc,
    )


def _frames(check: Checker) -> FrameRange | None:
    if not check.has(("frames",)):
        return None
    check.mapping(("frames",), ("start", "end"))
    start = check.integer(("frames", "start"), 0, minimum=0)
    end = check.integer(("frames", "end"), None, minimum=0)
    if end is not None:
        if end <= start:
            raise check.error(("frames", "end"), f"the frame range {start}:{end} is empty (end is exclusive)")
        if end - start > MAX_FRAMES:
            raise check.error(("frames",), f"{end - start} frames is over the limit of {MAX_FRAMES}")
    return FrameRange(start, end)


def _size(check: Checker) -> tuple[int, int] | None:
    return size_at(check, ("size",), minimum=1) if check.has(("size",)) else None


def size_at(check: Checker, path, *, minimum: int) -> tuple[int, int]:
    """``[width, height]``, or one number for a square, at ``path``."""
    value = check.value(path)
    if isinstance(value, int) and not isinstance(value, bool):
        side = check.integer(path, minimum=minimum, maximum=MAX_SIZE)
        return side, side
    items = check.sequence(path)
    if len(items) != 2:
        raise check.error(path, f"expected [width, height] or one number for a square, got {len(items)} values")
    return tuple(check.integer(path + (i,), minimum=minimum, maximum=MAX_SIZE) for i in range(2))


def _output(check: Checker, scene_path: Path) -> OutputSpec:
    check.mapping(("output",), ("dir", "video", "frames", "preview", "crf"))
    directory = check.path(("output", "dir"), None) or (check.base_dir / "out" / scene_path.stem).resolve()
    video = check.text(("output", "video"), f"{scene_path.stem}.mp4")
    if Path(video).name != video:
        raise check.error(("output", "video"), "give a file name; the video is written into output.dir")
    return OutputSpec(dir=directory, video=video,
                      frames=check.boolean(("output", "frames"), False),
                      preview=check.text(("output", "preview"), None, choices=PREVIEW_FORMATS),
                      crf=check.integer(("output", "crf"), 18, minimum=0, maximum=51))


def _background(check: Checker) -> dict:
    check.mapping(("background",), ("type", "color", "path", "exemplar"))
    kind = check.text(("background", "type"), "synthesized", choices=BACKGROUND_TYPES)
    result = {"type": kind}
    if kind == "solid":
        result["color"] = check.color(("background", "color"), "#ffffff")
    if kind == "image":
        result["path"] = check.path(("background", "path"))
    if kind == "synthesized":
        result["exemplar"] = check.text(("background", "exemplar"), None)
        result["path"] = check.path(("background", "path"), None)
    return result


def _exemplars(check: Checker) -> dict:
    entries = check.mapping(("exemplars",), None)
    result = {}
    for name in entries:
        where = ("exemplars", name)
        check.mapping(where, _EXEMPLAR_KEYS, required=True)
        kinds = [kind for kind in EXEMPLAR_KINDS if check.has(where + (kind,))]
        if len(kinds) != 1:
            raise check.error(where, "give exactly one of builtin (a preset name), video (a file), "
                              "images (a folder or pattern of frames) or image (a still painting)")
        spec = {"kind": kinds[0]}
        if kinds[0] == "builtin":
            spec["builtin"] = check.text(where + ("builtin",))
        else:
            spec["path"] = check.path(where + (kinds[0],))
        if check.has(where + ("segments",)):
            if kinds[0] != "image":
                raise check.error(where + ("segments",), "only a still image exemplar (image:) takes segments")
            if check.has(where + ("mask",)):
                raise check.error(where + ("mask",), "an exemplar with segments takes its mask from them; "
                                  "leave out mask")
            spec["segments"] = check.path(where + ("segments",))
        result[name] = spec | _exemplar_options(check, where)
    return result


def _exemplar_options(check: Checker, where) -> dict:
    options = {}
    if check.has(where + ("seed",)):
        options["seed"] = check.integer(where + ("seed",), minimum=0)
    if check.has(where + ("scale",)):
        options["scale"] = check.number(where + ("scale",), above=0, maximum=16)
    if check.has(where + ("step",)):
        options["step"] = check.number(where + ("step",), above=0, maximum=100)
    if check.has(where + ("reverse",)):
        options["reverse"] = check.boolean(where + ("reverse",))
    if check.has(where + ("color",)):
        options["color"] = check.color(where + ("color",))
    if check.has(where + ("wetness",)):
        options["wetness"] = check.number(where + ("wetness",), minimum=0, maximum=1)
    if check.has(where + ("mask",)):
        value = check.value(where + ("mask",))
        options["mask"] = value if value in ("auto", "full") else check.path(where + ("mask",))
    if check.has(where + ("flow",)):
        options["flow"] = check.text(where + ("flow",), choices=("masks", "motion", "exact"))
    if check.has(where + ("frames",)):
        frames = check.value(where + ("frames",))
        if isinstance(frames, int) and not isinstance(frames, bool):
            options["frames"] = check.integer(where + ("frames",), minimum=1, maximum=MAX_FRAMES)
        else:
            check.mapping(where + ("frames",), ("start", "end"))
            options["frames"] = (check.integer(where + ("frames", "start"), 0, minimum=0),
                                 check.integer(where + ("frames", "end"), None, minimum=1))
    if check.has(where + ("size",)):
        options["size"] = size_at(check, where + ("size",), minimum=8)
    return options


def _param_value(check: Checker, path, value):
    """A stylizer parameter as given: a number, true/false, text, or a list of numbers (per-level counts
    such as ``opt_iters: [4, 2, 1]``, as a tuple); the stylizer's parameter types check it further."""
    if isinstance(value, list) and all(isinstance(item, (int, float)) and not isinstance(item, bool) for item in value):
        return tuple(value)
    if not isinstance(value, (int, float, bool, str)):
        raise check.error(path, "expected a number, true/false, text or a list of numbers")
    return value


def _layer(check: Checker, where, allowed, exemplars: dict, base: LayerSpec | None) -> LayerSpec:
    check.mapping(where, allowed, required=base is not None)
    name = check.text(where + ("name",)) if base is not None else ""
    if base is not None and not _LAYER_NAME.match(name):
        raise check.error(where + ("name",), f"'{name}' cannot be a layer name: use letters, digits, "
                          "space, '_', '-' or '.', not starting with '.' or '-'")
    exemplar = check.text(where + ("exemplar",), base.exemplar if base else None)
    if exemplar is not None and exemplars and exemplar not in exemplars:
        raise check.error(where + ("exemplar",), f"no exemplar called '{exemplar}' in the exemplars section "
                          f"(defined: {', '.join(exemplars)})")
    colorize = check.text(where + ("colorize",), base.colorize if base else None)
    if colorize not in ("layer", "none", None):
        colorize = check.color(where + ("colorize",))
    params = {key: _param_value(check, where + ("params", key), value)
              for key, value in check.mapping(where + ("params",), None).items()}
    return LayerSpec(
        name=name,
        select=tuple(check.text_list(where + ("select",), None) or ([name] if name else [])),
        color=check.color(where + ("color",), None),
        exemplar=exemplar,
        stylizer=check.text(where + ("stylizer",), base.stylizer if base else "fluidymation", choices=stylizer_names()),
        colorize=colorize,
        blend=check.text(where + ("blend",), base.blend if base else "multiply", choices=BLEND_MODES),
        opacity=check.number(where + ("opacity",), base.opacity if base else 1.0, minimum=0, maximum=1),
        params=(dict(base.params) if base else {}) | params,
        param_paths=(dict(base.param_paths) if base else {}) | {key: where + ("params", key) for key in params},
        flow=check.text(where + ("flow",), base.flow if base else "vector", choices=FLOW_SOURCES),
        keyframes=_keyframes(check, where + ("keyframes",)) if "keyframes" in allowed else (),
        segments=check.text(where + ("segments",), base.segments if base else "by-color", choices=SEGMENT_SOURCES),
        segment_map=_segment_map(check, where + ("segment_map",)) if "segment_map" in allowed else (),
    )


def _segment_map(check: Checker, where) -> tuple[tuple[str, str], ...]:
    """``segment_map: {"#layer-fill": "#exemplar-region", ...}``: colours to colours."""
    pairs = []
    for key in check.mapping(where, None):
        if not isinstance(key, str) or not HEX_COLOR.match(key):
            raise check.error(where, f"{key!r}: the keys are the layer's fill colours as \"#rrggbb\"")
        pairs.append((key.lower(), check.color(where + (key,))))
    return tuple(pairs)


def _keyframes(check: Checker, where) -> tuple[tuple[int, Path], ...]:
    """``keyframes: {frame: image, ...}``: whole scene frame numbers to existing image files."""
    data = check.value(where, None)
    if data is None:
        return ()
    if not isinstance(data, dict) or not data:
        raise check.error(where, "expected a mapping of frame numbers to images, e.g. {0: paint/000.png}")
    pairs = []
    for key in data:
        frame = key if isinstance(key, int) and not isinstance(key, bool) else None
        if frame is None and isinstance(key, str) and key.strip().lstrip("-").isdigit():
            frame = int(key)
        if frame is None:
            raise check.error(where, f"keyframe {key!r}: the keys are whole frame numbers")
        path = check.path(where + (key,))
        if not path.is_file():
            raise check.error(where + (key,), f"{path}: no such image")
        pairs.append((frame, path))
    return tuple(sorted(pairs))


def _layers(check: Checker, exemplars: dict, defaults: LayerSpec) -> tuple[LayerSpec, ...] | None:
    if not check.has(("layers",)):
        return None
    items = check.sequence(("layers",))
    if not items:
        raise check.error(("layers",), "lists no layers; leave it out to use every vector layer")
    layers, seen = [], {}
    for index in range(len(items)):
        spec = _layer(check, ("layers", index), _LAYER_KEYS, exemplars, base=defaults)
        if spec.name in seen:
            raise check.error(("layers", index, "name"), f"layer '{spec.name}' is already defined at layers[{seen[spec.name]}]")
        seen[spec.name] = index
        layers.append(spec)
    return tuple(layers)
