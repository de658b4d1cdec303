"""The flow-guided keyframe morph (seed 003; docs/keyframes.md).

Every frame T_m of the layer is synthesized to minimise (eq. 6.1)

    E = Σ_m [ Σ_n ŵ(m, n) d(T_m, S_n) + β d(T_m, T_{m−1}) + β d(T_m, T_{m+1}) ]

where S_n are the keyframes, ŵ their weights (:func:`~fluidymation.stages.keyframes.keyframe_weights`)
and d the bidirectional similarity (completeness + coherence, each a mean patch distance)
of premultiplied RGBA with the layer's coverage as a guide. Per pyramid level, coarsest
first: an initialization votes, for every frame, the keyframe patches at the positions its
pixels reach by following the layer's flow (section 5; on finer levels merged per pixel
with the coarser level's matches); then sweeps, each a few search–vote iterations per
frame: PatchMatch to the keyframes from the previous matches, and to the neighbouring
frames only within a window of width p_ij around the advected position (the motion prior,
velocity-modulated by γ, eq. 6.2).

Schedules: ``jacobi`` (section 7) reads the neighbours from the previous sweep, so a
sweep's frames are independent tasks (run by the job's ``map_tasks``: local processes or
Dask); ``sequential`` alternates forward and backward sweeps that read the neighbour just
updated. Every task is a module-level function of files in the work folder, seeded by its
(pass, level, sweep, frame), and writes its result atomically: the bytes do not depend on
the number of workers, and a killed run continues from the tasks it finished.

The two-pass morph (section 7): pass 1 with ``blend`` weights and an unmodulated prior;
pass 2 takes every pass-1 frame as a keyframe, with the layer's weighting, radius and γ,
at full resolution from the pass-1 frames.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
from scipy import ndimage

from fluidymation.engine.morph import scatter_vote, window_search
from fluidymation.engine.nnf import NNF, fill_random, merge_nnf, upscale_nnf
from fluidymation.engine.patch_cost import build_patch_cost, patch_errors
from fluidymation.engine.patchmatch import patchmatch_pass
from fluidymation.engine.pyramid import downsample
from fluidymation.engine.vote import vote
from fluidymation.stages import keyframes as kf
from fluidymation.stages.files import atomic_path
from fluidymation.stages.keyframe_params import Params

log = logging.getLogger(__name__)

#: Coverage above which a pixel is the layer's (its segments grow from there by the patch radius).
_INSIDE = 0.01
#: Extra PatchMatch passes when the energy is evaluated, so it measures the frames rather than the search.
EVALUATION_PASSES = 6


@dataclass(frozen=True)
class Pass:
    """One morph pass: its keys (frame indices), where their full-resolution RGBA lies, the weighting,
    the prior's modulation, and the pyramid levels it runs (``levels`` − 1 down to 0)."""

    index: int
    keys: tuple[int, ...]
    key_dir: str
    weighting: str
    radius: int
    gamma: float
    levels: int
    initial_dir: str | None = None  # full-resolution frames to start from (pass 2: pass 1's), else advection


@dataclass(frozen=True)
class Context:
    """What every task of a pass reads: the work folder, the parameters, the pass and the sequence's size."""

    root: str
    params: Params
    stage: Pass
    frame_count: int
    shape: tuple[int, int]


@dataclass(frozen=True)
class Task:
    """One frame's work in one sweep (sweep 0: the level's initialization). ``neighbours`` are the state
    files of frames m − 1 and m + 1 to read (None at the sequence's ends)."""

    frame: int
    level: int
    sweep: int
    out: str
    current: str | None = None
    neighbours: tuple[str | None, str | None] = (None, None)


# --- the work folder -------------------------------------------------------------------------------------------

def _name(frame: int) -> str:
    return f"{frame:05d}"


def mask_path(root, frame: int) -> Path:
    return Path(root) / "masks" / f"{_name(frame)}.npy"


def step_path(root, frame: int) -> Path:
    return Path(root) / "steps" / f"{_name(frame)}.npz"


def map_path(root, stage: int, frame: int, key: int) -> Path:
    return Path(root) / f"pass{stage}" / "maps" / f"{_name(frame)}-{_name(key)}.npy"


def state_path(root, stage: int, level: int, sweep: int, frame: int) -> Path:
    return Path(root) / f"pass{stage}" / f"level{level}" / f"sweep{sweep}" / f"{_name(frame)}.npz"


def output_path(root, stage: int, frame: int) -> Path:
    return Path(root) / f"pass{stage}" / "out" / f"{_name(frame)}.npy"


def _save(path: Path, **arrays) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        np.savez(handle, **arrays)


def _save_array(path: Path, array: np.ndarray) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        np.save(handle, array)


def _load(path) -> dict:
    with np.load(path) as data:
        return dict(data)


# --- levels ----------------------------------------------------------------------------------------------------

def level_count(shape: tuple[int, int], params: Params) -> int:
    """The pyramid levels of the first pass: ``params.levels``, or as many as keep the shorter side ≥ 32 px."""
    if params.levels:
        return params.levels
    count, side = 1, min(shape)
    while side >= 64 and count < 6:
        side = (side + 1) // 2
        count += 1
    return count


def at_level(values: np.ndarray, level: int) -> np.ndarray:
    """An image (H, W) or (H, W, C) blurred and halved ``level`` times."""
    for _ in range(level):
        values = downsample(values)
    return np.ascontiguousarray(values, np.float32)


def positions_at_level(positions: np.ndarray, level: int, shape: tuple[int, int]) -> np.ndarray:
    """A full-resolution position map (H, W, 2) read on level ``level``'s grid of ``shape``, in that level's px."""
    if level == 0:
        return positions
    factor = float(2 ** level)
    grid = np.minimum(kf.identity(shape) * factor, np.array(positions.shape[1::-1], np.float32) - 1)
    return kf.sample(positions, grid) / np.float32(factor)


def _segment(coverage: np.ndarray, reach: int) -> np.ndarray:
    """Label 0 within ``reach`` px of the layer's pixels, −1 elsewhere."""
    inside = ndimage.binary_dilation(coverage > _INSIDE, iterations=reach) if reach else coverage > _INSIDE
    return np.where(inside, 0, -1).astype(np.int32)


def _prior_radius(speed: np.ndarray, coverage: np.ndarray, prior_size: int, gamma: float) -> np.ndarray:
    """Half-width of the motion prior's window per pixel: p_ij = (1 − γ) p + γ |v| / max |v| · p (eq. 6.2)."""
    inside = coverage > _INSIDE
    fastest = float(speed[inside].max()) if inside.any() else float(speed.max())
    share = speed / fastest if fastest > 0 else np.zeros_like(speed)
    width = (1.0 - gamma) * prior_size + gamma * share * prior_size
    return np.maximum(np.floor((width - 1.0) / 2.0 + 0.5), 0).astype(np.int64)


# --- one frame -------------------------------------------------------------------------------------------------

class _Frame:
    """Frame m of a pass at one level: its coverage, keys, key weights and motion, read from the work folder."""

    def __init__(self, context: Context, frame: int, level: int):
        self.context, self.frame, self.level = context, frame, level
        root, stage, params = context.root, context.stage, context.params
        self.coverage = at_level(np.load(mask_path(root, frame)), level)
        self.shape = self.coverage.shape
        self.reach = params.patch_size // 2
        self.segment = _segment(self.coverage, self.reach)
        self.weights = kf.keyframe_weights(frame, list(stage.keys), stage.weighting, stage.radius)
        self.keys = {key: self._key(key) for key in self.weights}
        self.maps = {key: positions_at_level(np.load(map_path(root, stage.index, frame, key)), level, self.shape)
                     for key in self.weights}

    def _key(self, key: int):
        colour = at_level(np.load(Path(self.context.stage.key_dir) / f"{_name(key)}.npy"), self.level)
        return colour, _segment(colour[..., 3], self.reach)

    def steps(self, frame: int):
        """Frame ``frame``'s back and forward positions (this level's px) and its prior radius."""
        steps = _load(step_path(self.context.root, frame))
        coverage = self.coverage if frame == self.frame else at_level(np.load(mask_path(self.context.root, frame)),
                                                                        self.level)
        speed = at_level(steps["speed"], self.level) / np.float32(2 ** self.level)
        radius = _prior_radius(speed, coverage, self.context.params.prior_size, self.context.stage.gamma)
        return (positions_at_level(steps["back"], self.level, self.shape),
                positions_at_level(steps["forward"], self.level, self.shape), radius)

    def cost(self, source, source_segment, target, target_segment, source_cover, target_cover):
        params = self.context.params
        return build_patch_cost(
            source_colour=source[None], source_guides=source_cover[None, ..., None], target_colour=target,
            target_guides=target_cover[..., None], colour_weights=np.ones(4, np.float32),
            guide_weights=np.array([params.mask_weight], np.float32), source_segment=source_segment[None],
            target_segment=target_segment, patch_size=params.patch_size)

    def advected_nnf(self, key: int) -> NNF:
        """Each pixel matched to where its material is in keyframe ``key`` (frame −1 outside the segment)."""
        height, width = self.keys[key][0].shape[:2]
        position = self.maps[key]
        coords = np.zeros(self.shape + (3,), np.float32)
        coords[..., 0] = np.clip(np.floor(position[..., 0] + 0.5), 0, width - 1)
        coords[..., 1] = np.clip(np.floor(position[..., 1] + 0.5), 0, height - 1)
        frame = np.where(self.segment >= 0, 0, -1).astype(np.int32)
        return NNF(frame, coords)


def _salt(context: Context, task: Task, term: int, iteration: int) -> int:
    return (((((context.stage.index * 8 + task.level) * 64 + task.sweep) * 100_000 + task.frame) * 32 + term) * 16
            + iteration)


def _inverse(nnf: NNF, source_shape: tuple[int, int], source_segment: np.ndarray, target_segment: np.ndarray,
             seed: int, salt: int) -> NNF:
    """A source → target field from a target → source one: each source pixel reached takes the last target
    pixel (in scan order) that reached it; the others random matches."""
    inverse = NNF.empty(*source_shape)
    ys, xs = np.nonzero(nnf.frame >= 0)
    sx = nnf.coords[ys, xs, 0].astype(np.int64)
    sy = nnf.coords[ys, xs, 1].astype(np.int64)
    inverse.frame[sy, sx] = 0
    inverse.coords[sy, sx, 0] = xs
    inverse.coords[sy, sx, 1] = ys
    inverse.frame[source_segment < 0] = -1
    fill_random(inverse, target_segment=source_segment, source_segment=target_segment[None], seed=seed, salt=salt,
                replace_all=False)
    return inverse


@dataclass
class _Vote:
    """Sums of a bidirectional-similarity vote and the energy of the matches voted."""

    total: np.ndarray
    weight: np.ndarray
    energy: float = 0.0

    def colour(self, fallback: np.ndarray) -> np.ndarray:
        scale = np.where(self.weight > 0, 1.0 / np.maximum(self.weight, 1e-30), 0.0).astype(np.float32)
        return np.where(self.weight[..., None] > 0, self.total * scale[..., None], fallback).astype(np.float32)


def _coherence(bds: _Vote, source, nnf, error, weight, patch_size):
    """Add the coherence half of one term: target patches voting their matches, weight / N_T each."""
    matched = nnf.frame >= 0
    count = int(np.count_nonzero(matched))
    if count == 0:
        return
    mean, covered = vote(source[None], nnf, patch_size=patch_size)
    share = weight / count
    bds.total += share * mean * covered[..., None]
    bds.weight += share * covered
    bds.energy += weight * float(error[matched].mean())


def _completeness(bds: _Vote, source, nnf, error, weight, patch_size):
    """Add the completeness half of one term: source patches voting into where they were matched, weight / N_S."""
    matched = nnf.frame >= 0
    count = int(np.count_nonzero(matched))
    if count == 0:
        return
    scatter_vote(source, nnf, patch_size=patch_size, weight=weight / count, total=bds.total, weights=bds.weight)
    bds.energy += weight * float(error[matched].mean())


def _search_keys(context: Context, task: Task, here: _Frame, colour: np.ndarray, nnfs: dict, bds: _Vote) -> None:
    """The keyframe terms: PatchMatch both ways from the current matches, then their votes."""
    params = context.params
    for term, (key, weight) in enumerate(sorted(here.weights.items())):
        key_colour, key_segment = here.keys[key]
        cost = here.cost(key_colour, key_segment, colour, here.segment, key_colour[..., 3], here.coverage)
        nnf = nnfs[key]
        error = patch_errors(cost, nnf)
        for iteration in range(params.patchmatch_iterations):
            patchmatch_pass(cost, nnf, error, seed=params.seed, salt=_salt(context, task, 2 * term, iteration),
                            reverse=iteration % 2 == 1)
        _coherence(bds, key_colour, nnf, error, weight, params.patch_size)
        back = here.cost(colour, here.segment, key_colour, key_segment, here.coverage, key_colour[..., 3])
        inverse = _inverse(nnf, key_colour.shape[:2], key_segment, here.segment, params.seed,
                           _salt(context, task, 2 * term + 1, 0))
        inverse_error = patch_errors(back, inverse)
        for iteration in range(params.patchmatch_iterations):
            patchmatch_pass(back, inverse, inverse_error, seed=params.seed,
                            salt=_salt(context, task, 2 * term + 1, iteration + 1), reverse=iteration % 2 == 1)
        _completeness(bds, key_colour, inverse, inverse_error, weight, params.patch_size)


def _search_neighbours(context: Context, task: Task, here: _Frame, colour: np.ndarray, neighbours, bds: _Vote):
    """The β terms: matches to frames m ∓ 1 only within the motion prior's window, both ways, and their votes."""
    params = context.params
    if params.beta == 0:
        return
    back, forward, radius = here.steps(task.frame)
    for side, state in zip((-1, 1), neighbours):
        if state is None:
            continue
        other = task.frame + side
        other_colour = _load(state)["colour"]
        other_cover = at_level(np.load(mask_path(context.root, other)), task.level)
        other_segment = _segment(other_cover, here.reach)
        cost = here.cost(other_colour, other_segment, colour, here.segment, other_cover, here.coverage)
        nnf, error = window_search(cost, back if side < 0 else forward, radius)
        _coherence(bds, other_colour, nnf, error, params.beta, params.patch_size)
        other_back, other_forward, other_radius = here.steps(other)
        towards_here = other_forward if side < 0 else other_back
        reverse_cost = here.cost(colour, here.segment, other_colour, other_segment, here.coverage, other_cover)
        reverse, reverse_error = window_search(reverse_cost, towards_here, other_radius)
        _completeness(bds, other_colour, reverse, reverse_error, params.beta, params.patch_size)


def _iterate(context: Context, task: Task, here: _Frame, colour: np.ndarray, nnfs: dict) -> _Vote:
    """One search–vote iteration's matches and votes (the NNFs to the keys updated in place)."""
    bds = _Vote(np.zeros(here.shape + (4,), np.float32), np.zeros(here.shape, np.float32))
    _search_keys(context, task, here, colour, nnfs, bds)
    _search_neighbours(context, task, here, colour, task.neighbours, bds)
    return bds


def _nnf_arrays(nnfs: dict) -> dict:
    arrays = {}
    for key, nnf in nnfs.items():
        arrays[f"frame_{key}"] = nnf.frame
        arrays[f"coords_{key}"] = nnf.coords
    return arrays


def _read_nnfs(state: dict, keys) -> dict:
    return {key: NNF(state[f"frame_{key}"], state[f"coords_{key}"]) for key in keys}


def _initial(context: Context, task: Task, here: _Frame) -> tuple[np.ndarray, dict]:
    """The level's starting frame and matches. Coarsest level of pass 1: each pixel voted from the keyframes
    where its material is (section 5), blended by ŵ. Finer levels: those matches or the coarser level's
    upscaled ones, whichever fits the upscaled frame better. Pass 2: its starting frame as is."""
    stage, params = context.stage, context.params
    nnfs = {key: here.advected_nnf(key) for key in here.weights}
    if stage.initial_dir is not None:
        colour = at_level(np.load(Path(stage.initial_dir) / f"{_name(task.frame)}.npy"), task.level)
        return colour, nnfs
    if task.level < stage.levels - 1:
        coarse = _load(state_path(context.root, stage.index, task.level + 1, params.sweeps, task.frame))
        guess = _upscale_colour(coarse["colour"], here.shape)
        for key, coarse_nnf in _read_nnfs(coarse, here.weights).items():
            key_colour, key_segment = here.keys[key]
            up = upscale_nnf(coarse_nnf, target_shape=here.shape, source_shape=key_colour.shape[:2])
            up.frame[here.segment < 0] = -1
            cost = here.cost(key_colour, key_segment, guess, here.segment, key_colour[..., 3], here.coverage)
            nnfs[key], _ = merge_nnf(up, nnfs[key], patch_errors(cost, up), patch_errors(cost, nnfs[key]))
    bds = _Vote(np.zeros(here.shape + (4,), np.float32), np.zeros(here.shape, np.float32))
    for key, weight in here.weights.items():
        nnf = nnfs[key]
        _coherence(bds, here.keys[key][0], nnf, np.zeros(here.shape, np.float32), weight, params.patch_size)
    return bds.colour(np.zeros(here.shape + (4,), np.float32)), nnfs


def _upscale_colour(colour: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """A coarser level's frame read bilinearly on the finer grid (x_fine = 2 x_coarse)."""
    grid = np.minimum(kf.identity(shape) / 2.0, np.array(colour.shape[1::-1], np.float32) - 1)
    return kf.sample(colour, grid)


def morph_frame(context: Context, task: Task) -> None:
    """Run one task (a module-level function, so local processes and Dask can run it); skip it if done."""
    out = Path(task.out)
    if out.is_file():
        return
    here = _Frame(context, task.frame, task.level)
    if task.sweep == 0:
        colour, nnfs = _initial(context, task, here)
    else:
        state = _load(task.current)
        colour, nnfs = state["colour"], _read_nnfs(state, here.weights)
        for _ in range(context.params.em_iterations):
            colour = _iterate(context, task, here, colour, nnfs).colour(colour)
    _save(out, colour=colour, **_nnf_arrays(nnfs))


def frame_energy(context: Context, frame: int, states: list[str]) -> float:
    """E_m of eq. 6.1 for the final frames (``states[j]``: frame j's final state file), from one search
    with the final sweep's protocol."""
    task = Task(frame, 0, context.params.sweeps + 1, out="", current=states[frame],
                neighbours=tuple(states[frame + side] if 0 <= frame + side < context.frame_count else None
                                 for side in (-1, 1)))
    here = _Frame(context, frame, 0)
    state = _load(task.current)
    thorough = dataclasses.replace(context, params=dataclasses.replace(
        context.params, patchmatch_iterations=context.params.patchmatch_iterations + EVALUATION_PASSES))
    return _iterate(thorough, task, here, state["colour"], _read_nnfs(state, here.weights)).energy


# --- the passes ------------------------------------------------------------------------------------------------

MapTasks = Callable[[Callable, list[tuple]], list]


def serial_map(function: Callable, arguments: list[tuple]) -> list:
    return [function(*args) for args in arguments]


def _sweep_tasks(context: Context, level: int, sweep: int, frames: range) -> list[Task]:
    root, index = context.root, context.stage.index

    def state(sweep_read, frame):
        return str(state_path(root, index, level, sweep_read, frame)) if 0 <= frame < context.frame_count else None

    return [Task(frame, level, sweep, str(state_path(root, index, level, sweep, frame)),
                 current=state(sweep - 1, frame) if sweep else None,
                 neighbours=(state(sweep - 1, frame - 1), state(sweep - 1, frame + 1)))
            for frame in frames]


def run_pass(context: Context, map_tasks: MapTasks = serial_map, progress: Callable[[], None] | None = None) -> None:
    """Every level and sweep of one pass, then its full-resolution frames into ``pass<i>/out``."""
    params, stage = context.params, context.stage
    frames = range(context.frame_count)
    for level in range(stage.levels - 1, -1, -1):
        for sweep in range(params.sweeps + 1):
            tasks = _sweep_tasks(context, level, sweep, frames)
            if sweep == 0 or params.schedule == "jacobi":
                map_tasks(morph_frame, [(context, task) for task in tasks])
            else:
                forward = sweep % 2 == 1
                for task in (tasks if forward else tasks[::-1]):
                    done_side = task.frame - 1 if forward else task.frame + 1
                    neighbours = tuple(
                        str(state_path(context.root, stage.index, level, sweep, n)) if n == done_side and path else path
                        for n, path in zip((task.frame - 1, task.frame + 1), task.neighbours))
                    morph_frame(context, dataclasses.replace(task, neighbours=neighbours))
            if progress is not None:
                progress()
    for frame in frames:
        final = output_path(context.root, stage.index, frame)
        if not final.is_file():
            colour = _load(state_path(context.root, stage.index, 0, params.sweeps, frame))["colour"]
            _save_array(final, colour)


def pass_energy(context: Context, map_tasks: MapTasks = serial_map) -> float:
    """E of eq. 6.1 over the pass's final frames."""
    states = [str(state_path(context.root, context.stage.index, 0, context.params.sweeps, frame))
              for frame in range(context.frame_count)]
    return float(sum(map_tasks(frame_energy, [(context, frame, states)
                                              for frame in range(context.frame_count)])))


# --- preparing the work folder ---------------------------------------------------------------------------------

def prepare(root: str | Path, masks: Callable[[int], np.ndarray], flows: Callable[[int], np.ndarray],
            frame_count: int, keyframes: dict[int, np.ndarray]) -> None:
    """Write what every task reads: each frame's coverage and one-step motion, and the painted keyframes
    (premultiplied RGBA) as pass 0's keys. Files already there (an interrupted run's) are kept."""
    root = Path(root)
    for frame in range(frame_count):
        if not mask_path(root, frame).is_file():
            _save_array(mask_path(root, frame), np.asarray(masks(frame), np.float32))
        if not step_path(root, frame).is_file():
            following = flows(frame + 1) if frame + 1 < frame_count else None
            back, forward, speed = kf.step_maps(flows(frame), following)
            _save(step_path(root, frame), back=back, forward=forward, speed=speed)
    for frame, rgba in keyframes.items():
        path = root / "keys" / f"{_name(frame)}.npy"
        if not path.is_file():
            _save_array(path, rgba)


def write_maps(context: Context) -> None:
    """For every frame, where its pixels' material is in each keyframe it weighs: the one-step positions
    chained from the keyframe outwards (:func:`~fluidymation.stages.keyframes.follow`)."""
    root, stage = context.root, context.stage
    needs = {frame: set(kf.keyframe_weights(frame, list(stage.keys), stage.weighting, stage.radius))
             for frame in range(context.frame_count)}
    for key in stage.keys:
        users = [frame for frame, keys in needs.items() if key in keys]
        for direction, field in ((1, "back"), (-1, "forward")):
            ends = [frame for frame in users if (frame - key) * direction > 0]
            last = (max if direction > 0 else min)(ends, default=key)
            position = kf.identity(context.shape)
            if direction > 0 and key in users and not map_path(root, stage.index, key, key).is_file():
                _save_array(map_path(root, stage.index, key, key), position)
            for frame in range(key + direction, last + direction, direction):
                position = kf.follow(position, _load(step_path(root, frame))[field])
                if frame in users and not map_path(root, stage.index, frame, key).is_file():
                    _save_array(map_path(root, stage.index, frame, key), position)


def plan_passes(root: str | Path, params: Params, keys: list[int], frame_count: int,
                shape: tuple[int, int]) -> list[Pass]:
    """The passes of the morph: the two-pass preset (section 7), or one pass with the layer's settings."""
    root = Path(root)
    levels = level_count(shape, params)
    painted = str(root / "keys")
    if not params.two_pass:
        return [Pass(0, tuple(sorted(keys)), painted, params.weighting, params.radius, params.gamma, levels)]
    first = Pass(0, tuple(sorted(keys)), painted, "blend", 1, 0.0, levels)
    smoothed = str(output_path(root, 0, 0).parent)
    second = Pass(1, tuple(range(frame_count)), smoothed, params.weighting, params.radius, params.gamma, 1,
                  initial_dir=smoothed)
    return [first, second]


def morph(root: str | Path, params: Params, keys: list[int], frame_count: int, shape: tuple[int, int], *,
          map_tasks: MapTasks = serial_map, progress: Callable[[], None] | None = None) -> list[Context]:
    """Run every pass (in the work folder made by :func:`prepare`); return their contexts, the last one's
    ``pass<i>/out`` holding the frames."""
    contexts = [Context(str(root), params, stage, frame_count, shape)
                for stage in plan_passes(root, params, keys, frame_count, shape)]
    for context in contexts:
        write_maps(context)
        run_pass(context, map_tasks, progress)
    return contexts


def sweep_count(params: Params, shape: tuple[int, int]) -> int:
    """How many sweeps (initializations included) :func:`morph` runs: the progress total."""
    passes = 2 if params.two_pass else 1
    return (level_count(shape, params) + (passes - 1)) * (params.sweeps + 1)


def frames_out(contexts: list[Context]) -> Iterator[tuple[int, np.ndarray]]:
    """The morph's final frames, premultiplied RGBA at full resolution, in order."""
    last = contexts[-1]
    for frame in range(last.frame_count):
        yield frame, np.load(output_path(last.root, last.stage.index, frame))
