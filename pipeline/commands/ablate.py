"""``fluidymation ablate SCENE --layer NAME``: the paper's ablation study on one layer.

The layer is stylized once per variant of its stylizer's ablation study
(:attr:`~fluidymation.stages.stylizer.Stylizer.ablation`): for ``fluidymation``, the full
energy and each term switched off (the weight set to 0): bound, dir, ext, temp, uni, and
dir+bound together. The results go side by side, labelled, into one video, so the part
each term plays can be seen.
"""

from __future__ import annotations

import dataclasses

from fluidymation.errors import InputError
from fluidymation.pipeline.panels import LayerPanels, add_layer_arguments, paper_colour
from fluidymation.pipeline.parameters import layer_guide_params, layer_stylize_params, layer_stylizer
from fluidymation.pipeline.render import load_layer_source


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "ablate", description="Stylize one layer once per variant of its stylizer's ablation study (fluidymation: the "
                    "full energy and each term switched off: bound, dir, ext, temp, uni, dir+bound), write each version to <output.dir>/ablate/<layer>/<variant>/ and a "
                    "labelled side-by-side video <output.dir>/ablate/<layer>.mp4. A term whose weight is already "
                    "0 for the layer gives no panel of its own.")
    add_layer_arguments(parser)
    parser.set_defaults(run=run)


def run(args) -> int:
    layers = LayerPanels.from_args(args)
    plan, layer = layers.plan, layers.layer
    stylizer = layer_stylizer(plan, layer)
    if not stylizer.ablation:
        raise InputError(f"layer '{layer.name}': the stylizer '{stylizer.name}' defines no ablation study")
    layers.render_masks()
    guide_params = layer_guide_params(plan, layer)
    full = layer_stylize_params(plan, layer)
    source = None if stylizer.uses_keyframes else load_layer_source(plan, layer, guide_params, args.quiet)
    panels, skipped = [], []
    for label, switched_off in stylizer.ablation:
        if switched_off and all(getattr(full, name) == 0 for name in switched_off):
            skipped.append(label)
            continue
        folder = layers.out / "ablate" / layer.dirname / label.replace(" ", "-").replace("+", "-")
        layers.stylize(folder, stylizer, dataclasses.replace(full, **{name: 0.0 for name in switched_off}), source,
                       guide_params)
        panels.append((label, folder))
    video = layers.out / "ablate" / f"{layer.dirname}.mp4"
    layers.write_video(video, panels, paper_colour(source), description="ablation video")
    if not args.quiet:
        note = f" ({', '.join(skipped)}: the weight is already 0, same as full)" if skipped else ""
        print(f"wrote {len(panels)} versions of layer {layer.name} side by side to {video}{note}")
    return 0
