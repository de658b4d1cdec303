"""``fluidymation synth``: single-image guided synthesis with EbSynth's options.

``--style S.png --guide SRC.png TGT.png [--weight W] ... -o OUT.png`` synthesizes an
image with the target guides' layout and the style's look. Values keep EbSynth's units
and defaults: colours count in 0..255 for the uniformity weight and the reported error;
``--weight`` applies to the preceding ``--style`` or ``--guide``; the style weight
(default 1) and each guide's weight (default 1/number of guides) are spread evenly over
their channels; grey images count as one channel.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from fluidymation.engine.synthesis import SynthesisInputs, SynthesisParams, synthesize
from fluidymation.errors import InputError
from fluidymation.stages.files import read_image, write_npy, write_png

#: EbSynth compares 8-bit values; the engine compares values in [0, 1].
_EBSYNTH_SCALE = 255.0 ** 2


class _Style(argparse.Action):
    def __call__(self, parser, namespace, value, option_string=None):
        namespace.style = value
        namespace.weight_slot = ("style", None)


class _Guide(argparse.Action):
    def __call__(self, parser, namespace, values, option_string=None):
        guides = list(namespace.guides or [])
        guides.append([values[0], values[1], None])
        namespace.guides = guides
        namespace.weight_slot = ("guide", len(guides) - 1)


class _Weight(argparse.Action):
    def __call__(self, parser, namespace, value, option_string=None):
        slot = getattr(namespace, "weight_slot", None)
        if slot is None:
            parser.error("--weight must follow a --style or --guide option")
        if value < 0:
            parser.error(f"--weight must be non-negative, got {value}")
        if slot[0] == "style":
            namespace.style_weight = value
        else:
            namespace.guides[slot[1]][2] = value


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "synth", description="Synthesize OUT with the layout of the target guides and the look of the style "
                    "(EbSynth's options and defaults; --weight applies to the preceding --style or --guide).",
    )
    parser.add_argument("--style", required=True, metavar="S.png", action=_Style, help="style exemplar")
    parser.add_argument("--guide", nargs=2, metavar=("SRC.png", "TGT.png"), action=_Guide, dest="guides",
                        help="a source guide aligned with the style and its target counterpart (repeatable)")
    parser.add_argument("--weight", type=float, metavar="W", action=_Weight, dest="weight_value",
                        help="weight of the preceding --style (default 1) or --guide (default 1/#guides)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.png", help="output image")
    parser.add_argument("--patch-size", type=int, default=5, metavar="N", help="odd patch side (default 5)")
    parser.add_argument("--uniformity", type=float, default=3500.0, metavar="U",
                        help="uniformity weight in EbSynth's units (default 3500; 0 disables)")
    parser.add_argument("--pyramid-levels", type=int, metavar="N", help="pyramid levels (default: as many as fit)")
    parser.add_argument("--search-vote-iters", type=int, default=6, metavar="N",
                        help="search-vote iterations per level (default 6)")
    parser.add_argument("--patchmatch-iters", type=int, default=4, metavar="N",
                        help="PatchMatch iterations per search (default 4)")
    parser.add_argument("--search-alpha", type=float, default=0.5, metavar="A",
                        help="shrink factor of the random-search radius (default 0.5, as EbSynth)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--nnf", metavar="OUT.npy",
                        help="also save the final NNF, (H, W, 4) float32: frame, x, y, rotation")
    parser.add_argument("--report", action="store_true", help="print the final mean patch error and the time")
    parser.set_defaults(run=run, guides=None, style_weight=None, weight_slot=None)


def _channels(image):
    """Drop an all-opaque alpha and collapse grey RGB to one channel, as EbSynth does."""
    if image.shape[2] in (2, 4) and (image[:, :, -1] >= 1.0).all():
        image = image[:, :, :-1]
    if image.shape[2] == 3 and (image[:, :, 0] == image[:, :, 1]).all() and (image[:, :, 1] == image[:, :, 2]).all():
        image = image[:, :, :1]
    return image


def _check_options(args):
    if args.patch_size < 3 or args.patch_size % 2 == 0:
        raise InputError(f"--patch-size must be an odd number ≥ 3, got {args.patch_size}")
    if args.pyramid_levels is not None and args.pyramid_levels < 1:
        raise InputError(f"--pyramid-levels must be ≥ 1, got {args.pyramid_levels}")
    if args.search_vote_iters < 0 or args.patchmatch_iters < 0:
        raise InputError("--search-vote-iters and --patchmatch-iters must be ≥ 0")
    if args.uniformity < 0:
        raise InputError(f"--uniformity must be ≥ 0, got {args.uniformity}")
    if not 0.0 < args.search_alpha < 1.0:
        raise InputError(f"--search-alpha must lie strictly between 0 and 1, got {args.search_alpha}")
    if args.seed < 0:
        raise InputError(f"--seed must be ≥ 0, got {args.seed}")
    if not args.guides:
        raise InputError("give at least one --guide SRC.png TGT.png pair")


def load_job(args):
    """Read the style and guides into :class:`SynthesisInputs` with EbSynth's weighting."""
    style = _channels(read_image(args.style))
    source_height, source_width = style.shape[:2]
    style_weight = 1.0 if args.style_weight is None else args.style_weight
    source_guides, target_guides, guide_weights = [], [], []
    target_size = None
    for source_path, target_path, weight in args.guides:
        source = read_image(source_path)
        target = read_image(target_path)
        if source.shape[:2] != (source_height, source_width):
            raise InputError(f"{source_path}: source guide is {source.shape[1]}×{source.shape[0]}, "
                             f"but the style {args.style} is {source_width}×{source_height}")
        if target_size is None:
            target_size = target.shape[:2]
        elif target.shape[:2] != target_size:
            raise InputError(f"{target_path}: target guide is {target.shape[1]}×{target.shape[0]}, "
                             f"but the first target guide is {target_size[1]}×{target_size[0]}")
        channels = max(_channels(source).shape[2], _channels(target).shape[2])
        source = source if channels == source.shape[2] else read_image(source_path, channels=channels)
        target = target if channels == target.shape[2] else read_image(target_path, channels=channels)
        weight = 1.0 / len(args.guides) if weight is None else weight
        source_guides.append(source)
        target_guides.append(target)
        guide_weights += [weight / channels] * channels
    return SynthesisInputs(
        source_colour=style[None],
        source_guides=np.concatenate(source_guides, axis=2)[None],
        target_guides=np.concatenate(target_guides, axis=2),
        colour_weights=np.full(style.shape[2], style_weight / style.shape[2], np.float32),
        guide_weights=np.asarray(guide_weights, np.float32),
    )


def run(args) -> int:
    _check_options(args)
    started = time.perf_counter()
    inputs = load_job(args)
    params = SynthesisParams(
        patch_size=args.patch_size,
        pyramid_levels=args.pyramid_levels,
        search_vote_iters=(args.search_vote_iters,),
        patchmatch_iters=(args.patchmatch_iters,),
        alpha=args.search_alpha,
        uniformity_weight=args.uniformity / _EBSYNTH_SCALE,
        seed=args.seed,
    )
    result = synthesize(inputs, params)
    image = result.image[:, :, 0] if result.image.shape[2] == 1 else result.image
    write_png(args.output, np.clip(image, 0.0, 1.0))
    if args.nnf:
        write_npy(args.nnf, result.nnf.as_array())
    if args.report:
        error = result.mean_error()
        print(f"mean patch error: {error * _EBSYNTH_SCALE:.1f} (0..255 units; {error:.6f} in 0..1 units)")
        print(f"time: {time.perf_counter() - started:.1f} s")
    elif not args.quiet:
        print(f"wrote {args.output}", file=sys.stderr)
    return 0
