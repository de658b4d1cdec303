"""Built-in moving exemplars: simulated watercolor and crumbling charcoal, cached on disk.

Each preset turns (seed, size, frames, colour, wetness) into a deterministic sequence:
``rgb`` (T, H, W, 3) float32 sRGB in [0, 1], ``mask`` (T, H, W) bool where paint is, and
``flow`` (T, H, W, 2) float32, the exact velocity of the medium in px/frame as (dx, dy)
with y pointing down (``flow[k]`` is the motion from frame k−1 to frame k). The first
call generates the sequence and stores it under ``cache_dir``; later calls with the same
resolved parameters load it back.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage

from fluidymation.engine import crumble, watercolor
from fluidymation.errors import StageError
from fluidymation.stages.colour import parse_hex

NAME = "exemplar_builtin"
VERSION = 2  # 2: watercolor kernels without fastmath (results no longer depend on the heap layout)

PAPER_COLOUR = (0.965, 0.945, 0.9)
WET_DEEPENING = 0.3
_HEX_COLOUR = re.compile(r"^#[0-9a-fA-F]{6}$")


@dataclass(frozen=True)
class Params:
    """Resolved parameters of a built-in exemplar (the cache key, with ``VERSION``).

    ``size`` is (width, height) in pixels, ``color`` a ``#rrggbb`` pigment colour and
    ``wetness`` in [0, 1] how much water the preset starts with.
    """

    preset: str
    seed: int
    size: tuple[int, int]
    frames: int
    color: str
    wetness: float

    def __post_init__(self):
        if self.preset not in PRESETS:
            raise StageError(f"unknown built-in exemplar {self.preset!r}; valid: {', '.join(sorted(PRESETS))}")
        width, height = self.size
        if not (16 <= width <= 4096 and 16 <= height <= 4096):
            raise StageError(f"exemplar size must be between 16 and 4096 pixels per side, got {width}x{height}")
        if not 2 <= self.frames <= 10000:
            raise StageError(f"exemplar frames must be between 2 and 10000, got {self.frames}")
        if not isinstance(self.color, str) or not _HEX_COLOUR.match(self.color):
            raise StageError(f"exemplar color must look like #rrggbb, got {self.color!r}")
        if not 0.0 <= self.wetness <= 1.0:
            raise StageError(f"exemplar wetness must be in [0, 1], got {self.wetness}")

    def cache_key(self) -> str:
        text = json.dumps({"stage": NAME, "version": VERSION, **dataclasses.asdict(self)}, sort_keys=True)
        return f"{self.preset}-{hashlib.sha256(text.encode()).hexdigest()[:16]}"


@dataclass(frozen=True)
class Exemplar:
    """A moving exemplar: ``rgb`` (T, H, W, 3) float32, ``mask`` (T, H, W) bool,
    ``flow`` (T, H, W, 2) float32 px/frame, and the parameters that made it."""

    rgb: np.ndarray
    mask: np.ndarray
    flow: np.ndarray
    params: Params


def make_builtin_exemplar(params: Params, *, cache_dir=None, progress=None) -> Exemplar:
    """Load the exemplar for ``params`` from ``cache_dir`` or generate (and store) it.

    Parameters
    ----------
    params : Params
        The fully resolved parameters.
    cache_dir : path, optional
        Folder of cached exemplars; ``None`` generates without caching.
    progress : callable, optional
        Called with no arguments after each generated frame (not on a cache hit).
    """
    entry = None if cache_dir is None else Path(cache_dir) / params.cache_key()
    if entry is not None and (entry / "params.json").is_file():
        return _load_entry(entry, params)
    rgb, mask, flow = generate(params, progress=progress)
    exemplar = Exemplar(rgb=rgb, mask=mask, flow=flow, params=params)
    if entry is not None:
        _store_entry(entry, exemplar)
    return exemplar


def generate(params: Params, *, progress=None):
    """Run the preset's simulation; return (rgb, mask, flow) arrays (see module doc)."""
    width, height = params.size
    rgb = np.empty((params.frames, height, width, 3), dtype=np.float32)
    mask = np.empty((params.frames, height, width), dtype=bool)
    flow = np.empty((params.frames, height, width, 2), dtype=np.float32)
    for index, (frame_rgb, frame_mask, frame_flow) in enumerate(PRESETS[params.preset].frames(params)):
        rgb[index], mask[index], flow[index] = frame_rgb, frame_mask, frame_flow
        if progress is not None:
            progress()
    return rgb, mask, flow


# --------------------------------------------------------------------------- cache


def _store_entry(entry: Path, exemplar: Exemplar) -> None:
    """Write the entry into a temporary folder, then rename it into place atomically."""
    entry.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{entry.name}.", suffix=".part", dir=entry.parent))
    try:
        for name in ("rgb", "mask", "flow"):
            np.save(staging / f"{name}.npy", getattr(exemplar, name))
        record = {"stage": NAME, "version": VERSION, "params": dataclasses.asdict(exemplar.params)}
        (staging / "params.json").write_text(json.dumps(record, indent=1))
        try:
            os.replace(staging, entry)
        except OSError:
            if not (entry / "params.json").is_file():  # not a concurrent writer: a real failure
                raise
    finally:
        with contextlib.suppress(FileNotFoundError):
            shutil.rmtree(staging)


def _load_entry(entry: Path, params: Params) -> Exemplar:
    try:
        arrays = {name: np.load(entry / f"{name}.npy") for name in ("rgb", "mask", "flow")}
    except (OSError, ValueError) as exc:
        raise StageError(f"{entry}: damaged exemplar cache entry ({exc}); delete the folder to regenerate it") from None
    return Exemplar(params=params, **arrays)


# --------------------------------------------------------------------------- presets


@dataclass(frozen=True)
class _Preset:
    description: str
    frames: Callable[[Params], Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]]


def _scale(params: Params) -> float:
    return min(params.size) / 256.0


def _noisy_disk(shape, centre, radius, rng, *, roughness=0.12, softness=1.5):
    """Soft-edged blob, (H, W) float32 in [0, 1]: a disk whose radius wobbles with angle."""
    yy, xx = np.mgrid[: shape[0], : shape[1]].astype(np.float64)
    angle = np.arctan2(yy - centre[0], xx - centre[1])
    wobble = sum(roughness / k * np.cos(k * angle + rng.uniform(0, 2 * np.pi)) for k in range(2, 8))
    distance = np.hypot(yy - centre[0], xx - centre[1])
    return np.clip((radius * (1.0 + wobble) - distance) / softness + 0.5, 0.0, 1.0).astype(np.float32)


def _paper(params: Params):
    width, height = params.size
    paper_height, capacity = watercolor.make_paper((height, width), seed=params.seed)
    paper_rgb = watercolor.srgb_to_linear(PAPER_COLOUR) * (0.9 + 0.1 * paper_height[:, :, None])
    return paper_height, capacity, paper_rgb.astype(np.float32)


def _pigment_coefficients(colour: str):
    """KM coefficients of a transparent pigment whose unit layer over white shows ``colour``."""
    over_white = np.clip(watercolor.srgb_to_linear(parse_hex(colour)), 0.004, 0.97)
    return watercolor.km_coefficients(over_white, 0.25 * over_white)


def _paint_mask(pigment, reference):
    """Where the stain is: pigment above a small fraction of the reference, holes filled."""
    return ndimage.binary_fill_holes(pigment > 0.06 * reference)


def _watercolor_frames(params, state, wash, *, paper_rgb, reference, steps):
    """Run a wash and render each frame with Kubelka–Munk over the paper."""
    absorption, scattering = _pigment_coefficients(params.color)
    steps_per_frame = max(1, round(steps / params.frames))
    for pigment, wet, flow in watercolor.simulate_wash(state, wash, frames=params.frames, steps_per_frame=steps_per_frame):
        # Wet paint looks deeper than dry paint (watercolor "dries lighter").
        sheen = 1.0 + WET_DEEPENING * ndimage.gaussian_filter(wet.astype(np.float32), 1.0)
        linear = watercolor.km_render(pigment * sheen / reference, absorption, scattering, paper_rgb)
        yield watercolor.linear_to_srgb(linear), _paint_mask(pigment, reference), flow


def _bloom_frames(params: Params):
    scale = _scale(params)
    width, height = params.size
    rng = np.random.default_rng([params.seed, 1])
    paper_height, capacity, paper_rgb = _paper(params)
    centre = (height / 2 + rng.uniform(-0.05, 0.05) * height, width / 2 + rng.uniform(-0.05, 0.05) * width)
    wet = _noisy_disk((height, width), (height / 2, width / 2), 0.47 * min(width, height), rng, softness=1.0) > 0.5
    drop = _noisy_disk((height, width), centre, 0.1 * min(width, height), rng, roughness=0.25, softness=2.0 * scale)
    pigment = 0.5
    state = watercolor.new_wash(
        height=paper_height,
        capacity=capacity,
        wet=wet,
        pressure=ndimage.gaussian_filter(drop, 3.0 * scale) * (1.0 + 4.0 * params.wetness),
        suspended=drop * pigment,
        saturation=wet * np.float32(0.3),
    )
    wash = watercolor.WashParams(drag=0.5, slope=1.0, edge_darkening=0.01, density=0.008, granulation=0.8)
    return _watercolor_frames(params, state, wash, paper_rgb=paper_rgb, reference=0.7 * pigment, steps=round(700 * scale))


def _dry_frames(params: Params):
    scale = _scale(params)
    width, height = params.size
    rng = np.random.default_rng([params.seed, 2])
    paper_height, capacity, paper_rgb = _paper(params)
    centre = (height / 2 + rng.uniform(-0.04, 0.04) * height, width / 2 + rng.uniform(-0.04, 0.04) * width)
    wash_area = _noisy_disk((height, width), centre, 0.33 * min(width, height), rng, roughness=0.2) > 0.5
    pigment = 0.4
    steps = round(360 * scale)
    # Standing water shaped like a flat drop (thin at the rim, deepest inside) with a
    # little unevenness, so the wash dries from its edges inwards.
    depth = ndimage.distance_transform_edt(wash_area)
    profile = 1.0 - (1.0 - np.minimum(depth / max(depth.max(), 1.0), 1.0)) ** 2
    noise = ndimage.gaussian_filter(rng.standard_normal((height, width)), 8.0 * scale)
    unevenness = 1.0 + 0.25 * noise / max(float(noise.std()), 1e-12)
    water = (0.6 + 0.8 * params.wetness) * (0.3 + 0.7 * profile) * np.clip(unevenness, 0.6, 1.4)
    state = watercolor.new_wash(
        height=paper_height,
        capacity=capacity,
        wet=wash_area,
        suspended=wash_area * np.float32(pigment),
        water=(water * wash_area).astype(np.float32),
    )
    wash = watercolor.WashParams(
        edge_darkening=0.06, density=0.03, granulation=0.8, slope=0.3, evaporation=1.0 / (1.7 * steps),
        edge_evaporation=1.0, edge_kernel=max(3, round(14 * scale)),
    )
    return _watercolor_frames(params, state, wash, paper_rgb=paper_rgb, reference=1.5 * pigment, steps=steps)


def _backrun_frames(params: Params):
    scale = _scale(params)
    width, height = params.size
    rng = np.random.default_rng([params.seed, 3])
    paper_height, capacity, paper_rgb = _paper(params)
    short = min(width, height)
    wash_area = _noisy_disk((height, width), (height / 2, width / 2), 0.42 * short, rng, roughness=0.15) > 0.5
    angle = rng.uniform(0, 2 * np.pi)
    offset = 0.12 * short
    centre = (height / 2 + offset * np.sin(angle), width / 2 + offset * np.cos(angle))
    drop = _noisy_disk((height, width), centre, 0.07 * short, rng, softness=1.0) > 0.5
    pigment = 0.3
    steps = round(420 * scale)
    state = watercolor.new_wash(
        height=paper_height,
        capacity=capacity,
        wet=drop,
        pressure=drop * np.float32(0.5 + params.wetness),
        suspended=wash_area * np.float32(0.05),
        deposited=wash_area * (pigment * (1.3 - 0.6 * paper_height)),
        saturation=wash_area * np.float32(0.2),
    )
    wash = watercolor.WashParams(
        edge_darkening=0.05, density=0.02, staining=1.5, granulation=0.6, slope=0.5, drag=0.1,
        edge_kernel=max(3, round(10 * scale)),
    )
    return _watercolor_frames(params, state, wash, paper_rgb=paper_rgb, reference=1.6 * pigment, steps=steps)


def _crumble_frames(params: Params):
    scale = _scale(params)
    width, height = params.size
    rng = np.random.default_rng([params.seed, 4])
    paper_height, _, paper_rgb = _paper(params)
    area = _noisy_disk((height, width), (height / 2, width / 2), 0.36 * min(width, height), rng, roughness=0.25) > 0.5
    absorption, scattering = _pigment_coefficients(params.color)
    for thickness, mask, flow in crumble.simulate_crumble(
        area,
        paper_height=paper_height,
        seed=int(rng.integers(2**31)),
        frames=params.frames,
        fragment_size=max(2.0, 6.0 * scale),
        remaining=0.1 + 0.4 * params.wetness,
        max_speed=max(2.0, 6.0 * scale),
    ):
        linear = watercolor.km_render(thickness, absorption, scattering, paper_rgb)
        yield watercolor.linear_to_srgb(linear), mask, flow


PRESETS = {
    "watercolor-bloom": _Preset("a drop of paint spreading on wet paper into a soft bloom", _bloom_frames),
    "watercolor-dry": _Preset("a flat wash drying, pigment migrating to its darkening edges", _dry_frames),
    "watercolor-backrun": _Preset("clean water creeping back into a damp wash: pale centre, ragged dark rim", _backrun_frames),
    "crumble": _Preset("a dry charcoal patch crumbling away from its edges in chunks", _crumble_frames),
}
