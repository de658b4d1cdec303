"""Golden-video tests: tiny scenes rendered end to end and compared frame by frame.

One scene per input type (SMIL SVG, Lottie, SVG sequence), together covering both blend
modes, opacity, the three colorize modes and the three background types. Each composite
frame must match its stored golden frame (tests/golden/<scene>/) at PSNR ≥ 40 dB.
``pytest --update-golden`` rewrites the golden frames; a failing comparison leaves the
rendered frame, the golden one and an amplified difference image in the test's folder.
"""

from fractions import Fraction
from pathlib import Path

import av
import imageio.v3 as iio
import numpy as np
import pytest

ROOT = Path(__file__).parents[2]
GOLDEN = ROOT / "tests" / "golden"
PSNR_MIN = 40.0
SIZE, FRAMES, FPS = 96, 8, 12

_EXEMPLAR = "exemplars:\n  ink: {builtin: watercolor-bloom, size: [64, 64], frames: 8}\n"
SCENES = {
    "smil": (f"input: {ROOT / 'examples/blob/blob.svg'}\nframes: {{start: 4, end: {4 + FRAMES}}}\n"
             "background: {type: synthesized}\n" + _EXEMPLAR +
             "defaults: {exemplar: ink}\n"
             "layers:\n"
             "  - {name: blob, blend: multiply}\n"
             "  - {name: drop, blend: over, opacity: 0.8, colorize: '#d94f30'}\n"),
    "lottie": (f"input: {ROOT / 'examples/wave/wave.json'}\nframes: {{start: 0, end: {FRAMES}}}\n"
               "background: {type: solid, color: '#f4efe4'}\n" + _EXEMPLAR +
               "defaults: {exemplar: ink, blend: multiply}\n"
               "layers:\n"
               "  - {name: body}\n"
               "  - {name: arm, colorize: none}\n"),
    "sequence": (f"input: '{ROOT / 'examples/squiggle/frames'}/%04d.svg'\nframes: {{start: 8, end: {8 + FRAMES}}}\n"
                 f"background: {{type: image, path: {ROOT / 'tests/data/paper.png'}}}\n" + _EXEMPLAR +
                 "defaults: {exemplar: ink}\n"
                 "layers:\n"
                 "  - {name: squiggle, blend: over}\n"),
}


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)


def _render(cli, tmp_path, name):
    scene = tmp_path / f"{name}.yaml"
    scene.write_text(f"version: 1\nfps: {FPS}\nsize: [{SIZE}, {SIZE}]\nseed: 3\n"
                     f"output: {{dir: out, video: {name}.mp4, frames: true}}\n" + SCENES[name])
    code, _, err = cli("-q", "render", scene)
    assert code == 0, err
    return tmp_path / "out"


def _probe(video: Path) -> dict:
    """What ffprobe reports, read through FFmpeg's own libraries (PyAV)."""
    with av.open(str(video)) as container:
        stream = container.streams.video[0]
        frames = sum(1 for _ in container.decode(stream))
        return {"frames": frames, "size": (stream.codec_context.width, stream.codec_context.height),
                "fps": stream.average_rate, "codec": stream.codec_context.name,
                "pix_fmt": stream.codec_context.pix_fmt}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_render_matches_the_golden_frames(cli, tmp_path, monkeypatch, update_golden, name):
    monkeypatch.setenv("FLUIDYMATION_CACHE", str(tmp_path / "cache"))
    out = _render(cli, tmp_path, name)
    assert _probe(out / f"{name}.mp4") == {"frames": FRAMES, "size": (SIZE, SIZE), "fps": Fraction(FPS),
                                           "codec": "h264", "pix_fmt": "yuv420p"}
    rendered = sorted((out / "frames").glob("*.png"))
    assert [p.name for p in rendered] == [f"{k:05d}.png" for k in range(FRAMES)]
    golden_dir = GOLDEN / name
    if update_golden:
        golden_dir.mkdir(parents=True, exist_ok=True)
        for path in rendered:
            (golden_dir / path.name).write_bytes(path.read_bytes())
    failures = []
    for path in rendered:
        expected = golden_dir / path.name
        assert expected.is_file(), f"no golden frame {expected}; run pytest --update-golden"
        got, want = iio.imread(path), iio.imread(expected)
        score = psnr(got, want)
        if score < PSNR_MIN:
            diff = np.clip(np.abs(got.astype(np.int16) - want.astype(np.int16)) * 8, 0, 255).astype(np.uint8)
            iio.imwrite(tmp_path / f"diff-{path.name}", diff)
            iio.imwrite(tmp_path / f"golden-{path.name}", want)
            failures.append(f"{path.name}: {score:.1f} dB")
    assert not failures, f"frames below {PSNR_MIN} dB (rendered, golden and diff images in {tmp_path}): {failures}"
