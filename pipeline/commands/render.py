"""``fluidymation render SCENE``: the finished film, or the stages up to ``--until``."""

from __future__ import annotations

from fluidymation.errors import InputError
from fluidymation.pipeline.executors import LOCAL, dask_address
from fluidymation.pipeline.render import STAGE_NAMES, Options, render, scaled_plan
from fluidymation.pipeline.resolve import parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene

PREVIEW_SCALE = 0.5


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "render", description="Rasterize, stylize and colorize every layer, synthesize the paper, composite the layers "
                    "in z-order and encode the MP4 into the scene's output.dir, with report.json (timings "
                    "and cache hits per stage and layer). Work whose inputs and parameters are unchanged is "
                    "taken from the stage cache (output.dir/.cache). Stages in order: " + ", ".join(STAGE_NAMES) + ". Frame files are "
                    "numbered from the start of the scene's frame range. A killed render started again continues "
                    "from its last finished frame; renders of one scene running at once wait for and reuse each "
                    "other's work.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("--until", default=STAGE_NAMES[-1], metavar="STAGE",
                        help=f"last stage to run: {', '.join(STAGE_NAMES)} (default: {STAGE_NAMES[-1]})")
    parser.add_argument("--layer", action="append", metavar="NAME",
                        help="only (re-)render this layer (repeatable); the film is composited with the other "
                             "layers' earlier results")
    parser.add_argument("--frames", metavar="A:B", help="only scene frames A to B (B exclusive)")
    parser.add_argument("--scale", type=float, default=1.0, metavar="S",
                        help="render at S times the scene's size (e.g. 0.5)")
    parser.add_argument("--preview", action="store_true",
                        help=f"quick look: {PREVIEW_SCALE:g}x the size and a faster synthesis schedule, "
                             "into <output.dir>/preview/")
    parser.add_argument("--force", action="store_true", help="redo every stage, even those the cache holds")
    parser.add_argument("--force-stage", action="append", default=[], metavar="STAGE",
                        help="redo this stage even if the cache holds it (repeatable)")
    parser.add_argument("--nnf", action="store_true",
                        help="also save each frame's nearest-neighbour field as stylized/<layer>/nnf/00000.npy "
                             "((H, W, 4) float32: source frame, x, y, θ; frame -1 = no match)")
    parser.add_argument("--jobs", type=int, default=1, metavar="N",
                        help="render up to N layers at once in separate processes, sharing the CPU cores "
                             "(default: 1)")
    parser.add_argument("--executor", default=LOCAL, metavar="WHERE",
                        help="where the layers are rendered: local (default) or dask://HOST:PORT, an existing Dask "
                             "scheduler whose workers share the output folder (pip install "
                             "'fluidymation[distributed]')")
    parser.set_defaults(run=run)


def run(args) -> int:
    if args.until not in STAGE_NAMES:
        raise InputError(f"--until {args.until!r}: not a stage; choose one of {', '.join(STAGE_NAMES)}")
    if not 0 < args.scale <= 8:
        raise InputError(f"--scale {args.scale:g}: must be above 0 and at most 8")
    if args.jobs < 1:
        raise InputError(f"--jobs {args.jobs}: must be at least 1")
    dask_address(args.executor)  # a malformed address is refused before any work
    options = Options(until=args.until, layers=tuple(args.layer) if args.layer else None,
                      window=parse_window(args.frames), preview=args.preview, nnf=args.nnf, quiet=args.quiet,
                      force=args.force, force_stages=tuple(args.force_stage), jobs=args.jobs,
                      executor=args.executor)
    plan = plan_scene(load_scene(args.scene), strict=args.strict)
    plan = scaled_plan(plan, args.scale * (PREVIEW_SCALE if args.preview else 1.0))
    out = render(plan, options)
    if not args.quiet:
        done = out / plan.scene.output.video if args.until == STAGE_NAMES[-1] else out
        print(f"rendered {plan.size[0]}x{plan.size[1]}, up to {args.until}: {done}")
    return 0

