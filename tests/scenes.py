"""Tiny scenes of the blob example for pipeline tests (quick to render, real end to end), and
tiny masks and exemplars for the stylize tests."""

import json
from pathlib import Path

import numpy as np
from scipy import ndimage

ROOT = Path(__file__).parents[1]
BLOB_ONLY = '  - {name: blob, color: "#2a6fdb"}\n'


def blob_scene(*, size: int = 40, frames: tuple[int, int] = (0, 4), layers: str = BLOB_ONLY,
               params: str = '{opt_iters: "2, 1", pm_iters: 2}') -> str:
    """examples/blob at ``size``² px, scene ``frames``, solid paper, two 32×32×6 built-in exemplars
    (``ink``, the default, and ``dry``), ``params`` for every layer (default: a quick synthesis schedule),
    and the given ``layers:`` entries."""
    return (f"version: 1\ninput: {ROOT / 'examples/blob/blob.svg'}\nfps: 12\nsize: [{size}, {size}]\n"
            f"frames: {{start: {frames[0]}, end: {frames[1]}}}\noutput: {{dir: out, video: film.mp4}}\n"
            'background: {type: solid, color: "#f4efe4"}\n'
            "exemplars:\n"
            "  ink: {builtin: watercolor-bloom, size: [32, 32], frames: 6}\n"
            "  dry: {builtin: watercolor-dry, size: [32, 32], frames: 6}\n"
            f"defaults: {{exemplar: ink, params: {params}}}\n"
            "layers:\n" + layers)


def write_scene(folder: Path, text: str) -> Path:
    """``folder/scene.yaml`` holding ``text`` (the folder is made)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "scene.yaml").write_text(text)
    return folder / "scene.yaml"


def disk(size: int, radius: float, centre_x: float | None = None) -> np.ndarray:
    """A soft-edged disk's coverage on a ``size``² frame, (size, size) float32, centred vertically."""
    centre_x = size / 2 if centre_x is None else centre_x
    yy, xx = np.mgrid[:size, :size] + 0.5
    return np.clip(radius - np.hypot(yy - size / 2, xx - centre_x) + 0.5, 0, 1).astype(np.float32)


def drifting_disk(j: int, size: int = 32) -> np.ndarray:
    """Frame ``j`` of a disk that grows 0.7 px and drifts 0.6 px a frame (a tiny stylize target)."""
    return disk(size, 8.0 + 0.7 * j, centre_x=size / 2 - 3 + 0.6 * j)


def spreading_wash(*, size: int, frames: int, seed: int, start_radius: float, growth: float):
    """A blotchy blue wash whose disk grows ``growth`` px a frame.

    Returns rgb (T, size, size, 3) float32 and mask (T, size, size) bool.
    """
    rng = np.random.default_rng(seed)
    texture = ndimage.gaussian_filter(rng.standard_normal((frames, size, size)), (0, 1.5, 1.5))
    mask = np.stack([disk(size, start_radius + growth * t) > 0.5 for t in range(frames)])
    density = np.clip(0.55 + 0.3 * texture / texture.std(), 0, 1) * mask
    rgb = (0.95 * (1 - density[..., None]) + np.array([0.2, 0.45, 0.85]) * density[..., None]).astype(np.float32)
    return rgb, mask


def turn_flow(size: int, degrees: float, centre: float | None = None) -> np.ndarray:
    """(size, size, 2) float32: the motion that brought each pixel's material there in a turn by ``degrees``
    (clockwise on screen) about (``centre``, ``centre``), pixel centres at integers; default the image centre."""
    angle, centre = np.radians(degrees), (size - 1) / 2 if centre is None else centre
    yy, xx = np.mgrid[:size, :size].astype(np.float64)
    back_x = centre + np.cos(angle) * (xx - centre) + np.sin(angle) * (yy - centre)
    back_y = centre - np.sin(angle) * (xx - centre) + np.cos(angle) * (yy - centre)
    return np.stack([xx - back_x, yy - back_y], axis=-1).astype(np.float32)


def gear_points(centre: tuple[float, float], inner: float, outer: float, teeth: int = 8) -> np.ndarray:
    """(4·teeth, 2) vertices of a gear: ``teeth`` square teeth from radius ``inner`` to ``outer``."""
    k = np.arange(4 * teeth)
    radius = np.where(k % 4 % 3 == 0, inner, outer)
    angle = 2 * np.pi * k / (4 * teeth)
    return np.column_stack([centre[0] + radius * np.cos(angle), centre[1] + radius * np.sin(angle)])


def gear_path(centre: tuple[float, float], inner: float, outer: float, teeth: int = 8) -> str:
    """SVG path data of :func:`gear_points`."""
    return "M" + " L".join(f"{x:.4f},{y:.4f}" for x, y in gear_points(centre, inner, outer, teeth)) + " Z"


def assert_turning(flow, owned, centre, degrees_per_frame, clockwise=True):
    """``flow`` over ``owned`` is a turn about ``centre``: speed ω·r within 5 % and direction within 5° of the
    tangent, 3 px from the centre on."""
    omega = np.radians(degrees_per_frame)
    yy, xx = np.nonzero(owned)
    offset = np.column_stack([xx + 0.5, yy + 0.5]) - np.asarray(centre)
    radius = np.hypot(offset[:, 0], offset[:, 1])
    away = radius > 3.0
    speed = np.hypot(*flow[yy, xx].T)
    np.testing.assert_allclose(speed[away], omega * radius[away], rtol=0.05)
    # a positive rotation turns x towards y: clockwise on screen (y down), tangent (−y, x)
    tangent = np.arctan2(offset[:, 0], -offset[:, 1]) + (0.0 if clockwise else np.pi)
    turn = np.angle(np.exp(1j * (np.arctan2(flow[yy, xx, 1], flow[yy, xx, 0]) - tangent)))
    assert np.degrees(np.abs(turn[away])).max() < 5.0


def turning_gear_svg(folder: Path) -> Path:
    """``folder/gear.svg``: a 64-px gear (layer ``gear``) turned once every 3 s by SMIL ``animateTransform``."""
    path = folder / "gear.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="64" height="64"><g id="gear">'
                    f'<path d="{gear_path((32, 32), 15, 22)}"/><animateTransform attributeName="transform" '
                    'type="rotate" from="0 32 32" to="360 32 32" dur="3s" repeatCount="indefinite"/></g></svg>')
    return path


def still(value) -> dict:
    """A Lottie property that keeps ``value``."""
    return {"a": 0, "k": value}


def lottie_path(points, closed: bool = True) -> dict:
    """A Lottie path value through ``points`` with straight segments."""
    points = np.asarray(points, float).tolist()
    return {"v": points, "i": [[0, 0]] * len(points), "o": [[0, 0]] * len(points), "c": closed}


def turning_gear_lottie(folder: Path) -> Path:
    """``folder/gear.json``: the gear of :func:`turning_gear_svg` as a Lottie shape layer turned by its rotation."""
    gear = {"ty": "sh", "ks": still(lottie_path(gear_points((32, 32), 15, 22)))}
    fill = {"ty": "fl", "c": still([0, 0, 0, 1]), "o": still(100), "r": 1}
    turn = {"a": 1, "k": [{"t": 0, "s": [0], "o": {"x": [0], "y": [0]}, "i": {"x": [1], "y": [1]}},
                          {"t": 72, "s": [360]}]}
    layer = {"ty": 4, "nm": "gear", "ind": 1, "ip": 0, "op": 72, "st": 0, "shapes": [gear, fill],
             "ks": {"a": still([32, 32]), "p": still([32, 32]), "s": still([100, 100]), "r": turn, "o": still(100)}}
    path = folder / "gear.json"
    path.write_text(json.dumps({"v": "5.7.0", "fr": 24, "ip": 0, "op": 72, "w": 64, "h": 64, "layers": [layer]}))
    return path


def two_region_painting(size: int = 64):
    """A still painting of two regions with distinct textures: blue stripes left of a wavy line, green dots
    right of it. Returns rgb (size, size, 3) float32 and the region labels (size, size) int32 (0 blue, 1 green)."""
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[:size, :size]
    labels = np.where(xx < size / 2 + 6 * np.sin(yy / 6), 0, 1).astype(np.int32)
    stripes = 0.5 + 0.4 * np.sin(xx * 0.9 + rng.normal(0, 0.3, (size, size)))
    dots = (rng.random((size, size)) < 0.15).astype(np.float32)
    rgb = np.where((labels == 0)[..., None], np.stack([0.2 * stripes, 0.3 * stripes, 0.9 * stripes], -1),
                   np.stack([0.3 + 0.5 * dots, 0.8 - 0.3 * dots, 0.2 + 0 * dots], -1)).astype(np.float32)
    return rgb, labels


def map_svg(size: int = 48) -> str:
    """A still two-colour map (group ``map``: water #334ccc left, land #409940 right) and a ``boat`` (#e0c070)
    sailing right 12 px over 1 s, in SMIL."""
    half = size // 2
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">\n'
            f'  <g id="map"><rect x="2" y="2" width="{half - 2}" height="{size - 4}" fill="#334ccc"/>\n'
            f'    <rect x="{half}" y="2" width="{half - 2}" height="{size - 4}" fill="#409940"/></g>\n'
            f'  <g id="boat" fill="#e0c070"><circle cx="12" cy="{half}" r="7">\n'
            '    <animate attributeName="cx" from="12" to="24" begin="0s" dur="1s" fill="freeze"/></circle></g>\n'
            '</svg>\n')
