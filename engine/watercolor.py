"""Watercolor on a grid after Curtis et al., "Computer-Generated Watercolor", 1997.

One wash (glaze) of one pigment is simulated on three layers:

* the shallow-water layer: wet-area mask ``wet`` (M), velocities ``u`` on the vertical
  cell faces, shape (H, W+1), and ``v`` on the horizontal faces, shape (H+1, W),
  pressure ``pressure`` (also the water-surface height) and the suspended pigment
  ``suspended`` (g);
* the pigment-deposition layer: ``deposited`` (d);
* the capillary layer: ``saturation`` (s) bounded by the paper's ``capacity`` (c).

One step is MoveWater (slope, velocities, divergence relaxation, flow outward), then
MovePigment, TransferPigment and SimulateCapillaryFlow, then (optionally) evaporation
after Van Laerhoven & Van Reeth 2005 so that a wash can dry. Two errata of the paper's
pseudocode are fixed (``+μB`` in the velocity update, ``δ = −ξ·div`` in the
relaxation). Axes: ``x`` is the column and grows to the right, ``y`` is the row and
grows downwards; a positive ``u`` moves water to the right, a positive ``v`` down.

The kernels are serial: each launch does little work (a relaxation sweep is a few
hundred microseconds at 256²), so thread start-up and barriers would cost more than they
save on a busy machine, and serial loops make the result independent of the thread count.
They are compiled without fastmath (``exact_kernel``): with it, the vectorized and the
scalar version of a loop rounded differently and which one ran depended on where the
arrays lay in memory, so the same seed gave different exemplars.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from fluidymation.engine._jit import exact_kernel

__all__ = [
    "WashParams",
    "WashState",
    "make_paper",
    "new_wash",
    "step_wash",
    "simulate_wash",
    "km_coefficients",
    "km_render",
    "srgb_to_linear",
    "linear_to_srgb",
]


# --------------------------------------------------------------------------- paper


def make_paper(shape, *, seed, capacity_min=0.3, capacity_max=0.7, fibre_weight=0.35, grain_sigma=6.0):
    """Procedural paper: a height field and its capillary capacity.

    A few octaves of blurred white noise (coarsest ``grain_sigma`` px, halving each
    octave) plus a fine fibre term (white noise blurred with σ = 0.7 px), normalised to
    [0, 1] after clipping the extreme 0.5 % on each side.

    Parameters
    ----------
    shape : (int, int)
        Height and width of the grid.
    seed : int
        Seed of the numpy Generator; the same seed gives the same paper.
    capacity_min, capacity_max : float
        Capacity c = h·(capacity_max − capacity_min) + capacity_min.
    fibre_weight : float
        Weight of the fibre term relative to the octaves (which sum to weight 1).
    grain_sigma : float
        Blur radius of the coarsest octave, in pixels.

    Returns
    -------
    height, capacity : (H, W) float32
    """
    height_px, width_px = (int(n) for n in shape)
    if height_px < 2 or width_px < 2:
        raise ValueError(f"paper shape must be at least 2×2, got {shape}")
    if not 0.0 <= capacity_min < capacity_max <= 1.0:
        raise ValueError("need 0 <= capacity_min < capacity_max <= 1")
    rng = np.random.default_rng(seed)
    total = np.zeros((height_px, width_px), dtype=np.float64)
    sigma, weight, weights = float(grain_sigma), 1.0, 0.0
    while sigma >= 0.9:
        total += weight * _unit_noise(rng, (height_px, width_px), sigma)
        weights += weight
        sigma, weight = sigma / 2.0, weight * 0.6
    total = total / weights + fibre_weight * _unit_noise(rng, (height_px, width_px), 0.7)
    low, high = np.percentile(total, [0.5, 99.5])
    height = np.clip((total - low) / max(high - low, 1e-12), 0.0, 1.0).astype(np.float32)
    capacity = (height * np.float32(capacity_max - capacity_min) + np.float32(capacity_min)).astype(np.float32)
    return height, capacity


def _unit_noise(rng, shape, sigma):
    noise = ndimage.gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    return noise / max(float(noise.std()), 1e-12)


# --------------------------------------------------------------------------- state


@dataclass(frozen=True)
class WashParams:
    """Constants of one wash; all are per pixel and per simulation step.

    ``viscosity`` μ, ``drag`` κ, ``slope`` scales ∇h, ``max_speed`` caps |u|, |v|;
    divergence relaxation with ``relax_rate`` ξ, ``relax_tolerance`` τ and at most
    ``relax_sweeps`` sweeps; flow outward with ``edge_darkening`` η over a
    ``edge_kernel``-pixel box blur of the wet mask; pigment ``density`` ρ,
    ``staining`` ω, ``granulation`` γ; capillary ``absorption`` α,
    ``diffuse_min`` ε, ``receive_min`` δ, ``wet_threshold`` σ; evaporation (0 turns
    drying off) of standing water, ``edge_evaporation`` β (edges dry first),
    ``saturation_decay`` of the paper's moisture once the standing water is gone and
    ``dry_saturation`` below which a cell dries.
    """

    viscosity: float = 0.1
    drag: float = 0.01
    slope: float = 1.0
    max_speed: float = 5.0
    relax_rate: float = 0.1
    relax_tolerance: float = 0.01
    relax_sweeps: int = 50
    edge_darkening: float = 0.03
    edge_kernel: int = 10
    density: float = 0.02
    staining: float = 5.5
    granulation: float = 0.8
    absorption: float = 0.05
    diffuse_min: float = 0.35
    receive_min: float = 0.05
    wet_threshold: float = 0.43
    evaporation: float = 0.0
    edge_evaporation: float = 4.0
    saturation_decay: float = 0.01
    dry_saturation: float = 0.06

    def __post_init__(self):
        if not 0.0 < self.relax_rate < 0.25:
            raise ValueError(f"relax_rate must be in (0, 0.25) for a stable relaxation, got {self.relax_rate}")
        if self.viscosity < 0 or self.viscosity > 0.25:
            raise ValueError(f"viscosity must be in [0, 0.25], got {self.viscosity}")
        if not 0 <= self.drag < 1:
            raise ValueError(f"drag must be in [0, 1), got {self.drag}")
        if self.max_speed <= 0:
            raise ValueError(f"max_speed must be positive, got {self.max_speed}")
        if self.edge_kernel < 1 or self.relax_sweeps < 0:
            raise ValueError("edge_kernel must be >= 1 and relax_sweeps >= 0")
        if self.staining <= 0 or self.density < 0 or not 0 <= self.granulation <= 1:
            raise ValueError("need staining > 0, density >= 0 and granulation in [0, 1]")


@dataclass
class WashState:
    """The evolving fields of one wash (float32 unless noted; H×W unless noted).

    ``wet`` is uint8 (0/1); ``u`` is (H, W+1), ``v`` is (H+1, W); ``water`` is the
    standing water that evaporation removes (only used when drying is on).
    """

    height: np.ndarray
    capacity: np.ndarray
    wet: np.ndarray
    u: np.ndarray
    v: np.ndarray
    pressure: np.ndarray
    suspended: np.ndarray
    deposited: np.ndarray
    saturation: np.ndarray
    water: np.ndarray
    wet_blur: np.ndarray = field(default=None, repr=False)

    @property
    def shape(self):
        return self.pressure.shape

    def cell_velocity(self):
        """(H, W, 2) float32 velocity at the cell centres, (dx, dy) per step."""
        velocity = np.empty(self.shape + (2,), dtype=np.float32)
        velocity[:, :, 0] = 0.5 * (self.u[:, :-1] + self.u[:, 1:])
        velocity[:, :, 1] = 0.5 * (self.v[:-1, :] + self.v[1:, :])
        return velocity


def new_wash(*, height, capacity, wet, pressure=None, suspended=None, deposited=None, saturation=None, water=None):
    """Build a :class:`WashState` at rest from initial fields.

    Parameters
    ----------
    height, capacity : (H, W) float
        The paper (see :func:`make_paper`).
    wet : (H, W) bool or 0/1
        Initial wet-area mask.
    pressure, suspended, deposited, saturation, water : (H, W) float, optional
        Initial water-surface height, suspended and deposited pigment, capillary
        saturation and standing water; zero when omitted (``water`` defaults to 1 on
        the wet area). Suspended pigment and pressure are cleared outside ``wet``.
    """
    height = _as_field(height, "height")
    shape = height.shape
    fields = {"capacity": _as_field(capacity, "capacity", shape)}
    for name, value in (
        ("pressure", pressure),
        ("suspended", suspended),
        ("deposited", deposited),
        ("saturation", saturation),
        ("water", water),
    ):
        fields[name] = np.zeros(shape, dtype=np.float32) if value is None else _as_field(value, name, shape)
    wet_mask = np.asarray(wet)
    if wet_mask.shape != shape:
        raise ValueError(f"wet must have shape {shape}, got {wet_mask.shape}")
    wet_mask = (wet_mask > 0).astype(np.uint8)
    if water is None:
        fields["water"] = wet_mask.astype(np.float32)
    fields["pressure"] *= wet_mask
    fields["suspended"] *= wet_mask
    for name in ("suspended", "deposited", "saturation", "water"):
        if np.any(fields[name] < 0):
            raise ValueError(f"{name} must be non-negative")
    h, w = shape
    return WashState(
        height=height,
        wet=wet_mask,
        u=np.zeros((h, w + 1), dtype=np.float32),
        v=np.zeros((h + 1, w), dtype=np.float32),
        **fields,
    )


def _as_field(value, name, shape=None):
    array = np.ascontiguousarray(value, dtype=np.float32)
    if array.ndim != 2 or (shape is not None and array.shape != shape):
        raise ValueError(f"{name} must be a 2-D array{'' if shape is None else f' of shape {shape}'}, got {array.shape}")
    return array.copy()


# --------------------------------------------------------------------------- kernels


@exact_kernel
def _zero_dry_faces(u, v, wet):
    height, width = wet.shape
    for y in range(height):
        u[y, 0] = 0.0
        u[y, width] = 0.0
        for x in range(1, width):
            if wet[y, x - 1] == 0 or wet[y, x] == 0:
                u[y, x] = 0.0
    for y in range(height + 1):
        for x in range(width):
            if y == 0 or y == height or wet[y - 1, x] == 0 or wet[y, x] == 0:
                v[y, x] = 0.0


@exact_kernel
def _apply_slope(u, v, paper_height, wet, slope):
    height, width = wet.shape
    for y in range(height):
        for x in range(1, width):
            if wet[y, x - 1] != 0 and wet[y, x] != 0:
                u[y, x] -= slope * (paper_height[y, x] - paper_height[y, x - 1])
    for y in range(1, height):
        for x in range(width):
            if wet[y - 1, x] != 0 and wet[y, x] != 0:
                v[y, x] -= slope * (paper_height[y, x] - paper_height[y - 1, x])


@exact_kernel
def _advance_velocities(u, v, pressure, wet, dt, viscosity, drag, max_speed, u_out, v_out):
    """One forward-Euler substep of the shallow-water momentum equation."""
    height, width = wet.shape
    for y in range(height):
        for x in range(width + 1):
            if x == 0 or x == width or wet[y, x - 1] == 0 or wet[y, x] == 0:
                u_out[y, x] = 0.0
                continue
            here = u[y, x]
            up = u[y - 1, x] if y > 0 else here
            down = u[y + 1, x] if y < height - 1 else here
            centre_left = 0.5 * (u[y, x - 1] + here)
            centre_right = 0.5 * (here + u[y, x + 1])
            corner_top = 0.5 * (up + here) * 0.5 * (v[y, x - 1] + v[y, x])
            corner_bottom = 0.5 * (here + down) * 0.5 * (v[y + 1, x - 1] + v[y + 1, x])
            advection = centre_left * centre_left - centre_right * centre_right + corner_top - corner_bottom
            diffusion = u[y, x + 1] + u[y, x - 1] + up + down - 4.0 * here
            value = here + dt * (advection + viscosity * diffusion + pressure[y, x - 1] - pressure[y, x] - drag * here)
            u_out[y, x] = min(max(value, -max_speed), max_speed)
    for y in range(height + 1):
        for x in range(width):
            if y == 0 or y == height or wet[y - 1, x] == 0 or wet[y, x] == 0:
                v_out[y, x] = 0.0
                continue
            here = v[y, x]
            left = v[y, x - 1] if x > 0 else here
            right = v[y, x + 1] if x < width - 1 else here
            centre_up = 0.5 * (v[y - 1, x] + here)
            centre_down = 0.5 * (here + v[y + 1, x])
            corner_left = 0.5 * (left + here) * 0.5 * (u[y - 1, x] + u[y, x])
            corner_right = 0.5 * (here + right) * 0.5 * (u[y - 1, x + 1] + u[y, x + 1])
            advection = centre_up * centre_up - centre_down * centre_down + corner_left - corner_right
            diffusion = v[y + 1, x] + v[y - 1, x] + left + right - 4.0 * here
            value = here + dt * (advection + viscosity * diffusion + pressure[y - 1, x] - pressure[y, x] - drag * here)
            v_out[y, x] = min(max(value, -max_speed), max_speed)


@exact_kernel
def _relax_divergence(u, v, pressure, wet, rate, tolerance, max_sweeps, delta, row_max):
    """Jacobi sweeps that remove divergence: δ = −ξ·div moves into p and the faces."""
    height, width = wet.shape
    for _ in range(max_sweeps):
        for y in range(height):
            largest = 0.0
            for x in range(width):
                if wet[y, x] != 0:
                    change = -rate * (u[y, x + 1] - u[y, x] + v[y + 1, x] - v[y, x])
                    delta[y, x] = change
                    largest = max(largest, abs(change))
                else:
                    delta[y, x] = 0.0
            row_max[y] = largest
        for y in range(height):
            for x in range(width):
                pressure[y, x] += delta[y, x]
            for x in range(1, width):
                if wet[y, x - 1] != 0 and wet[y, x] != 0:
                    u[y, x] += delta[y, x - 1] - delta[y, x]
        for y in range(1, height):
            for x in range(width):
                if wet[y - 1, x] != 0 and wet[y, x] != 0:
                    v[y, x] += delta[y - 1, x] - delta[y, x]
        if row_max.max() <= tolerance:
            break


@exact_kernel
def _advect_pigment(u, v, pigment, substeps, flux_x, flux_y):
    """Upwind flux-form advection: conserves mass, keeps pigment non-negative."""
    height, width = pigment.shape
    dt = 1.0 / substeps
    for _ in range(substeps):
        for y in range(height):
            for x in range(1, width):
                face = u[y, x]
                flux_x[y, x] = dt * (max(face, 0.0) * pigment[y, x - 1] - max(-face, 0.0) * pigment[y, x])
        for y in range(1, height):
            for x in range(width):
                face = v[y, x]
                flux_y[y, x] = dt * (max(face, 0.0) * pigment[y - 1, x] - max(-face, 0.0) * pigment[y, x])
        for y in range(height):
            for x in range(width):
                pigment[y, x] += flux_x[y, x] - flux_x[y, x + 1] + flux_y[y, x] - flux_y[y + 1, x]


@exact_kernel
def _transfer_pigment(suspended, deposited, paper_height, wet, density, staining, granulation):
    height, width = wet.shape
    for y in range(height):
        for x in range(width):
            if wet[y, x] == 0:
                continue
            g = suspended[y, x]
            d = deposited[y, x]
            h = paper_height[y, x]
            down = g * (1.0 - h * granulation) * density
            up = d * (1.0 + (h - 1.0) * granulation) * density / staining
            if d + down > 1.0:
                down = max(0.0, 1.0 - d)
            if g + up > 1.0:
                up = max(0.0, 1.0 - g)
            deposited[y, x] = d + down - up
            suspended[y, x] = g + up - down


@exact_kernel
def _capillary_share(source, target, target_capacity, diffuse_min, receive_min):
    """Saturation that moves from a cell with ``source`` to its neighbour with ``target``."""
    if source > diffuse_min and source > target and target > receive_min:
        return max(0.0, min(source - target, target_capacity - target) / 4.0)
    return 0.0


@exact_kernel
def _capillary_flow(
    saturation, capacity, wet, water, absorption, use_water, diffuse_min, receive_min, wet_threshold, snapshot, grown_rows
):
    """Absorb water into the paper, diffuse it along the fibres, wet the cells it reaches."""
    height, width = wet.shape
    for y in range(height):
        for x in range(width):
            if wet[y, x] != 0:
                amount = max(0.0, min(absorption, capacity[y, x] - saturation[y, x]))
                if use_water:
                    amount = min(amount, max(water[y, x], 0.0))
                    water[y, x] -= amount
                saturation[y, x] += amount
            snapshot[y, x] = saturation[y, x]
    for y in range(height):
        for x in range(width):
            here = snapshot[y, x]
            cap = capacity[y, x]
            net = 0.0
            for k in range(4):
                ny = y + (k == 1) - (k == 0)
                nx = x + (k == 3) - (k == 2)
                if ny < 0 or ny >= height or nx < 0 or nx >= width:
                    continue
                there = snapshot[ny, nx]
                net += _capillary_share(there, here, cap, diffuse_min, receive_min)
                net -= _capillary_share(here, there, capacity[ny, nx], diffuse_min, receive_min)
            saturation[y, x] = here + net
    for y in range(height):
        grown = 0
        for x in range(width):
            if wet[y, x] == 0 and saturation[y, x] > wet_threshold:
                wet[y, x] = 1
                grown = 1
        grown_rows[y] = grown


@exact_kernel
def _evaporate(
    wet, wet_blur, water, saturation, suspended, deposited, pressure, rate, edge_boost, saturation_decay, dry_saturation,
    dried_rows,
):
    """Standing water evaporates (faster near the wet edge); drained cells dry out."""
    height, width = wet.shape
    for y in range(height):
        dried = 0
        for x in range(width):
            if wet[y, x] != 0 and water[y, x] > 0.0:
                water[y, x] -= rate * (1.0 + edge_boost * (1.0 - wet_blur[y, x]))
            if water[y, x] <= 0.0:
                water[y, x] = 0.0
                saturation[y, x] = max(0.0, saturation[y, x] - saturation_decay)
                if wet[y, x] != 0 and saturation[y, x] < dry_saturation:
                    wet[y, x] = 0
                    deposited[y, x] += suspended[y, x]
                    suspended[y, x] = 0.0
                    pressure[y, x] = 0.0
                    dried = 1
        dried_rows[y] = dried


# --------------------------------------------------------------------------- steps


class _Workspace:
    """Scratch buffers reused by every step of one simulation."""

    def __init__(self, shape):
        h, w = shape
        self.u = np.zeros((h, w + 1), dtype=np.float32)
        self.v = np.zeros((h + 1, w), dtype=np.float32)
        self.flux_x = np.zeros((h, w + 1), dtype=np.float32)
        self.flux_y = np.zeros((h + 1, w), dtype=np.float32)
        self.cells = np.zeros((h, w), dtype=np.float32)
        self.rows = np.zeros(h, dtype=np.float32)
        self.row_flags = np.zeros(h, dtype=np.uint8)


def _blur_wet(state, params):
    state.wet_blur = ndimage.uniform_filter(
        state.wet.astype(np.float32), size=params.edge_kernel, mode="constant"
    ).astype(np.float32)


def step_wash(state, params, workspace=None):
    """Advance ``state`` in place by one step; return the (H, W, 2) cell velocity used.

    The returned velocity is the water velocity that moved the pigment in this step,
    in pixels per step, (dx, dy) with y pointing down.
    """
    work = workspace if workspace is not None else _Workspace(state.shape)
    if state.wet_blur is None:
        _blur_wet(state, params)
    # MoveWater: UpdateVelocities
    _zero_dry_faces(state.u, state.v, state.wet)
    _apply_slope(state.u, state.v, state.height, state.wet, np.float32(params.slope))
    largest = max(float(np.abs(state.u).max()), float(np.abs(state.v).max()), 1e-6)
    substeps = max(1, math.ceil(min(largest, params.max_speed)))
    for _ in range(substeps):
        _advance_velocities(
            state.u, state.v, state.pressure, state.wet, np.float32(1.0 / substeps), np.float32(params.viscosity),
            np.float32(params.drag), np.float32(params.max_speed), work.u, work.v,
        )
        state.u, work.u = work.u, state.u
        state.v, work.v = work.v, state.v
    # RelaxDivergence
    _relax_divergence(
        state.u, state.v, state.pressure, state.wet, np.float32(params.relax_rate),
        np.float32(params.relax_tolerance), int(params.relax_sweeps), work.cells, work.rows,
    )
    np.clip(state.u, -params.max_speed, params.max_speed, out=state.u)
    np.clip(state.v, -params.max_speed, params.max_speed, out=state.v)
    # FlowOutward
    state.pressure -= np.float32(params.edge_darkening) * (1.0 - state.wet_blur) * state.wet
    velocity = state.cell_velocity()
    # MovePigment
    largest = max(float(np.abs(state.u).max()), float(np.abs(state.v).max()))
    if not math.isfinite(largest):
        raise FloatingPointError("watercolor velocities are not finite; the wash parameters are unstable")
    if largest > 0.0:
        _advect_pigment(state.u, state.v, state.suspended, max(1, math.ceil(4.0 * largest)), work.flux_x, work.flux_y)
    # TransferPigment
    _transfer_pigment(
        state.suspended, state.deposited, state.height, state.wet, np.float32(params.density),
        np.float32(params.staining), np.float32(params.granulation),
    )
    # SimulateCapillaryFlow
    drying = params.evaporation > 0.0
    _capillary_flow(
        state.saturation, state.capacity, state.wet, state.water, np.float32(params.absorption), drying,
        np.float32(params.diffuse_min), np.float32(params.receive_min), np.float32(params.wet_threshold), work.cells,
        work.row_flags,
    )
    changed = bool(work.row_flags.any())
    if drying:
        _evaporate(
            state.wet, state.wet_blur, state.water, state.saturation, state.suspended, state.deposited,
            state.pressure, np.float32(params.evaporation), np.float32(params.edge_evaporation),
            np.float32(params.saturation_decay), np.float32(params.dry_saturation), work.row_flags,
        )
        changed = changed or bool(work.row_flags.any())
    if changed:
        _zero_dry_faces(state.u, state.v, state.wet)
        _blur_wet(state, params)
    return velocity


def simulate_wash(state, params, *, frames, steps_per_frame):
    """Run the wash and yield one record per frame.

    Frame ``k`` is the state after ``(k + 1)·steps_per_frame`` steps; its flow is the
    water displacement accumulated over the steps since frame ``k − 1``.

    Yields
    ------
    pigment : (H, W) float32
        Suspended plus deposited pigment.
    wet : (H, W) bool
        The wet-area mask.
    flow : (H, W, 2) float32
        Water velocity in px/frame, (dx, dy), y down, zero on dry paper.
    """
    if frames < 1 or steps_per_frame < 1:
        raise ValueError("frames and steps_per_frame must be >= 1")
    work = _Workspace(state.shape)
    for _ in range(frames):
        flow = np.zeros(state.shape + (2,), dtype=np.float32)
        for _ in range(steps_per_frame):
            flow += step_wash(state, params, work)
        yield state.suspended + state.deposited, state.wet.astype(bool), flow


# --------------------------------------------------------------------------- Kubelka–Munk


def srgb_to_linear(rgb):
    """sRGB values in [0, 1] to linear reflectance (float32)."""
    rgb = np.asarray(rgb, dtype=np.float32)
    return np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4).astype(np.float32)


def linear_to_srgb(linear):
    """Linear reflectance in [0, 1] to sRGB values (float32)."""
    linear = np.clip(np.asarray(linear, dtype=np.float32), 0.0, 1.0)
    return np.where(linear <= 0.0031308, linear * 12.92, 1.055 * linear ** (1 / 2.4) - 0.055).astype(np.float32)


def km_coefficients(over_white, over_black):
    """Absorption K and scattering S of a pigment from the look of a unit layer.

    Parameters
    ----------
    over_white, over_black : (3,) float
        Linear reflectance of a unit-thickness layer over white and over black,
        ``0 < over_black < over_white < 1`` per channel.

    Returns
    -------
    absorption, scattering : (3,) float64
    """
    white = np.asarray(over_white, dtype=np.float64)
    black = np.asarray(over_black, dtype=np.float64)
    if white.shape != (3,) or black.shape != (3,):
        raise ValueError("over_white and over_black must have shape (3,)")
    if not (np.all(black > 0) and np.all(black < white) and np.all(white < 1)):
        raise ValueError("need 0 < over_black < over_white < 1 in every channel")
    a = 0.5 * (white + (black - white + 1.0) / black)
    b = np.sqrt(a * a - 1.0)
    z = (b * b - (a - white) * (a - 1.0)) / (b * (1.0 - white))
    scattering = np.maximum((1.0 / b) * 0.5 * np.log((z + 1.0) / (z - 1.0)), 1e-4)
    absorption = scattering * (a - 1.0)
    return absorption, scattering


def km_render(thickness, absorption, scattering, paper):
    """Reflectance of a pigment layer of the given thickness over the paper.

    Parameters
    ----------
    thickness : (H, W) float
        Layer thickness (1 looks like the colour the coefficients came from).
    absorption, scattering : (3,) float
        From :func:`km_coefficients`.
    paper : (H, W, 3) or (3,) float
        Linear reflectance of the paper under the layer.

    Returns
    -------
    (H, W, 3) float32 linear reflectance.
    """
    x = np.maximum(np.asarray(thickness, dtype=np.float64), 0.0)[:, :, None]
    k = np.asarray(absorption, dtype=np.float64)
    s = np.asarray(scattering, dtype=np.float64)
    a = 1.0 + k / s
    b = np.sqrt(a * a - 1.0)
    bsx = b * s * x
    sinh, cosh = np.sinh(bsx), np.cosh(bsx)
    c = a * sinh + b * cosh
    reflectance = sinh / c
    transmittance = b / c
    paper = np.asarray(paper, dtype=np.float64)
    result = reflectance + transmittance * transmittance * paper / (1.0 - reflectance * paper)
    return result.astype(np.float32)
