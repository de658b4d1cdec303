"""``fluidymation cache info|prune SCENE``: what the stage cache of a scene holds, and tidying it."""

from __future__ import annotations

import shutil
from pathlib import Path

from fluidymation.pipeline import paths
from fluidymation.pipeline.cache import StageCache
from fluidymation.pipeline.scene import load_scene

#: Folders of the output directory whose files belong to stages (the rest is left alone).
STAGE_FOLDERS = ("masks", "coverage", "stylized", "layers", "frames")


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "cache", description="info: the finished stage work recorded for the scene (stage, layer, files, size), and the "
                    "size of the user cache of exemplars. prune: delete files in the scene's output folder that "
                    "no finished stage refers to (frames of older runs, leftovers of interrupted ones such as their temporary guide folders); with "
                    "--exemplars also empty the user cache of generated exemplars and their guides.")
    parser.add_argument("action", choices=("info", "prune"))
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("--preview", action="store_true", help="the cache of --preview renders")
    parser.add_argument("--exemplars", action="store_true", help="prune: also empty the user exemplar cache")
    parser.set_defaults(run=run)


def run(args) -> int:
    scene = load_scene(args.scene)
    out = scene.output.dir / "preview" if args.preview else scene.output.dir
    cache = StageCache(out)
    manifests = cache.manifests()
    if args.action == "info":
        print(f"stage cache of {scene.path.name} in {out}:")
        for (stage, layer), manifest in sorted(manifests.items(), key=lambda item: (item[0][0], item[0][1] or "")):
            files = [out / name for name in manifest.get("files", ())]
            size = sum(path.stat().st_size for path in files if path.is_file())
            state = "complete" if all(path.is_file() for path in files) else "files missing"
            print(f"  {stage:<18} {layer or '(scene)':<16} {len(files):>6} files {_mib(size):>9}  "
                  f"key {manifest.get('key', '?')[:12]}  {state}")
        if not manifests:
            print("  (empty)")
        print(f"user exemplar cache {paths.cache_dir()}: {_mib(_folder_size(paths.cache_dir()))}")
        return 0
    kept = {out / name for manifest in manifests.values() for name in manifest.get("files", ())}
    removed = 0
    for folder in STAGE_FOLDERS:
        for path in sorted((out / folder).rglob("*")) if (out / folder).is_dir() else ():
            if path.is_file() and path not in kept and path.name != "layers.json":
                path.unlink()
                removed += 1
    for leftover in [*out.glob(".guides-*"), *out.glob("*/.guides-*")]:
        shutil.rmtree(leftover, ignore_errors=True)
        removed += 1
    if args.exemplars:
        for entry in (paths.exemplar_cache_dir(), paths.exemplar_guides_cache_dir()):
            shutil.rmtree(entry, ignore_errors=True)
    if not args.quiet:
        print(f"removed {removed} file(s) no finished stage refers to from {out}"
              + ("; emptied the user exemplar cache" if args.exemplars else ""))
    return 0


def _folder_size(folder: Path) -> int:
    return sum(path.stat().st_size for path in folder.rglob("*") if path.is_file()) if folder.is_dir() else 0


def _mib(size: int) -> str:
    return f"{size / 2**20:.1f} MiB"
