"""The stage cache: each stage's products, per layer, recorded under a key of all they depend on.

A key is the hash of the stage's name and version, its resolved parameters and the keys
of its inputs (content hashes of input files, or the keys of earlier stages). After a
stage finishes, a manifest ``<output>/.cache/<stage>/<layer>.json`` records the key and
the files written; a later run whose key is unchanged and whose files are all still
there skips the stage. Manifests are written atomically after their files, so a killed
run never leaves a manifest for missing or partial work.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

from fluidymation.stages.files import write_text

_CHUNK = 1 << 20
_digests: dict[tuple, str] = {}


def file_digest(path: str | os.PathLike) -> str:
    """SHA-256 of a file's content (remembered per path, size and modification time)."""
    path = Path(path)
    stat = path.stat()
    memo = (str(path.resolve()), stat.st_size, stat.st_mtime_ns)
    if memo not in _digests:
        digest = hashlib.sha256()
        with open(path, "rb") as handle:
            while chunk := handle.read(_CHUNK):
                digest.update(chunk)
        _digests[memo] = digest.hexdigest()
    return _digests[memo]


def stage_key(stage: str, version: int, **parts) -> str:
    """The key of a stage's work: its name, version and everything in ``parts`` (JSON-able)."""
    record = json.dumps({"stage": stage, "version": version, **parts}, sort_keys=True, default=str)
    return hashlib.sha256(record.encode()).hexdigest()[:32]


class StageCache:
    """Manifests of finished stage work under ``<output>/.cache``."""

    def __init__(self, output_dir: Path):
        self.root = Path(output_dir)
        self.dir = self.root / ".cache"

    def _manifest(self, stage: str, layer: str | None) -> Path:
        if layer is None:
            return self.dir / stage / "_scene.json"
        safe = re.sub(r"[^A-Za-z0-9_.-]", "_", layer).lstrip(".")
        return self.dir / stage / f"{safe}-{hashlib.sha256(layer.encode()).hexdigest()[:8]}.json"

    def manifests(self) -> dict[tuple[str, str | None], dict]:
        """Every readable manifest, by (stage, layer); layer None for scene stages."""
        found = {}
        for path in sorted(self.dir.glob("*/*.json")) if self.dir.is_dir() else ():
            try:
                manifest = json.loads(path.read_text())
            except (OSError, ValueError):
                continue
            found[(path.parent.name, manifest.get("layer"))] = manifest
        return found

    def lookup(self, stage: str, layer: str | None) -> dict | None:
        """The manifest of the last finished run of ``stage`` for ``layer``, if readable."""
        try:
            return json.loads(self._manifest(stage, layer).read_text())
        except (OSError, ValueError):
            return None

    def hit(self, stage: str, layer: str | None, key: str) -> bool:
        """Whether ``stage`` already finished for ``layer`` under ``key`` and its files are all there."""
        manifest = self.lookup(stage, layer)
        return (manifest is not None and manifest.get("key") == key
                and all((self.root / name).is_file() for name in manifest.get("files", ())))

    def commit(self, stage: str, layer: str | None, key: str, files, **extra) -> None:
        """Record that ``stage`` finished for ``layer`` under ``key``, having written ``files``."""
        names = sorted(str(Path(f).relative_to(self.root)) for f in files)
        write_text(self._manifest(stage, layer), json.dumps({"key": key, "layer": layer, "files": names, **extra}, indent=1) + "\n")

    def forget(self, stage: str, layer: str | None) -> None:
        """Drop the manifest (before redoing the stage), so a half-redone stage is never taken as done."""
        self._manifest(stage, layer).unlink(missing_ok=True)
