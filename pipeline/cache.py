"""The stage cache: each stage's products, per layer, recorded under a key of all they depend on.

A key is the hash of the stage's name and version, its resolved parameters and the keys
of its inputs (content hashes of input files, or the keys of earlier stages). After a
stage finishes, a manifest ``<output>/.cache/<stage>/<layer>.json`` records the key and
the files written; a later run whose key is unchanged and whose files are all still
there skips the stage. Manifests are written atomically after their files, so a killed
run never leaves a manifest for missing or partial work.

A stage that can be resumed (stylize) also records when it starts: ``<layer>.partial``
holds the key it works under and ``<layer>.state/`` what it needs to continue; a run
under the same key continues from there, any other key empties it. Renders running at
once take turns on each stage and layer through locks in ``.cache/locks/``.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
from pathlib import Path

from fluidymation.pipeline.locks import exclusive_lock
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
        return self.dir / stage / f"{_entry_name(layer)}.json"

    def _partial(self, stage: str, layer: str | None) -> Path:
        return self.dir / stage / f"{_entry_name(layer)}.partial"

    def state_dir(self, stage: str, layer: str | None) -> Path:
        """Where a resumable stage keeps what it needs to continue after an interruption."""
        return self.dir / stage / f"{_entry_name(layer)}.state"

    def lock(self, stage: str, layer: str | None):
        """A context holding the lock of ``stage`` for ``layer``: one render at a time checks, runs and commits it."""
        return exclusive_lock(self.dir / "locks" / f"{stage}-{_entry_name(layer)}.lock")

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

    def begin(self, stage: str, layer: str | None, key: str) -> Path:
        """Record that ``stage`` starts for ``layer`` under ``key``; return its :meth:`state_dir`.

        The folder keeps what an interrupted run under the same key left; under another key it is emptied.
        """
        state = self.state_dir(stage, layer)
        try:
            started = json.loads(self._partial(stage, layer).read_text()).get("key")
        except (OSError, ValueError):
            started = None
        if started != key:
            shutil.rmtree(state, ignore_errors=True)
            write_text(self._partial(stage, layer), json.dumps({"key": key, "layer": layer}) + "\n")
        state.mkdir(parents=True, exist_ok=True)
        return state

    def commit(self, stage: str, layer: str | None, key: str, files, **extra) -> dict:
        """Record that ``stage`` finished for ``layer`` under ``key``, having written ``files``; return the manifest.

        What :meth:`begin` recorded is dropped.
        """
        manifest = {"key": key, "layer": layer, "files": sorted(str(Path(f).relative_to(self.root)) for f in files),
                    **extra}
        write_text(self._manifest(stage, layer), json.dumps(manifest, indent=1) + "\n")
        self._partial(stage, layer).unlink(missing_ok=True)
        shutil.rmtree(self.state_dir(stage, layer), ignore_errors=True)
        return manifest

    def forget(self, stage: str, layer: str | None) -> None:
        """Drop the manifest (before redoing the stage), so a half-redone stage is never taken as done."""
        self._manifest(stage, layer).unlink(missing_ok=True)


def _entry_name(layer: str | None) -> str:
    """A file name for a layer's entries: readable and unique (``_scene`` for the scene stages)."""
    if layer is None:
        return "_scene"
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", layer).lstrip(".")
    return f"{safe}-{hashlib.sha256(layer.encode()).hexdigest()[:8]}"
