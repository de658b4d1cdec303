"""Tiny scenes of the blob example for pipeline tests: quick to render, real end to end."""

from pathlib import Path

ROOT = Path(__file__).parents[1]
BLOB_ONLY = '  - {name: blob, color: "#2a6fdb"}\n'


def blob_scene(*, size: int = 40, frames: tuple[int, int] = (0, 4), layers: str = BLOB_ONLY) -> str:
    """examples/blob at ``size``² px, scene ``frames``, solid paper, two 32×32×6 built-in exemplars
    (``ink``, the default, and ``dry``), a quick synthesis schedule, and the given ``layers:`` entries."""
    return (f"version: 1\ninput: {ROOT / 'examples/blob/blob.svg'}\nfps: 12\nsize: [{size}, {size}]\n"
            f"frames: {{start: {frames[0]}, end: {frames[1]}}}\noutput: {{dir: out, video: film.mp4}}\n"
            'background: {type: solid, color: "#f4efe4"}\n'
            "exemplars:\n"
            "  ink: {builtin: watercolor-bloom, size: [32, 32], frames: 6}\n"
            "  dry: {builtin: watercolor-dry, size: [32, 32], frames: 6}\n"
            'defaults: {exemplar: ink, params: {opt_iters: "2, 1", pm_iters: 2}}\n'
            "layers:\n" + layers)


def write_scene(folder: Path, text: str) -> Path:
    """``folder/scene.yaml`` holding ``text`` (the folder is made)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "scene.yaml").write_text(text)
    return folder / "scene.yaml"
