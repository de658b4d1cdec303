"""``fluidymation ablate SCENE --layer NAME``: the paper's ablation study on one layer.

The layer is stylized once per variant of its stylizer's ablation study
(:attr:`~fluidymation.stages.stylizer.Stylizer.ablation`): for ``fluidymation``, the full
energy and each term switched off (the weight set to 0): bound, dir, ext, temp, uni, and
dir+bound together. The results go side by side, labelled, into one video, so the part
each term plays can be seen.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from fluidymation.errors import InputError
from fluidymation.pipeline.layer_stages import layer_motion, stylize_layer
from fluidymation.pipeline.parameters import layer_guide_params, layer_stylize_params, layer_stylizer
from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.render import Options, load_layer_source, render, scaled_plan
from fluidymation.pipeline.resolve import parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages import colorize, encode
from fluidymation.stages.files import read_image
from fluidymation.stages.labels import label_strip


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "ablate", help="render a layer with each energy term switched off, side by side",
        description="Stylize one layer once per variant of its stylizer's ablation study (fluidymation: the "
                    "full energy and each term switched off: bound, dir, ext, temp, uni, dir+bound), write each version to <output.dir>/ablate/<layer>/<variant>/ and a "
                    "labelled side-by-side video <output.dir>/ablate/<layer>.mp4. A term whose weight is already "
                    "0 for the layer gives no panel of its own.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("--layer", required=True, metavar="NAME", help="the scene layer")
    parser.add_argument("--frames", metavar="A:B", help="only scene frames A to B (B exclusive)")
    parser.add_argument("--scale", type=float, default=1.0, metavar="S", help="render at S times the scene's size")
    parser.set_defaults(run=run)


def run(args) -> int:
    if not 0 < args.scale <= 8:
        raise InputError(f"--scale {args.scale:g}: must be above 0 and at most 8")
    plan = scaled_plan(plan_scene(load_scene(args.scene), strict=args.strict), args.scale)
    layer = plan.layer(args.layer)
    window = parse_window(args.frames)
    out = render(plan, Options(until="masks", layers=(layer.name,), window=window, quiet=args.quiet,
                                 report=False))
    frames = plan.frames(window)
    stylizer = layer_stylizer(plan, layer)
    if not stylizer.ablation:
        raise InputError(f"layer '{layer.name}': the stylizer '{stylizer.name}' defines no ablation study")
    guide_params = layer_guide_params(plan, layer)
    full = layer_stylize_params(plan, layer)
    source = None if stylizer.uses_keyframes else load_layer_source(plan, layer, guide_params, args.quiet)
    paper = np.ones(3, np.float32) if source is None else colorize.estimate_paper(source.rgb, source.segment)
    panels, skipped = [], []
    for label, switched_off in stylizer.ablation:
        if switched_off and all(getattr(full, name) == 0 for name in switched_off):
            skipped.append(label)
            continue
        params = dataclasses.replace(full, **{name: 0.0 for name in switched_off})
        folder = out / "ablate" / layer.dirname / label.replace(" ", "-").replace("+", "-")
        stylize_layer(plan, layer, frames, source, stylizer, params, guide_params,
                      coverage_dir=out / "coverage" / layer.dirname, out_dir=folder, quiet=args.quiet,
                      given_flow=layer_motion(out, layer))
        panels.append((label, folder))
    video = out / "ablate" / f"{layer.dirname}.mp4"
    labels = label_strip([label for label, _ in panels], width=plan.size[0])

    def side_by_side():
        with progress(len(frames), "ablation video", quiet=args.quiet) as bar:
            for frame in frames:
                name = f"{frame - plan.start:05d}.png"
                tiles = []
                for (_, folder), caption in zip(panels, labels):
                    rgba = read_image(folder / name, channels=4)
                    tiles.append(np.concatenate([caption, rgba[..., :3] * rgba[..., 3:] + paper * (1 - rgba[..., 3:])]))
                bar.update()
                yield np.concatenate(tiles, axis=1)

    encode.encode_mp4(side_by_side(), video, params=encode.Params(fps=plan.fps))
    if not args.quiet:
        note = f" ({', '.join(skipped)}: the weight is already 0, same as full)" if skipped else ""
        print(f"wrote {len(panels)} versions of layer {layer.name} side by side to {video}{note}")
    return 0
