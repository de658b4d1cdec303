"""``fluidymation render SCENE --until STAGE``: run the per-layer stages up to STAGE.

Available stages, in order: ``masks`` (writes ``masks/<layer>/*.png``), ``guides``
(also views of the guidance channels in ``guides/<layer>/``) and ``stylize`` (masks and
``stylized/<layer>/*.png``, RGBA). Colorize, background, composite and encode do not
exist yet.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from fluidymation.errors import InputError
from fluidymation.pipeline.commands.guides import write_layer_guides
from fluidymation.pipeline.exemplars import layer_source, simulated_frame_count
from fluidymation.pipeline.parameters import check_layer_params, layer_guide_params, layer_stylize_params
from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.resolve import parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages.files import write_npy, write_png
from fluidymation.stages.rasterize import Params as RasterParams
from fluidymation.stages.rasterize import rasterize_frame
from fluidymation.stages.stylize import stylize_sequence

STAGES = ("masks", "guides", "stylize")
PLANNED_STAGES = ("colorize", "background", "composite", "encode")


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "render", help="render a scene's layers up to a stage (for now: masks, guides or stylize)",
        description="Run the per-layer stages of a scene up to --until: masks (masks/<layer>/00000.png ...), "
                    "guides (guides/<layer>/ views), stylize (masks, then stylized/<layer>/00000.png ... RGBA). "
                    "Files are numbered from the start of the scene's frame range. The later stages "
                    f"({', '.join(PLANNED_STAGES)}) do not exist yet.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("--until", default="stylize", metavar="STAGE",
                        help=f"last stage to run: {', '.join(STAGES)} (default: stylize); "
                             f"{', '.join(PLANNED_STAGES)} are not available yet")
    parser.add_argument("--layer", action="append", metavar="NAME", help="only this layer (repeatable)")
    parser.add_argument("--frames", metavar="A:B", help="only scene frames A to B (B exclusive)")
    parser.add_argument("--nnf", action="store_true",
                        help="also save each frame's nearest-neighbour field as stylized/<layer>/nnf/00000.npy "
                             "((H, W, 4) float32: source frame, x, y, θ; frame -1 = no match)")
    parser.set_defaults(run=run)


def run(args) -> int:
    if args.until in PLANNED_STAGES:
        raise InputError(f"--until {args.until}: the {args.until} stage does not exist yet; this version renders "
                         f"up to {STAGES[-1]} (choose one of {', '.join(STAGES)})")
    if args.until not in STAGES:
        raise InputError(f"--until {args.until!r}: not a stage; choose one of {', '.join(STAGES)}")
    plan = plan_scene(load_scene(args.scene))
    window = plan.frames(parse_window(args.frames))
    layers = [plan.layer(name) for name in args.layer] if args.layer else list(plan.layers)
    for layer in layers:
        check_layer_params(plan, layer)
    raster = RasterParams(size=plan.size, fps=plan.fps)
    out_dir = plan.scene.output.dir
    for layer in layers:
        def coverage(index, layer=layer):
            return rasterize_frame(plan.source, layer.vector_layers, plan.start + index, raster).coverage

        with progress(len(window), f"masks {layer.name}", quiet=args.quiet) as bar:
            for frame in window:
                write_png(out_dir / "masks" / layer.dirname / f"{frame - plan.start:05d}.png",
                          (coverage(frame - plan.start) > 0.5).astype(np.uint8) * 255)
                bar.update()
        if args.until == "guides":
            write_layer_guides(plan, layer, window, coverage, out_dir / "guides" / layer.dirname, quiet=args.quiet)
        elif args.until == "stylize":
            _stylize(plan, layer, window, coverage, args)
    if not args.quiet:
        print(f"rendered {len(layers)} layer(s), frames {window.start}:{window.stop}, up to {args.until}, "
              f"into {out_dir}")
    return 0


def stylize_layer(plan, layer, window, coverage, out_dir: Path, *, quiet=False, nnf=False, **overrides):
    """Stylize one layer over a window of scene frames into ``out_dir``; return the files written by index."""
    guide_params = layer_guide_params(plan, layer)
    params = layer_stylize_params(plan, layer, **overrides)
    with progress(simulated_frame_count(plan, layer), f"exemplar for {layer.name}", quiet=quiet) as bar:
        source = layer_source(plan, layer, guide_params, progress=bar.update)
    written = {}
    plan.scene.output.dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=".guides-", dir=plan.scene.output.dir) as cache_dir, \
            progress(len(window), f"stylize {layer.name}", quiet=quiet) as bar:
        frames = stylize_sequence(coverage, plan.frame_count, source, params=params, guide_params=guide_params,
                                  cache_dir=cache_dir, frames=(window.start - plan.start, window.stop - plan.start))
        for result in frames:
            path = out_dir / f"{result.index:05d}.png"
            write_png(path, result.rgba)
            if nnf:
                write_npy(out_dir / "nnf" / f"{result.index:05d}.npy", result.nnf.as_array())
            written[result.index] = path
            bar.update()
    return written


def _stylize(plan, layer, window, coverage, args):
    stylize_layer(plan, layer, window, coverage, plan.scene.output.dir / "stylized" / layer.dirname,
                  quiet=args.quiet, nnf=args.nnf)
