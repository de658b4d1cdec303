"""What a stylizer implements: the plugin contract of the ``stylize`` stage.

A stylizer turns a layer's coverage sequence and its exemplar into painted RGBA frames.
Stylizers are found through the ``fluidymation.stylizers`` entry-point group (see
docs/extending.md); a scene layer's ``stylizer:`` names one. Each brings:

* ``name`` (the scene's ``stylizer:`` value) and ``version`` (part of the stylize key:
  raise it whenever the same inputs would give other frames);
* ``Params``, a frozen dataclass of its parameters, and ``defaults``, the YAML file of
  their defaults (a ``params:`` mapping and an optional ``preview:`` one with the quicker
  values of ``render --preview``). The scene's ``params:`` may set any field of
  ``Params``; a field named ``seed`` takes the scene's seed unless a layer sets it;
* :meth:`Stylizer.stylize`, a generator of :class:`StylizedFrame` objects (such as
  :class:`Frame`), one per frame as soon as it is done, given a :class:`StylizeJob`;
* the format of its per-frame state, so an interrupted render continues from its last
  finished frame (:meth:`Stylizer.frame_state`, :meth:`Stylizer.resume_from`).
* optionally, the engine modules whose kernels :meth:`Stylizer.warm_up` compiles, so a first
  render compiles them in a helper process alongside (``warm_up_modules``).

The exemplar comes from :mod:`fluidymation.stages.exemplar_store`.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, ClassVar, Iterator, NamedTuple, Protocol

import numpy as np

from fluidymation.stages.guide_params import Params as GuideParams

if TYPE_CHECKING:
    from importlib.resources.abc import Traversable

    from fluidymation.stages.exemplar_store import StoredSource


class StylizedFrame(Protocol):
    """What a stylizer yields per frame: ``index`` (in the layer's sequence), ``rgba``
    (H, W, 4) float32 in [0, 1] with the coverage as alpha, and ``nnf`` (an
    :class:`~fluidymation.engine.nnf.NNF`, or None when the stylizer has none)."""

    index: int
    rgba: np.ndarray
    nnf: Any


class Frame(NamedTuple):
    """The simplest :class:`StylizedFrame`: a frame's index and RGBA, without an NNF."""

    index: int
    rgba: np.ndarray
    nnf: Any = None


@dataclass(frozen=True)
class StylizeJob:
    """One layer's stylize work.

    ``masks(j)`` gives frame j's (H, W) float32 coverage in [0, 1] for j in
    ``0..frame_count−1``; ``frames`` = (first, stop) are the frames to yield; ``source``
    is the layer's exemplar with its guides, made with ``guide_params``; ``cache_dir`` is
    a scratch folder for the length of the job; ``resume`` is None or what
    :meth:`Stylizer.resume_from` made of the state of the last finished frame;
    ``given_flow(j)``, when set, is frame j's motion read from the vector geometry (NaN where
    unknown; docs/guides.md), for the guides in place of the masks' estimate;
    ``keyframes`` maps frame indices to the layer's painted keyframe images (for a stylizer
    that :attr:`~Stylizer.uses_keyframes`); ``work_dir`` is a folder that outlives an
    interrupted run under the same stage key (for work finer than frames); ``map_tasks(f,
    arguments)`` gives ``[f(*args) for args in arguments]``, maybe in other processes (``f``
    module-level, its arguments picklable); ``colours(j)`` gives frame j's straight colour of the
    layer's own fills, (H, W, 3) float32; ``segments`` and ``segment_map`` are the layer's keys of
    those names (its regions, for a stylizer matching regions); ``layer`` its name, for messages.
    """

    masks: Callable[[int], np.ndarray]
    frame_count: int
    frames: tuple[int, int]
    source: StoredSource
    guide_params: GuideParams
    cache_dir: str
    resume: Any = None
    given_flow: Callable[[int], np.ndarray] | None = None
    keyframes: dict[int, Path] = dataclasses.field(default_factory=dict)
    work_dir: str | None = None
    map_tasks: Callable[[Callable, list[tuple]], list] | None = None
    colours: Callable[[int], np.ndarray] | None = None
    segments: str = "by-color"
    segment_map: tuple[tuple[str, str], ...] = ()
    layer: str = ""

    def motion(self) -> Callable[[int], np.ndarray]:
        """``flow(j)``: the layer's motion into frame j as its guides see it (``given_flow`` where known, else the
        masks' estimate), the guides computed once into the scratch folder."""
        from fluidymation.stages import guides  # numerical code: not imported for checking a scene

        cache = guides.compute_guides(self.masks, self.frame_count, params=self.guide_params,
                                      cache_dir=Path(self.cache_dir) / "guides", given_flow=self.given_flow)
        return lambda j: cache.read("flow", j)


class Stylizer(ABC):
    """Base of the stylizer plugins (see the module docstring)."""

    name: ClassVar[str]
    version: ClassVar[int]
    Params: ClassVar[type]
    defaults: ClassVar[Traversable | None] = None
    #: Whether the layer's guide parameters (``blur_sigma``, ``border_width`` …) mean anything to it.
    uses_guides: ClassVar[bool] = True
    #: Whether it paints from the layer's ``keyframes:`` (then it needs them) rather than from an exemplar.
    uses_keyframes: ClassVar[bool] = False
    #: The layer's ``colorize:`` when the scene sets none.
    default_colorize: ClassVar[str] = "layer"
    #: Whether its frames carry an NNF (``render --nnf``).
    writes_nnf: ClassVar[bool] = False
    #: The ablation study (``fluidymation ablate``): (label, parameters set to 0), the full energy first.
    ablation: ClassVar[tuple[tuple[str, tuple[str, ...]], ...]] = ()
    #: The engine modules (``fluidymation.engine.…``) whose kernels :meth:`warm_up` compiles. A first render
    #: (numba's disk cache empty) runs the warm-up in a helper process meanwhile (pipeline/compile_helper.py). Empty: none.
    warm_up_modules: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def parameter_names(cls) -> tuple[str, ...]:
        """The scene ``params:`` keys it accepts: the fields of its ``Params``."""
        return tuple(field.name for field in dataclasses.fields(cls.Params))

    def processing_order(self, frames: range, params) -> list[int]:
        """The frame indices of ``frames`` in the order :meth:`stylize` yields them (default: ascending)."""
        return list(frames)

    @abstractmethod
    def stylize(self, job: StylizeJob, params) -> Iterator[StylizedFrame]:
        """Yield the frames ``job.frames`` in :meth:`processing_order`, continuing after ``job.resume`` if given."""

    def frame_state(self, frame: StylizedFrame) -> dict[str, np.ndarray]:
        """What a resumed run needs of a finished ``frame``, as named arrays (saved atomically beside the frames)."""
        return {}

    def resume_from(self, index: int, state: dict[str, np.ndarray]) -> Any:
        """``job.resume`` for continuing after frame ``index`` from its :meth:`frame_state`."""
        return index

    def warm_up(self, params, folder: Path) -> None:
        """Stylize a tiny made-up layer with ``params`` (scratch files in ``folder``), compiling the kernels
        :meth:`stylize` runs (:mod:`fluidymation.stages.warm_up`; for an exemplar stylizer)."""
        from fluidymation.stages.warm_up import tiny_job  # numerical code: not imported for checking a scene

        for _ in self.stylize(tiny_job(folder), params):
            pass
