"""Motion fields from mask sequences (paper appendix A, thesis 3.8).

On the inner boundary of a mask the material moves along the distance gradient by the
change of the signed distance between two frames; with ``dist`` positive inside the
gradient points inward, hence the minus sign: the normal velocity is ``-(dist_cur -
dist_prev) · ∇dist_cur / |∇dist_cur|``, so the flow points outward where a mask grows.

Masks show only that normal component. Filling it alone into the interior under-reads
rigid motion: a disk translating at v has normal boundary velocity ``v·cos φ`` along
its normal, whose harmonic fill reads v/2 at the centre. So per connected component
the normal velocities are also fitted (least squares, slightly regularised) by an
affine motion ``u(x) = b + A·(x − c)``, and each boundary pixel gets that motion's
tangential part, scaled by the share of the normal velocities' energy the fit explains
(1 for a rigid or affine motion, near 0 for a deformation it cannot express), plus the
measured normal part. Affine fields are harmonic, so a translating, rotating or scaling
shape's interior reads its motion exactly.

The rest of the image is filled by solving Laplace's equation with those boundary
values (cascadic multigrid: solve on the coarsest grid, then prolong and relax level by
level). Inside the mask that is the harmonic interpolation of the boundary; outside it
is a smooth extension, so that smoothing flows along time near a moving boundary blends
like with like instead of with zeros.

Flows are float32 ``(H, W, 2)`` holding ``(dx, dy)`` in px/frame with y pointing down.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from fluidymation.engine._jit import kernel

_OUTSIDE = 0
_FIXED = 1
_UNKNOWN = 2

#: Grids no larger than this on their longer side are solved directly by relaxation.
_COARSEST_SIDE = 12
_COARSEST_SWEEPS = 200
#: Over-relaxation factor of the red-black Gauss-Seidel sweeps.
_OMEGA = 1.6
#: Side of the square tiles in which the finer grids are marked for relaxation.
_TILE = 8
#: Distance changes at or below this (px) are float rounding of the temporal filter.
_STILL = 1e-4
#: Ridge added to the affine fit's normal equations, per boundary pixel: on the
#: translation and on the linear part (coordinates in units of the component's radius).
#: Motions the boundary does not show (a circle's rotation) stay near zero.
_RIDGE_TRANSLATION = 0.01
_RIDGE_LINEAR = 0.1


@kernel
def _weighted(dists, weights, y, x):
    """``sum_k weights[k] · dists[k, y, x]``, skipping zero weights."""
    total = np.float32(0.0)
    for slot in range(weights.shape[0]):
        if weights[slot] != 0.0:
            total += weights[slot] * dists[slot, y, x]
    return total


@kernel
def _boundary_velocity(dists, prev_weights, cur_weights, mask, normal, speed, state):
    """Mark the inner boundary fixed; store there the unit inward normal ∇D/|∇D| (zero
    where the gradient vanishes) and the speed along it, ``-ΔD/|∇D|``."""
    height, width = mask.shape
    for y in range(height):
        for x in range(width):
            normal[y, x, 0] = 0.0
            normal[y, x, 1] = 0.0
            speed[y, x] = 0.0
            if not mask[y, x]:
                state[y, x] = _UNKNOWN
                continue
            on_boundary = (
                (x > 0 and not mask[y, x - 1])
                or (x < width - 1 and not mask[y, x + 1])
                or (y > 0 and not mask[y - 1, x])
                or (y < height - 1 and not mask[y + 1, x])
            )
            if not on_boundary:
                state[y, x] = _UNKNOWN
                continue
            state[y, x] = _FIXED
            x0 = max(x - 1, 0)
            x1 = min(x + 1, width - 1)
            y0 = max(y - 1, 0)
            y1 = min(y + 1, height - 1)
            grad_x = (_weighted(dists, cur_weights, y, x1) - _weighted(dists, cur_weights, y, x0)) / max(x1 - x0, 1)
            grad_y = (_weighted(dists, cur_weights, y1, x) - _weighted(dists, cur_weights, y0, x)) / max(y1 - y0, 1)
            norm = math.sqrt(grad_x * grad_x + grad_y * grad_y)
            if norm < 1e-6:
                continue
            normal[y, x, 0] = grad_x / norm
            normal[y, x, 1] = grad_y / norm
            change = _weighted(dists, cur_weights, y, x) - _weighted(dists, prev_weights, y, x)
            if abs(change) > _STILL:
                speed[y, x] = -change / norm


@kernel
def _affine_features(normal, x, y, centre_x, centre_y, radius, features):
    """``features · p`` is the normal component of the affine motion ``p`` at (x, y):
    ``p = (b_x, b_y, a_xx, a_xy, a_yx, a_yy)``, ``u = b + A·((x, y) − c)/radius``."""
    gx = normal[y, x, 0]
    gy = normal[y, x, 1]
    rx = (x - centre_x) / radius
    ry = (y - centre_y) / radius
    features[0] = gx
    features[1] = gy
    features[2] = gx * rx
    features[3] = gx * ry
    features[4] = gy * rx
    features[5] = gy * ry


@kernel
def _affine_normal_equations(normal, speed, state, labels, geometry, matrices, rhs, energy):
    """Per component (label ≥ 1): ``geometry[l] = (centre x, centre y, radius, pixels)``
    of its boundary, and the normal equations of the affine fit to its normal speeds."""
    height, width = state.shape
    geometry[...] = 0.0
    for y in range(height):
        for x in range(width):
            if state[y, x] == _FIXED and labels[y, x] > 0:
                label = labels[y, x]
                geometry[label, 0] += x
                geometry[label, 1] += y
                geometry[label, 3] += 1.0
    for label in range(geometry.shape[0]):
        if geometry[label, 3] > 0.0:
            geometry[label, 0] /= geometry[label, 3]
            geometry[label, 1] /= geometry[label, 3]
    for y in range(height):
        for x in range(width):
            if state[y, x] == _FIXED and labels[y, x] > 0:
                label = labels[y, x]
                geometry[label, 2] += (x - geometry[label, 0]) ** 2 + (y - geometry[label, 1]) ** 2
    for label in range(geometry.shape[0]):
        if geometry[label, 3] > 0.0:
            geometry[label, 2] = max(math.sqrt(geometry[label, 2] / geometry[label, 3]), 1.0)
    matrices[...] = 0.0
    rhs[...] = 0.0
    energy[...] = 0.0
    features = np.empty(6, dtype=np.float64)
    for y in range(height):
        for x in range(width):
            if state[y, x] != _FIXED or labels[y, x] <= 0:
                continue
            label = labels[y, x]
            _affine_features(normal, x, y, geometry[label, 0], geometry[label, 1], geometry[label, 2], features)
            for row in range(6):
                rhs[label, row] += features[row] * speed[y, x]
                for column in range(6):
                    matrices[label, row, column] += features[row] * features[column]
            energy[label] += speed[y, x] * speed[y, x]


@kernel
def _boundary_values(normal, speed, state, labels, geometry, motions, flow):
    """``flow`` on the boundary: the fitted motion with its normal part replaced by the
    measured one; zero elsewhere."""
    height, width = state.shape
    for y in range(height):
        for x in range(width):
            flow[y, x, 0] = 0.0
            flow[y, x, 1] = 0.0
            if state[y, x] != _FIXED:
                continue
            label = labels[y, x]
            gx = normal[y, x, 0]
            gy = normal[y, x, 1]
            rx = (x - geometry[label, 0]) / geometry[label, 2]
            ry = (y - geometry[label, 1]) / geometry[label, 2]
            p = motions[label]
            u_x = p[0] + p[2] * rx + p[3] * ry
            u_y = p[1] + p[4] * rx + p[5] * ry
            along = speed[y, x] - (gx * u_x + gy * u_y)
            flow[y, x, 0] = u_x + along * gx
            flow[y, x, 1] = u_y + along * gy


def _fit_affine_motions(normal, speed, state, mask):
    """Component labels, boundary geometry and per component the affine motion
    parameters, already scaled by the share of the normal speeds' energy they explain."""
    labels, count = ndimage.label(mask)
    labels = labels.astype(np.int32)
    geometry = np.empty((count + 1, 4), dtype=np.float64)
    matrices = np.empty((count + 1, 6, 6), dtype=np.float64)
    rhs = np.empty((count + 1, 6), dtype=np.float64)
    energy = np.empty(count + 1, dtype=np.float64)
    _affine_normal_equations(normal, speed, state, labels, geometry, matrices, rhs, energy)
    ridge = np.diag([_RIDGE_TRANSLATION] * 2 + [_RIDGE_LINEAR] * 4)
    pixels = np.maximum(geometry[:, 3], 1.0)
    motions = np.linalg.solve(matrices + pixels[:, None, None] * ridge, rhs[:, :, None])[:, :, 0]
    residual = energy - 2 * np.einsum("li,li->l", motions, rhs) + np.einsum("li,lij,lj->l", motions, matrices, motions)
    explained = np.where(energy > 0, 1.0 - residual / np.maximum(energy, 1e-30), 0.0)
    motions *= np.clip(explained, 0.0, 1.0)[:, None]
    return labels, geometry, motions


@kernel
def _restrict_state(state, coarse_state):
    """A coarse cell is fixed if any of its 2x2 fine cells is, else unknown if any is."""
    height, width = state.shape
    coarse_height, coarse_width = coarse_state.shape
    for cy in range(coarse_height):
        for cx in range(coarse_width):
            fixed = False
            unknown = False
            for y in range(2 * cy, min(2 * cy + 2, height)):
                for x in range(2 * cx, min(2 * cx + 2, width)):
                    fixed = fixed or state[y, x] == _FIXED
                    unknown = unknown or state[y, x] == _UNKNOWN
            coarse_state[cy, cx] = _FIXED if fixed else _UNKNOWN if unknown else _OUTSIDE


@kernel
def _restrict_values(state, values, coarse_state, coarse_values):
    """Fixed coarse cells get the mean of their fixed fine cells, the others zero."""
    height, width = state.shape
    coarse_height, coarse_width = coarse_state.shape
    for cy in range(coarse_height):
        for cx in range(coarse_width):
            coarse_values[cy, cx] = 0.0
            if coarse_state[cy, cx] != _FIXED:
                continue
            fixed_count = 0
            total = np.float32(0.0)
            for y in range(2 * cy, min(2 * cy + 2, height)):
                for x in range(2 * cx, min(2 * cx + 2, width)):
                    if state[y, x] == _FIXED:
                        fixed_count += 1
                        total += values[y, x]
            coarse_values[cy, cx] = total / fixed_count


@kernel
def _coarse_neighbours(length, coarse_length):
    """Per fine index along one axis: the two coarse cells around its centre and the
    weight of the second (bilinear interpolation, clamped at the ends)."""
    first = np.empty(length, dtype=np.int64)
    second = np.empty(length, dtype=np.int64)
    weight = np.empty(length, dtype=np.float32)
    for i in range(length):
        centre = 0.5 * i - 0.25  # in coarse cell coordinates
        first[i] = min(max(int(math.floor(centre)), 0), coarse_length - 1)
        second[i] = min(first[i] + 1, coarse_length - 1)
        weight[i] = min(max(centre - first[i], 0.0), 1.0)
    return first, second, weight


@kernel
def _prolong(coarse_state, coarse_values, state, values):
    """Bilinear interpolation onto the unknown fine cells, ignoring outside coarse cells."""
    height, width = state.shape
    cy0s, cy1s, wy1s = _coarse_neighbours(height, coarse_state.shape[0])
    cx0s, cx1s, wx1s = _coarse_neighbours(width, coarse_state.shape[1])
    for y in range(height):
        cy0 = cy0s[y]
        cy1 = cy1s[y]
        wy1 = wy1s[y]
        for x in range(width):
            if state[y, x] != _UNKNOWN:
                continue
            cx0 = cx0s[x]
            cx1 = cx1s[x]
            wx1 = wx1s[x]
            total_weight = np.float32(0.0)
            total = np.float32(0.0)
            for corner in range(4):
                cy = cy1 if corner >= 2 else cy0
                cx = cx1 if corner % 2 == 1 else cx0
                weight = (wy1 if corner >= 2 else 1 - wy1) * (wx1 if corner % 2 == 1 else 1 - wx1)
                if coarse_state[cy, cx] != _OUTSIDE:
                    total_weight += weight
                    total += weight * coarse_values[cy, cx]
            values[y, x] = total / total_weight if total_weight > 0.0 else coarse_values[y // 2, x // 2]


@kernel
def _runs_near_fixed(state, reach, counts, starts, stops):
    """Row runs that cover every cell within Chebyshev distance ``reach`` of a fixed
    cell, in whole tiles of ``_TILE`` x ``_TILE`` cells: row ``y`` gets ``counts[y]``
    runs ``[start, stop)``, appended to ``starts``/``stops``. Returns the number of runs."""
    height, width = state.shape
    tiles_y = (height + _TILE - 1) // _TILE
    tiles_x = (width + _TILE - 1) // _TILE
    has_fixed = np.zeros((tiles_y, tiles_x), dtype=np.bool_)
    for y in range(height):
        for x in range(width):
            if state[y, x] == _FIXED:
                has_fixed[y // _TILE, x // _TILE] = True
    tile_reach = (reach + _TILE - 1) // _TILE
    near = np.zeros((tiles_y, tiles_x), dtype=np.bool_)
    for ty in range(tiles_y):
        for tx in range(tiles_x):
            if has_fixed[ty, tx]:
                near[max(ty - tile_reach, 0): ty + tile_reach + 1, max(tx - tile_reach, 0): tx + tile_reach + 1] = True
    run = 0
    for y in range(height):
        first = run
        for tx in range(tiles_x):
            if near[y // _TILE, tx] and (tx == 0 or not near[y // _TILE, tx - 1]):
                starts[run] = tx * _TILE
            if near[y // _TILE, tx] and (tx == tiles_x - 1 or not near[y // _TILE, tx + 1]):
                stops[run] = min((tx + 1) * _TILE, width)
                run += 1
        counts[y] = run - first
    return run


@kernel
def _relax(state, values, row_runs, starts, stops, sweeps, omega):
    """Red-black Gauss-Seidel with over-relaxation on the unknown cells of the row runs
    (row ``y`` owns runs ``row_runs[y]:row_runs[y + 1]``, each ``[start, stop)``)."""
    height, width = state.shape
    for _ in range(sweeps):
        for colour in range(2):
            for y in range(height):
                for run in range(row_runs[y], row_runs[y + 1]):
                    start = starts[run]
                    for x in range(start + (start + y + colour) % 2, stops[run], 2):
                        if state[y, x] != _UNKNOWN:
                            continue
                        count = 0
                        total = np.float32(0.0)
                        if x > 0 and state[y, x - 1] != _OUTSIDE:
                            count += 1
                            total += values[y, x - 1]
                        if x < width - 1 and state[y, x + 1] != _OUTSIDE:
                            count += 1
                            total += values[y, x + 1]
                        if y > 0 and state[y - 1, x] != _OUTSIDE:
                            count += 1
                            total += values[y - 1, x]
                        if y < height - 1 and state[y + 1, x] != _OUTSIDE:
                            count += 1
                            total += values[y + 1, x]
                        if count > 0:
                            values[y, x] += omega * (total / count - values[y, x])


@kernel
def _solve_levels(states, shapes, cell_offsets, row_offsets, row_runs, starts, stops, values, fields, sweeps):
    """The cascadic solve of both channels of ``values`` (H, W, 2), one after the other,
    on the planar work space ``fields`` (2, cells). The levels are packed
    finest first: level ``l`` has shape ``shapes[l]``, its cells start at
    ``cell_offsets[l]`` and its rows at ``row_offsets[l]`` of ``row_runs``."""
    height, width = values.shape[:2]
    levels = shapes.shape[0]
    for channel in range(2):
        field = fields[channel]
        for y in range(height):
            for x in range(width):
                field[y * width + x] = values[y, x, channel]
        grids = []
        for level in range(levels):
            cells = slice(cell_offsets[level], cell_offsets[level + 1])
            shape = (shapes[level, 0], shapes[level, 1])
            grids.append((states[cells].reshape(shape), field[cells].reshape(shape)))
        for level in range(1, levels):
            _restrict_values(grids[level - 1][0], grids[level - 1][1], grids[level][0], grids[level][1])
        for level in range(levels - 1, -1, -1):
            state, level_values = grids[level]
            if level < levels - 1:
                _prolong(grids[level + 1][0], grids[level + 1][1], state, level_values)
            runs = row_runs[row_offsets[level]: row_offsets[level] + shapes[level, 0] + 1]
            level_sweeps = sweeps if level < levels - 1 else _COARSEST_SWEEPS
            _relax(state, level_values, runs, starts, stops, level_sweeps, np.float32(_OMEGA))
    for y in range(height):
        for x in range(width):
            values[y, x, 0] = fields[0, y * width + x]
            values[y, x, 1] = fields[1, y * width + x]


def _fill_interior(values: np.ndarray, state: np.ndarray, *, sweeps: int) -> None:
    """Solve Laplace's equation in place on the unknown cells of ``state``.

    Cascadic multigrid: a full relaxation on the coarsest grid, then on each finer grid
    the prolonged solution is relaxed only near the fixed cells (where the prolongation
    errs); farther away it is already smooth, and ``sweeps`` sweeps would carry a
    correction only about ``2·sweeps`` cells anyway.
    """
    states = [state]
    while max(states[-1].shape) > _COARSEST_SIDE:
        fine = states[-1]
        coarse = np.empty(((fine.shape[0] + 1) // 2, (fine.shape[1] + 1) // 2), dtype=np.int8)
        _restrict_state(fine, coarse)
        states.append(coarse)
    heights = np.array([level.shape[0] for level in states])
    row_offsets = np.cumsum(heights) - heights
    run_counts = np.zeros(heights.sum() + 1, dtype=np.int64)
    starts, stops = [], []
    for level, level_state in enumerate(states):
        counts = run_counts[row_offsets[level] + 1: row_offsets[level] + 1 + level_state.shape[0]]
        if level == len(states) - 1:  # the coarsest grid is relaxed everywhere
            counts[...] = 1
            starts.append(np.zeros(level_state.shape[0], dtype=np.int64))
            stops.append(np.full(level_state.shape[0], level_state.shape[1], dtype=np.int64))
            continue
        most = level_state.shape[0] * ((level_state.shape[1] + _TILE - 1) // _TILE // 2 + 1)
        level_starts = np.empty(most, dtype=np.int64)
        level_stops = np.empty(most, dtype=np.int64)
        count = _runs_near_fixed(level_state, 2 * sweeps, counts, level_starts, level_stops)
        starts.append(level_starts[:count])
        stops.append(level_stops[:count])
    cell_offsets = np.concatenate([[0], np.cumsum([level.size for level in states])])
    _solve_levels(
        np.concatenate([level.ravel() for level in states]),
        np.array([level.shape for level in states], dtype=np.int64),
        cell_offsets,
        row_offsets,
        np.cumsum(run_counts),
        np.concatenate(starts),
        np.concatenate(stops),
        values,
        np.empty((2, cell_offsets[-1]), dtype=np.float32),
        sweeps,
    )


def flow_from_distances(
    dist_prev: np.ndarray, dist_cur: np.ndarray, mask: np.ndarray, *, sweeps: int = 8
) -> np.ndarray:
    """Estimate the motion of a mask between two frames from their signed distances.

    Parameters
    ----------
    dist_prev, dist_cur : (H, W) float32
        Signed distances (positive inside) of the earlier and the later frame; they may
        be smoothed along time.
    mask : (H, W) bool
        The mask whose inner boundary carries the estimate (pixels inside with a
        4-neighbour outside): the measured normal velocity plus the tangential part of
        the affine motion fitted to its connected component (see the module notes);
        every other pixel gets the harmonic interpolation of the boundary values (zero
        normal derivative at the image edges).
    sweeps : int
        Red-black relaxation sweeps per multigrid level.

    Returns
    -------
    (H, W, 2) float32
        ``(dx, dy)`` in px/frame, pointing the way the boundary moves.
    """
    one_hot = np.eye(2, dtype=np.float32)
    return flow_from_distance_stack(np.stack([dist_prev, dist_cur]), one_hot[0], one_hot[1], mask, sweeps=sweeps)


def flow_from_distance_stack(
    dists: np.ndarray, prev_weights: np.ndarray, cur_weights: np.ndarray, mask: np.ndarray, *, sweeps: int = 8
) -> np.ndarray:
    """:func:`flow_from_distances` of two weighted sums of a stack of distance fields.

    ``dist_prev = sum_k prev_weights[k] · dists[k]`` and likewise ``dist_cur``, e.g.
    temporal filters over a ring of frames; the sums are only evaluated on the boundary,
    where they are needed.

    Parameters
    ----------
    dists : (K, H, W) float32
    prev_weights, cur_weights : (K,) float32
    mask, sweeps
        As for :func:`flow_from_distances`.

    Returns
    -------
    (H, W, 2) float32
    """
    dists = np.ascontiguousarray(dists, dtype=np.float32)
    prev_weights = np.ascontiguousarray(prev_weights, dtype=np.float32)
    cur_weights = np.ascontiguousarray(cur_weights, dtype=np.float32)
    mask = np.ascontiguousarray(mask, dtype=np.bool_)
    if mask.ndim != 2 or dists.ndim != 3 or dists.shape[1:] != mask.shape:
        raise ValueError(f"flow_from_distances: shapes do not fit: dists {dists.shape}, mask {mask.shape}")
    if prev_weights.shape != dists.shape[:1] or cur_weights.shape != dists.shape[:1]:
        raise ValueError(
            f"flow_from_distances: {prev_weights.shape} and {cur_weights.shape} weights for {dists.shape[0]} fields"
        )
    if sweeps < 1:
        raise ValueError(f"sweeps must be at least 1, got {sweeps}")
    normal = np.empty(mask.shape + (2,), dtype=np.float32)
    speed = np.empty(mask.shape, dtype=np.float32)
    state = np.empty(mask.shape, dtype=np.int8)
    _boundary_velocity(dists, prev_weights, cur_weights, mask, normal, speed, state)
    labels, geometry, motions = _fit_affine_motions(normal, speed, state, mask)
    flow = np.empty(mask.shape + (2,), dtype=np.float32)
    _boundary_values(normal, speed, state, labels, geometry, motions, flow)
    _fill_interior(flow, state, sweeps=sweeps)
    return flow


def harmonic_fill(values: np.ndarray, fixed: np.ndarray, domain: np.ndarray, *, sweeps: int = 8) -> np.ndarray:
    """Interpolate ``values`` from the ``fixed`` pixels over ``domain`` (Laplace's equation).

    Parameters
    ----------
    values : (H, W, 2) float32
        Boundary values, read where ``fixed``.
    fixed, domain : (H, W) bool
        Dirichlet pixels, and the region to solve on (``fixed`` is part of it); the
        edges of the domain that are not fixed have zero normal derivative.

    Returns
    -------
    (H, W, 2) float32, zero outside ``domain``.
    """
    values = np.asarray(values, dtype=np.float32)
    fixed = np.asarray(fixed, dtype=bool)
    domain = np.asarray(domain, dtype=bool)
    if values.shape != fixed.shape + (2,) or fixed.shape != domain.shape or fixed.ndim != 2:
        raise ValueError(f"harmonic_fill: shapes {values.shape}, {fixed.shape}, {domain.shape} do not fit")
    state = np.where(fixed & domain, _FIXED, np.where(domain, _UNKNOWN, _OUTSIDE)).astype(np.int8)
    out = np.where((state == _FIXED)[:, :, None], values, np.float32(0.0)).astype(np.float32)
    _fill_interior(out, state, sweeps=sweeps)
    return out


#: Pixels summed over all slots at a time, so the partial sums stay in cache.
_SUM_BLOCK = 4096


@kernel
def _weighted_sum(stack, slot_weights, out):
    count, size = stack.shape
    for block in range((size + _SUM_BLOCK - 1) // _SUM_BLOCK):
        start = block * _SUM_BLOCK
        stop = min(start + _SUM_BLOCK, size)
        for i in range(start, stop):
            out[i] = 0.0
        for slot in range(count):
            weight = slot_weights[slot]
            if weight != 0.0:
                for i in range(start, stop):
                    out[i] += weight * stack[slot, i]


def weighted_sum(stack: np.ndarray, slot_weights: np.ndarray) -> np.ndarray:
    """``sum_k slot_weights[k] · stack[k]`` over the first axis (a temporal filter).

    Parameters
    ----------
    stack : (K, H, ...) float32
    slot_weights : (K,) float32

    Returns
    -------
    (H, ...) float32
    """
    stack = np.ascontiguousarray(stack, dtype=np.float32)
    slot_weights = np.ascontiguousarray(slot_weights, dtype=np.float32)
    if slot_weights.shape != stack.shape[:1]:
        raise ValueError(f"weighted_sum: {slot_weights.shape[0]} weights for {stack.shape[0]} slots")
    out = np.empty(stack.shape[1:], dtype=np.float32)
    _weighted_sum(stack.reshape(stack.shape[0], -1), slot_weights, out.reshape(-1))
    return out
