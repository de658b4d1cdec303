"""``fluidymation check SCENE``: validate a scene and print what it resolves to."""

from __future__ import annotations

from fluidymation.pipeline.parameters import check_layer_params, layer_stylizer
from fluidymation.pipeline.resolve import Plan, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages.rasterize import ColorTally, Params, rasterize_frame


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "check", description="Validate SCENE and print its input (with the reader and renderer it uses), size, "
                             "fps, frame range and, per scene layer, the vector layers it selects, their fill "
                             "colour and z-order.")
    parser.add_argument("scene", help="the scene's YAML file")
    parser.set_defaults(run=run)


def run(args) -> int:
    plan = plan_scene(load_scene(args.scene), strict=args.strict)
    print(describe(plan))
    return 0


def describe(plan: Plan) -> str:
    scene, document, renderer = plan.scene, plan.document, plan.renderer
    native_fps = f"{document.native_fps:g} fps" if document.native_fps else "no frame rate"
    lines = [
        f"scene:   {scene.path}",
        f"input:   {scene.input} ({document.kind}, {document.width:g}x{document.height:g} px, {native_fps})",
        f"reader:  {document.reader} v{document.reader_version}, renderer {renderer.name} v{renderer.version}",
        *([f"picked:  {', '.join(f'{name} {value}' for name, value in document.choices.items())}"]
          if document.choices else []),
        f"size:    {plan.size[0]}x{plan.size[1]} px",
        f"fps:     {plan.fps:g}",
        f"frames:  {plan.start}:{plan.end} ({plan.frame_count} frames)",
        f"output:  {scene.output.dir}",
        f"vector layers (bottom to top): {', '.join(document.layer_names()) or '(none)'}",
        "scene layers (bottom to top):",
    ]
    params = Params(size=plan.size, fps=plan.fps)
    samples = sorted({plan.start, (plan.start + plan.end - 1) // 2, plan.end - 1})
    for layer in sorted(plan.layers, key=lambda layer: layer.z):
        tally = ColorTally()
        for frame in samples:
            tally.add(rasterize_frame(renderer, document, layer.vector_layers, frame, params).rgba)
        found = tally.dominant() or "none (never visible in the sampled frames)"
        color = f"{layer.spec.color} (set in the scene; file: {found})" if layer.spec.color else found
        stylizer = layer_stylizer(plan, layer)
        check_layer_params(plan, layer)
        keyframes = f", keyframes at frames {', '.join(str(f) for f, _ in layer.spec.keyframes)}" \
            if layer.spec.keyframes else ""
        lines.append(f"  {layer.name}: z={layer.z}, selects {', '.join(layer.vector_layers)}, colour {color}, "
                     f"stylizer {stylizer.name} v{stylizer.version}{keyframes}")
    return "\n".join(lines)
