"""``fluidymation check SCENE``: validate a scene and print what it resolves to."""

from __future__ import annotations

from fluidymation.pipeline import paths
from fluidymation.pipeline.cache import stage_key
from fluidymation.pipeline.parameters import check_layer_params, layer_stylizer
from fluidymation.pipeline.resolve import Plan, PlannedLayer, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages.files import write_text
from fluidymation.stages.rasterize import ColorTally, Params, rasterize_frame

#: Version of the remembered fill colours (raise it when :func:`file_colour` would find others).
COLOUR_VERSION = 1


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
    for layer in sorted(plan.layers, key=lambda layer: layer.z):
        found = file_colour(plan, layer) or "none (never visible in the sampled frames)"
        color = f"{layer.spec.color} (set in the scene; file: {found})" if layer.spec.color else found
        stylizer = layer_stylizer(plan, layer)
        check_layer_params(plan, layer)
        keyframes = f", keyframes at frames {', '.join(str(f) for f, _ in layer.spec.keyframes)}" \
            if layer.spec.keyframes else ""
        lines.append(f"  {layer.name}: z={layer.z}, selects {', '.join(layer.vector_layers)}, colour {color}, "
                     f"stylizer {stylizer.name} v{stylizer.version}{keyframes}")
    return "\n".join(lines)


def file_colour(plan: Plan, layer: PlannedLayer) -> str | None:
    """The layer's dominant fill ('#rrggbb') over its first, middle and last frames, or None when it never shows.

    Drawing loads the renderer (cairo takes longer to load than the rest of ``check``), so the answer is kept in
    the user cache under everything it depends on: an unchanged input is not drawn again when a scene is edited.
    """
    samples = sorted({plan.start, (plan.start + plan.end - 1) // 2, plan.end - 1})
    key = stage_key("check-colour", COLOUR_VERSION, drawing=plan.drawing_record(), layers=layer.vector_layers,
                    frames=samples, size=plan.size, fps=plan.fps)
    remembered = paths.cache_dir() / "check-colours" / key
    if remembered.is_file():
        return remembered.read_text() or None
    params, tally = Params(size=plan.size, fps=plan.fps), ColorTally()
    for frame in samples:
        tally.add(rasterize_frame(plan.renderer, plan.document, layer.vector_layers, frame, params).rgba)
    found = tally.dominant()
    try:
        remembered.parent.mkdir(parents=True, exist_ok=True)
        write_text(remembered, found or "")
    except OSError:  # a read-only cache only costs the next check its drawing
        pass
    return found
