"""``fluidymation resynth CLIP -o OUT --frames N``: a new clip with a drawn clip's geometry and motion (seed 004).

The clip (a video, an image folder or a pattern such as ``frames/%04d.png``) is analysed
(its subject by ``--mask``, its grid-PatchMatch motion and geometry samples:
:mod:`fluidymation.stages.cartoon_clip`), then N frames are synthesized
(:mod:`fluidymation.stages.cartoon`), N possibly beyond the clip's length: the subject
follows the clip's global motion pattern, looping. OUT receives ``frames/0000.png …`` (RGBA,
the subject over transparency) and ``resynth.mp4`` (over the clip's paper colour). The
analysis and the last finished frame's state are kept in ``OUT/.resynth/``, so a run stopped
part way, or asked for more frames, goes on from the last finished frame; other parameters
or another clip start afresh. Parameters are those of ``stylizer: cartoon``
(configs/cartoon.yaml), set with ``--param NAME=VALUE``.
"""

from __future__ import annotations

import hashlib
import json
import logging
import shutil
from pathlib import Path

import numpy as np
import yaml

from fluidymation.errors import InputError
from fluidymation.pipeline.panels import over_paper
from fluidymation.pipeline.parameters import build_params, default_params
from fluidymation.pipeline.progress import progress, reporter
from fluidymation.stages import cartoon, cartoon_params, encode, exemplar_user
from fluidymation.stages.cartoon_clip import Clip, analyse_clip
from fluidymation.stages.files import atomic_path, read_image, write_png, write_text

log = logging.getLogger(__name__)

#: The most frames one run may be asked for.
MAX_FRAMES = 100_000


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "resynth", description="Synthesize a new clip of N frames with the geometry and motion of CLIP (a video, "
                               "an image folder or a pattern): OUT/frames/0000.png ... (RGBA) and OUT/resynth.mp4.")
    parser.add_argument("clip", metavar="CLIP", help="the drawn clip: a video, an image folder or a pattern")
    parser.add_argument("-o", "--output", required=True, metavar="OUT", help="output folder")
    parser.add_argument("--frames", required=True, type=int, metavar="N", help="frames to synthesize")
    parser.add_argument("--seed", type=int, metavar="S", help="random seed (default: configs/cartoon.yaml's, 0)")
    parser.add_argument("--mask", default="auto", metavar="auto|FOLDER",
                        help="the subject: found on the plain background (auto, the default), or one mask image "
                             "per clip frame (a folder or pattern)")
    parser.add_argument("--fps", type=float, default=24.0, help="frame rate of resynth.mp4 (default 24)")
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a cartoon parameter (configs/cartoon.yaml), e.g. --param temporal_size=5 (repeatable)")
    parser.set_defaults(run=run)


def resynth_params(args) -> cartoon.Params:
    """The defaults file's parameters with ``--seed`` and ``--param`` applied."""
    from fluidymation.stages.cartoon_stylizer import CartoonStylizer

    defaults = default_params(CartoonStylizer)
    values = {name: (getattr(defaults, name), None) for name in CartoonStylizer.parameter_names()}
    for item in args.param:
        name, sep, text = item.partition("=")
        if not sep or name not in values:
            known = ", ".join(CartoonStylizer.parameter_names())
            raise InputError(f"--param {item}: give NAME=VALUE with NAME one of {known}")
        values[name] = (yaml.safe_load(text), None)
    if args.seed is not None:
        values["seed"] = (args.seed, None)
    return build_params(cartoon.Params, values, fallback=None)


def run(args) -> int:
    if not 1 <= args.frames <= MAX_FRAMES:
        raise InputError(f"--frames must be between 1 and {MAX_FRAMES}, got {args.frames}")
    if not 0 < args.fps <= 1000:
        raise InputError(f"--fps must be a positive rate up to 1000, got {args.fps}")
    params = resynth_params(args)
    out = Path(args.output)
    state = out / ".resynth"
    recording = exemplar_user.load_user_exemplar(exemplar_user.Params(source=args.clip, mask=args.mask))
    key = _run_key(args, params)
    if _read_key(state) != key:  # another clip or other parameters: what is there is not this run's
        shutil.rmtree(out / "frames", ignore_errors=True)
        shutil.rmtree(state, ignore_errors=True)
        state.mkdir(parents=True)
        write_text(state / "key", key)
    clip = _clip(recording, params, args, state / "clip.npz")
    synthesis = cartoon.CartoonSynthesis(clip, params)
    path = cartoon.ResynthPath(clip, args.frames)
    previous = _resumed(state)
    done = 0 if previous is None else previous.index + 1
    if done >= args.frames:
        previous = None
    targets = ((index, path.target(index)) for index in range(done, args.frames))
    left = None
    with progress(max(args.frames - done, 0), "resynth", quiet=args.quiet) as bar:
        for frame in cartoon.synthesize_frames(synthesis, targets, previous):
            if left is None and not (frame.rgba[..., 3] >= 0.5).any():
                left = frame.index
                log.warning("%s: output frame %d: the subject has moved out of the frame along the clip's motion",
                            args.clip, frame.index)
            write_png(out / "frames" / f"{frame.index:04d}.png", cartoon.straight(frame.rgba))
            _save_state(state, frame)
            bar.update()
    video = out / "resynth.mp4"
    encode.encode_mp4((over_paper(read_image(out / "frames" / f"{index:04d}.png", channels=4), recording.paper)
                       for index in range(args.frames)), video, params=encode.Params(fps=args.fps))
    if not args.quiet:
        print(f"wrote {args.frames} frames to {out / 'frames'} and {video}")
    return 0


def _run_key(args, params: cartoon.Params) -> str:
    """What decides the frames: the clip's and masks' files (names, sizes, times) and the parameters."""
    stamps = [(str(p), p.stat().st_size, p.stat().st_mtime_ns) for spec in (args.clip, args.mask)
              if spec != "auto" for p in _files(spec)]
    text = json.dumps({"files": stamps, "mask": args.mask, "params": repr(params), "version": cartoon_params.VERSION})
    return hashlib.sha256(text.encode()).hexdigest()


def _files(spec: str) -> list[Path]:
    path = Path(spec)
    return [path] if path.is_file() else exemplar_user.image_sequence(spec)


def _read_key(state: Path) -> str | None:
    try:
        return (state / "key").read_text()
    except OSError:
        return None


def _clip(recording, params: cartoon.Params, args, path: Path) -> Clip:
    """The clip analysed, or read back from an earlier run of the same key."""
    if path.is_file():
        return Clip.load(path)
    with progress(len(recording.rgb) - 1, "motion", quiet=args.quiet) as bar:
        clip = analyse_clip(recording.rgb, recording.mask, name=args.clip, motion=params.motion, seed=params.seed,
                            progress=reporter(bar))
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        clip.save(handle)
    return clip


def _save_state(state: Path, frame: cartoon.CartoonFrame) -> None:
    with atomic_path(state / "last.npz") as tmp, open(tmp, "wb") as handle:
        np.savez(handle, index=frame.index, rgba=frame.rgba, frame=frame.nnf.frame, coords=frame.nnf.coords,
                 history=frame.history)


def _resumed(state: Path) -> cartoon.CartoonFrame | None:
    """The last finished frame's state, saved after its PNG (None before the first)."""
    from fluidymation.engine.nnf import NNF

    if not (state / "last.npz").is_file():
        return None
    with np.load(state / "last.npz") as stored:
        return cartoon.CartoonFrame(int(stored["index"]), stored["rgba"], NNF(stored["frame"], stored["coords"]),
                                    stored["history"])
