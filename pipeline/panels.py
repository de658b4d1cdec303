"""One scene layer stylized several ways and shown side by side: what ``ablate`` and ``compare`` share.

Each way (an ablation variant, another stylizer) is a *panel*: its stylized frames go to a
folder of their own, and the panels go, each under its label, into one video over the
exemplar's paper.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fluidymation.errors import InputError
from fluidymation.pipeline.layer_stages import layer_motion, stylize_layer
from fluidymation.pipeline.progress import progress
from fluidymation.pipeline.render import Options, render, scaled_plan
from fluidymation.pipeline.resolve import Plan, PlannedLayer, parse_window, plan_scene
from fluidymation.pipeline.scene import load_scene
from fluidymation.stages import colorize, encode
from fluidymation.stages.exemplar_store import StoredSource
from fluidymation.stages.files import read_image
from fluidymation.stages.labels import label_strip
from fluidymation.stages.stylizer import Stylizer


def add_layer_arguments(parser) -> None:
    """The arguments of a panels command: the scene, ``--layer``, ``--frames`` and ``--scale``."""
    parser.add_argument("scene", help="the scene's YAML file")
    parser.add_argument("--layer", required=True, metavar="NAME", help="the scene layer")
    parser.add_argument("--frames", metavar="A:B", help="only scene frames A to B (B exclusive)")
    parser.add_argument("--scale", type=float, default=1.0, metavar="S", help="render at S times the scene's size")


@dataclass(frozen=True)
class LayerPanels:
    """The layer a panels command stylizes: the plan (at ``--scale``), the frames, the output folder."""

    plan: Plan
    layer: PlannedLayer
    frames: range
    out: Path
    quiet: bool

    @classmethod
    def from_args(cls, args) -> LayerPanels:
        """The layer, frames and scale of :func:`add_layer_arguments`, checked (nothing rendered yet)."""
        if not 0 < args.scale <= 8:
            raise InputError(f"--scale {args.scale:g}: must be above 0 and at most 8")
        plan = scaled_plan(plan_scene(load_scene(args.scene), strict=args.strict), args.scale)
        return cls(plan, plan.layer(args.layer), plan.frames(parse_window(args.frames)), plan.scene.output.dir,
                   args.quiet)

    @property
    def coverage_dir(self) -> Path:
        return self.out / "coverage" / self.layer.dirname

    def render_masks(self) -> None:
        """The layer's masks, coverage and motion over the frames (from the stage cache when it has them)."""
        render(self.plan, Options(until="masks", layers=(self.layer.name,),
                                  window=(self.frames.start, self.frames.stop), quiet=self.quiet, report=False))

    def stylize(self, folder: Path, stylizer: Stylizer, params, source: StoredSource | None, guide_params) -> None:
        """The frames painted by ``stylizer`` with ``params`` into ``folder`` (``source``: the layer's exemplar,
        None for a stylizer that paints from keyframes)."""
        stylize_layer(self.plan, self.layer, self.frames, source, stylizer, params, guide_params,
                      coverage_dir=self.coverage_dir, out_dir=folder, quiet=self.quiet,
                      given_flow=layer_motion(self.out, self.layer))

    def read(self, folder: Path, frame: int) -> np.ndarray:
        """Scene frame ``frame`` of a panel, (H, W, 4) float32."""
        return read_image(folder / f"{frame - self.plan.start:05d}.png", channels=4)

    def write_video(self, video: Path, panels: list[tuple[str, Path]], paper: np.ndarray, *, description: str) -> None:
        """The panels (label, folder) side by side over ``paper``, each under its label, as an MP4."""
        captions = label_strip([label for label, _ in panels], width=self.plan.size[0])

        def side_by_side():
            with progress(len(self.frames), description, quiet=self.quiet) as bar:
                for frame in self.frames:
                    yield np.concatenate([np.concatenate([caption, over_paper(self.read(folder, frame), paper)])
                                          for (_, folder), caption in zip(panels, captions)], axis=1)
                    bar.update()

        encode.encode_mp4(side_by_side(), video, params=encode.Params(fps=self.plan.fps))


def paper_colour(source: StoredSource | None) -> np.ndarray:
    """(3,) float32: the exemplar's paper, white without one (keyframes)."""
    return np.ones(3, np.float32) if source is None else colorize.estimate_paper(source.rgb, source.segment)


def over_paper(rgba: np.ndarray, paper: np.ndarray) -> np.ndarray:
    """(H, W, 4) stylized paint over ``paper``, (H, W, 3)."""
    return rgba[..., :3] * rgba[..., 3:] + paper * (1 - rgba[..., 3:])
