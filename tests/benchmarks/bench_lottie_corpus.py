"""Benchmark: Lottie fidelity, refusals, crashes and speed on a corpus of real files, against two reference players.

Run: ``.venv/bin/python tests/benchmarks/bench_lottie_corpus.py CORPUS [--size 512] [--out results.jsonl]``
with CORPUS a folder of Lottie files (.json, .lottie, searched recursively), e.g. rlottie's
``example/resource`` fetched for measurement only. Nothing is downloaded or committed.

Each file is rendered at three frames of its own (in-point, one third and two thirds in)
at SIZE×SIZE, in a child process per file and engine, so a native crash is counted, not
fatal:

* ``default``: our reader and its default renderer, every layer alone, their coverage
  composited (alpha over alpha) and thresholded at 0.5, each layer-frame timed;
* ``rlottie-layers``: the same isolated JSON drawn by rlottie (to compare the players
  on our isolation);
* ``thorvg``, ``rlottie``: the whole file drawn by each reference player straight from
  its JSON, not through our reader (also: whether ThorVG draws a half frame between two).

A file counts where the two references agree (IoU ≥ 0.95 on all three frames); ours is
right there when its IoU with both references is ≥ 0.95 on all three frames. To measure
an older tree, put its package first on PYTHONPATH: the ``default`` engine is whatever
``fluidymation`` imports.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

AGREE = 0.95
ENGINES = ("default", "rlottie-layers", "thorvg", "rlottie")


def corpus_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.suffix.lower() in (".json", ".lottie") and p.is_file())


def file_frames(data: dict) -> list[int]:
    first, end = data["ip"], data["op"]
    return [int(first + (end - first) * k // 3) for k in range(3)]


def raw_json(path: Path) -> bytes:
    """The file's JSON as the references get it, with every image embedded (a .lottie: its first animation).

    Read here, not by our reader, so that the references do not share its refusals.
    """
    if path.suffix.lower() == ".lottie":
        with zipfile.ZipFile(path) as archive:
            member = sorted(n for n in archive.namelist() if n.split("/")[0] in ("animations", "a")
                            and n.endswith(".json"))[0]
            data = json.loads(archive.read(member))
            files = {name: archive.read(name) for name in archive.namelist()}
        images = {name.split("/", 1)[-1]: content for name, content in files.items()}
    else:
        data = json.loads(path.read_bytes())
        images = {}
    for asset in data.get("assets", []):
        if "p" not in asset or "layers" in asset or str(asset["p"]).startswith("data:"):
            continue
        name = str(asset.get("u") or "") + str(asset["p"])
        content = images.get(str(asset["p"])) or images.get(name)
        if content is None and (path.parent / name).is_file():
            content = (path.parent / name).read_bytes()
        if content is not None:
            asset.update(u="", p="data:image/png;base64," + base64.b64encode(content).decode(), e=1)
    return json.dumps(data).encode()


def fitted_alpha(rgba: np.ndarray) -> np.ndarray:
    return rgba[:, :, 3] >= 128


def over(coverage: np.ndarray, rgba: np.ndarray) -> np.ndarray:
    """The layers' coverage so far with one more layer drawn over it (so two translucent layers add up as in
    the whole composition)."""
    return 1 - (1 - coverage) * (1 - rgba[:, :, 3] / 255.0)


# --- engines (each runs in its own child process) -------------------------------------------------------------

def run_default(path: Path, size: int) -> dict:
    from fluidymation.errors import InputError
    from fluidymation.stages.vector import open_document, renderer_for

    try:
        document = open_document(path)
        renderer = renderer_for(document)
        frames = file_frames(document.data)
        masks, times = [], []
        for frame in frames:
            union = np.zeros((size, size))
            for name in document.layer_names():
                start = time.perf_counter()
                rgba = renderer.render(document, [name], frame / document.lottie_fps, (size, size))
                times.append(time.perf_counter() - start)
                union = over(union, rgba)
            masks.append(union >= 0.5)
    except InputError as exc:
        status = "crashed" if "player crashed" in str(exc) else "hung" if "did not finish" in str(exc) else "refused"
        return {"status": status, "message": str(exc)[:300]}
    except Exception as exc:  # an internal error of ours: counted, with its type
        return {"status": "internal", "message": f"{type(exc).__name__}: {exc}"[:300]}
    return {"status": "ok", "masks": np.array(masks), "renderer": renderer.name, "layers": len(document.layers),
            "layer_frame_seconds": times}


def _rlottie_render(data: bytes, frame: int, size: int) -> np.ndarray:
    from rlottie_python import LottieAnimation

    animation = LottieAnimation.from_data(data.decode())
    if not animation.animation_p:
        raise ValueError("rlottie cannot load it")
    buffer = animation.lottie_animation_render(frame_num=frame, width=size, height=size)
    return np.frombuffer(buffer, np.uint8).reshape(size, size, 4)


def run_rlottie_layers(path: Path, size: int) -> dict:
    from fluidymation.errors import InputError
    from fluidymation.stages.vector import open_document

    try:
        document = open_document(path)
        frames = file_frames(document.data)
        masks, times = [], []
        for frame in frames:
            union = np.zeros((size, size))
            for name in document.layer_names():
                isolated = document.isolate([name], frame / document.lottie_fps)
                start = time.perf_counter()
                rgba = _rlottie_render(isolated.json, round(isolated.frame), size)
                times.append(time.perf_counter() - start)
                union = over(union, rgba)
            masks.append(union >= 0.5)
    except (InputError, ValueError) as exc:
        return {"status": "refused", "message": str(exc)[:300]}
    return {"status": "ok", "masks": np.array(masks), "layer_frame_seconds": times}


def run_rlottie(path: Path, size: int) -> dict:
    data = raw_json(path)
    frames = file_frames(json.loads(data))
    first = json.loads(data)["ip"]
    try:
        masks = [fitted_alpha(_rlottie_render(data, int(frame - first), size)) for frame in frames]
    except ValueError as exc:
        return {"status": "refused", "message": str(exc)}
    return {"status": "ok", "masks": np.array(masks)}


def run_thorvg(path: Path, size: int) -> dict:
    import thorvg_python as tvg

    data = raw_json(path)
    parsed = json.loads(data)
    engine = tvg.Engine(threads=0)

    def draw(frame: float) -> np.ndarray:
        canvas = tvg.SwCanvas(engine)
        canvas.set_target(size, size)
        animation = tvg.LottieAnimation(engine)
        picture = animation.get_picture()
        if picture.load_data(data, "lottie", None, True) != tvg.Result.SUCCESS:
            raise ValueError("ThorVG cannot load it")
        width, height = parsed["w"], parsed["h"]
        scale = min(size / width, size / height)
        picture.set_size(width * scale, height * scale)
        picture.translate((size - width * scale) / 2, (size - height * scale) / 2)
        canvas.add(picture)
        animation.set_frame(frame)
        canvas.update()
        canvas.draw(True)
        canvas.sync()
        return np.frombuffer(bytes(canvas.buffer_arr), np.uint8).reshape(size, size, 4)

    frames = [frame - parsed["ip"] for frame in file_frames(parsed)]
    try:
        masks = [fitted_alpha(draw(frame)) for frame in frames]
        halves = [draw(frames[1] + offset)[:, :, 3].astype(np.int32) for offset in (0, 0.5, 1)]
    except ValueError as exc:
        return {"status": "refused", "message": str(exc)}
    moving = bool((halves[0] != halves[2]).any())
    between = moving and bool((halves[1] != halves[0]).any() and (halves[1] != halves[2]).any())
    return {"status": "ok", "masks": np.array(masks), "moving": moving, "half_frame_between": between}


RUNNERS = {"default": run_default, "rlottie-layers": run_rlottie_layers, "thorvg": run_thorvg, "rlottie": run_rlottie}


def child(engine: str, path: Path, size: int, out: Path) -> None:
    result = RUNNERS[engine](path, size)
    masks = result.pop("masks", None)
    np.savez_compressed(out, masks=np.packbits(masks) if masks is not None else np.zeros(0, np.uint8),
                        meta=np.frombuffer(json.dumps(result).encode(), np.uint8))


def run_engine(engine: str, path: Path, size: int, timeout: float) -> dict:
    with tempfile.TemporaryDirectory() as scratch:
        out = Path(scratch) / "result.npz"
        try:
            process = subprocess.run([sys.executable, __file__, "--child", engine, str(path), str(size), str(out)],
                                     capture_output=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"status": "hung"}
        if process.returncode != 0:
            status = "crashed" if process.returncode < 0 else "internal"
            return {"status": status, "message": f"exit {process.returncode}: {process.stderr.decode()[-300:]}"}
        stored = np.load(out)
        result = json.loads(stored["meta"].tobytes())
        if result["status"] == "ok":
            result["masks"] = np.unpackbits(stored["masks"])[:3 * size * size].reshape(3, size, size).astype(bool)
        return result


def iou(a: np.ndarray, b: np.ndarray) -> float:
    union = (a | b).sum()
    return 1.0 if union == 0 else float((a & b).sum() / union)


def worst_iou(a: dict, b: dict) -> float | None:
    if a.get("status") != "ok" or b.get("status") != "ok":
        return None
    return min(iou(x, y) for x, y in zip(a["masks"], b["masks"]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per file and engine")
    parser.add_argument("--engines", nargs="+", default=list(ENGINES), choices=ENGINES)
    parser.add_argument("--out", type=Path, help="one JSON line per file")
    args = parser.parse_args()
    load_before = os.getloadavg()
    rows = []
    sink = args.out.open("w") if args.out else None
    for path in corpus_files(args.corpus):
        results = {engine: run_engine(engine, path, args.size, args.timeout) for engine in args.engines}
        row = {"file": str(path.relative_to(args.corpus)),
               **{f"{engine}_status": result["status"] for engine, result in results.items()}}
        references = "thorvg" in results and "rlottie" in results
        if references:
            row["references_iou"] = worst_iou(results["thorvg"], results["rlottie"])
            for engine in ("default", "rlottie-layers"):
                if engine in results:
                    scores = [worst_iou(results[engine], results[r]) for r in ("thorvg", "rlottie")]
                    row[f"{engine}_iou"] = None if None in scores else min(scores)
        for engine, result in results.items():
            for key in ("message", "renderer", "layers", "moving", "half_frame_between"):
                if key in result:
                    row[f"{engine}_{key}"] = result[key]
            if "layer_frame_seconds" in result:
                row[f"{engine}_seconds"] = result["layer_frame_seconds"]
        rows.append(row)
        print(json.dumps({k: v for k, v in row.items() if not k.endswith("_seconds")}), flush=True)
        if sink:
            sink.write(json.dumps(row) + "\n")
    if sink:
        sink.close()
    summarize(rows, args.engines, load_before, os.getloadavg())


def summarize(rows: list[dict], engines: list[str], load_before, load_after) -> None:
    print(f"\n{len(rows)} files; load average {load_before[0]:.2f} before, {load_after[0]:.2f} after")
    for engine in engines:
        statuses = [row[f"{engine}_status"] for row in rows]
        counts = {status: statuses.count(status) for status in sorted(set(statuses))}
        line = f"{engine:15s} " + ", ".join(f"{status} {count}" for status, count in counts.items())
        seconds = [s for row in rows for s in row.get(f"{engine}_seconds", [])]
        if seconds:
            line += f"; {1000 * np.mean(seconds):.2f} ms per layer-frame (median {1000 * np.median(seconds):.2f}, " \
                    f"{len(seconds)} layer-frames)"
        print(line)
    agreeing = [row for row in rows if (row.get("references_iou") or 0) >= AGREE]
    both = [row for row in rows if row.get("references_iou") is not None]
    if both:
        print(f"references agree (IoU >= {AGREE}) on {len(agreeing)} of the {len(both)} files both render")
    for engine in ("default", "rlottie-layers"):
        if any(f"{engine}_iou" in row for row in agreeing):
            right = [row for row in agreeing if (row.get(f"{engine}_iou") or 0) >= AGREE]
            print(f"{engine}: within IoU {AGREE} of both references on {len(right)} of {len(agreeing)} "
                  f"({100 * len(right) / len(agreeing):.1f} %)")
            for row in agreeing:
                if row not in right:
                    print(f"    {row['file']}: {row.get(f'{engine}_iou')} {row.get(f'{engine}_message', '')}")
    moving = [row for row in rows if row.get("thorvg_moving")]
    if moving:
        between = sum(1 for row in moving if row.get("thorvg_half_frame_between"))
        print(f"thorvg: a half frame differs from both neighbours on {between} of {len(moving)} moving files")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        child(sys.argv[2], Path(sys.argv[3]), int(sys.argv[4]), Path(sys.argv[5]))
    else:
        main()
