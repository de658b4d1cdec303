"""The patch cost of generalized PatchMatch: what a match costs, and how the features it
compares are stored.

The cost of matching target pixel q to source patch ``(i, x, y, θ)`` is a sum over the
n×n window of

* a weighted SSD of features (colour first, then guides). Features are stored as 16-bit
  codes over each feature's range, the weights scaled to match (see :class:`PatchCost`);
  features may further be scaled per target pixel by a weight map (e.g. the temporal
  modulation m(q)), evaluated at the window's target pixel;
* optionally ``w_dir · min(|tan(S_dir − θ − T_dir)|, clamp)`` (orientation term);
* optionally, when source and target flows point roughly opposite ways
  (``cos(S_dir(p) − θ − T_dir(q)) < 0`` at the centres), a permutation of the source
  features (e.g. swap ext+ and ext−).

Summation stops early once the partial sum exceeds a bound (the search's current best).

The search (:mod:`fluidymation.engine.patchmatch`) knows none of this, as EbSynth's
search knows only the patch-SSD object it is given: it takes the cost as one numba tuple
(:class:`KernelCost`, from :meth:`PatchCost.kernel_cost`) and hands it to the kernels
here, which take it first: :func:`_patch_cost` for any candidate; for unrotated integer
candidates of a plain cost, checked with :func:`_is_plain_window`, the row-wise SSD
:func:`_plain_window_cost`; for turned ones (flow-aligned synthesis) :func:`_rotated_cost`,
a float32 cost whose feature loop vectorizes; a random candidate's two flow-aligned angles share their samples in
:func:`_flow_pair_cost`; :func:`_prefetch_window` starts loading a candidate's data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from fluidymation.engine._jit import inline_kernel, kernel, prefetch, run_parts
from fluidymation.engine.sampling import _bilinear_setup

_CODE = np.uint16
_CODE_MAX = float(np.iinfo(_CODE).max)


@kernel
def _window_ssd(source_rows, target_rows, run_weights, source_height, radius, frame, sx, sy, tx, ty, bound):
    """Weighted SSD of the unrotated n×n windows around source ``(frame, sx, sy)`` and target
    ``(tx, ty)``, both inside their images; rows are read as contiguous runs of n·F codes."""
    length = run_weights.shape[0]
    features = length // (2 * radius + 1)
    source_row = frame * source_height + sy - radius
    source_column = (sx - radius) * features
    target_column = (tx - radius) * features
    total = np.float32(0.0)
    for dy in range(2 * radius + 1):
        source_run = source_rows[source_row + dy, source_column:source_column + length]
        target_run = target_rows[ty - radius + dy, target_column:target_column + length]
        row_total = np.float32(0.0)
        for k in range(length):
            d = np.float32(source_run[k]) - np.float32(target_run[k])
            row_total += run_weights[k] * d * d
        total += row_total
        if total > bound:
            return total
    return total


@inline_kernel
def _plain_window_cost(cost, frame, sx, sy, tx, ty, bound):
    """The cost of the integer, unturned candidate ``(frame, sx, sy)`` at target ``(tx, ty)``
    where :func:`_is_plain_window` holds: the row-wise :func:`_window_ssd`."""
    return _window_ssd(
        cost.source_rows, cost.target_rows, cost.run_weights, cost.source.shape[1], cost.radius, np.int64(frame),
        np.int64(sx), np.int64(sy), np.int64(tx), np.int64(ty), np.float32(bound),
    )


@inline_kernel
def _is_plain_window(cost, tx, ty, x, y, theta):
    """Whether a candidate's cost is :func:`_plain_window_cost` (a plain cost, θ = 0, integer
    position, both windows inside): checked before calling it, which is cheaper than a
    call of :func:`_patch_cost` with all its arrays."""
    source_height = cost.source.shape[1]
    source_width = cost.source.shape[2]
    height = cost.target.shape[0]
    width = cost.target.shape[1]
    radius = cost.radius
    sx = int(x)
    sy = int(y)
    return (
        cost.plain and theta == 0.0 and x == sx and y == sy
        and radius <= sx < source_width - radius and radius <= sy < source_height - radius
        and radius <= tx < width - radius and radius <= ty < height - radius
    )


@kernel
def _patch_cost(cost, tx, ty, frame, x, y, theta, bound):
    """The cost of source patch ``(frame, x, y, θ)`` at target pixel ``(tx, ty)``, any
    candidate (stops once over ``bound``).

    Callers pass int64 ``tx``, ``ty`` and ``frame`` and float32 ``x``, ``y``, ``θ`` and ``bound``:
    every other mix of types would be compiled again (seconds each, on a first run)."""
    source = cost.source
    target = cost.target
    feature_weights = cost.feature_weights
    feature_start = cost.feature_start
    plain_end = cost.plain_end
    group_ends = cost.group_ends
    weight_maps = cost.weight_maps
    opposite_feature = cost.opposite_feature
    source_angle = cost.source_angle
    target_angle = cost.target_angle
    orientation_weight = cost.orientation_weight
    orientation_clamp = cost.orientation_clamp
    radius = cost.radius
    height = target.shape[0]
    width = target.shape[1]
    source_height = source.shape[1]
    source_width = source.shape[2]
    groups = group_ends.shape[0]
    opposite = False
    if cost.use_opposite:
        centre_angle = source_angle[frame, int(y + 0.5), int(x + 0.5)]
        opposite = math.cos(centre_angle - theta - target_angle[ty, tx]) < 0.0
    total = np.float32(0.0)
    sx = int(x)
    sy = int(y)
    if (
        theta == 0.0 and x == sx and y == sy and not opposite and orientation_weight == 0.0
        and radius <= sx < source_width - radius and radius <= sy < source_height - radius
    ):
        if (
            groups == 0 and feature_start == 0
            and radius <= tx < width - radius and radius <= ty < height - radius
        ):
            return _window_ssd(
                cost.source_rows, cost.target_rows, cost.run_weights, source_height, radius, frame, sx, sy, tx, ty,
                bound,
            )
        for dy in range(-radius, radius + 1):
            qy = ty + dy
            if qy < 0 or qy >= height:
                continue
            py = sy + dy
            for dx in range(-radius, radius + 1):
                qx = tx + dx
                if qx < 0 or qx >= width:
                    continue
                px = sx + dx
                for c in range(feature_start, plain_end):
                    d = np.float32(source[frame, py, px, c]) - np.float32(target[qy, qx, c])
                    total += feature_weights[c] * d * d
                start = plain_end
                for g in range(groups):
                    part = np.float32(0.0)
                    for c in range(max(start, feature_start), group_ends[g]):
                        d = np.float32(source[frame, py, px, c]) - np.float32(target[qy, qx, c])
                        part += feature_weights[c] * d * d
                    total += weight_maps[g, qy, qx] * part
                    start = group_ends[g]
            if total > bound:
                return total
        return total
    if theta != 0.0:
        return _rotated_cost(
            cost, tx, ty, frame, x, y, theta, np.float32(math.cos(theta)), np.float32(math.sin(theta)), opposite, bound,
        )
    # unturned, but off the integer grid, swapped, with the orientation term or over the source's border
    cos_t = math.cos(theta)
    sin_t = math.sin(theta)
    for dy in range(-radius, radius + 1):
        qy = ty + dy
        if qy < 0 or qy >= height:
            continue
        for dx in range(-radius, radius + 1):
            qx = tx + dx
            if qx < 0 or qx >= width:
                continue
            sample_x = x + cos_t * dx - sin_t * dy
            sample_y = y + sin_t * dx + cos_t * dy
            x0, y0, x1, y1, w00, w10, w01, w11 = _bilinear_setup(sample_x, sample_y, source_height, source_width)
            start = feature_start
            for g in range(-1, groups):
                end = plain_end if g < 0 else group_ends[g]
                part = np.float32(0.0)
                for c in range(start, end):
                    sc = opposite_feature[c] if opposite else c
                    value = (
                        w00 * source[frame, y0, x0, sc]
                        + w10 * source[frame, y0, x1, sc]
                        + w01 * source[frame, y1, x0, sc]
                        + w11 * source[frame, y1, x1, sc]
                    )
                    d = value - np.float32(target[qy, qx, c])
                    part += feature_weights[c] * d * d
                total += part if g < 0 else weight_maps[g, qy, qx] * part
                start = max(end, feature_start)
            if orientation_weight > 0.0:
                nearest_x = int(min(max(sample_x + 0.5, 0.0), source_width - 1.0))
                nearest_y = int(min(max(sample_y + 0.5, 0.0), source_height - 1.0))
                turn = source_angle[frame, nearest_y, nearest_x] - theta - target_angle[qy, qx]
                total += orientation_weight * min(abs(math.tan(turn)), orientation_clamp)
        if total > bound:
            return total
    return total


@inline_kernel
def _rotated_cost(cost, tx, ty, frame, x, y, theta, cos_t, sin_t, opposite, bound):
    """The cost of a candidate turned by θ (``cos_t``, ``sin_t`` given) or at a fractional
    position: bilinear samples in float32 against the target's features and per-pixel
    weights (their swapped copies when ``opposite``), one contiguous run of features per
    sample so the feature loop vectorizes. It stops as soon as the partial sum exceeds
    ``bound`` (most random candidates are refused within the first few pixels)."""
    source_rows = cost.source_rows
    target_rows = cost.target_rows
    target_weight_rows = cost.target_weight_rows
    source_angle = cost.source_angle
    target_angle = cost.target_angle
    orientation_weight = cost.orientation_weight
    orientation_clamp = cost.orientation_clamp
    feature_start = cost.feature_start
    radius = cost.radius
    source_height = cost.source.shape[1]
    source_width = cost.source.shape[2]
    features = source_rows.shape[1] // source_width
    height = target_rows.shape[0]
    width = target_rows.shape[1] // features
    if opposite:
        target_rows = cost.swapped_rows
        target_weight_rows = cost.swapped_weight_rows
    length = features - feature_start
    per_pixel = target_weight_rows.shape[0] * target_weight_rows.shape[1] > features
    high_x = np.float32(source_width - 1)
    high_y = np.float32(source_height - 1)
    one = np.float32(1.0)
    frame_row = frame * source_height
    total = np.float32(0.0)
    for dy in range(-radius, radius + 1):
        qy = ty + dy
        if qy < 0 or qy >= height:
            continue
        for dx in range(-radius, radius + 1):
            qx = tx + dx
            if qx < 0 or qx >= width:
                continue
            sample_x = min(max(x + cos_t * np.float32(dx) - sin_t * np.float32(dy), np.float32(0.0)), high_x)
            sample_y = min(max(y + sin_t * np.float32(dx) + cos_t * np.float32(dy), np.float32(0.0)), high_y)
            x0 = int(sample_x)
            y0 = int(sample_y)
            fx = sample_x - np.float32(x0)
            fy = sample_y - np.float32(y0)
            w00 = (one - fx) * (one - fy)
            w10 = fx * (one - fy)
            w01 = (one - fx) * fy
            w11 = fx * fy
            row0 = frame_row + y0
            row1 = frame_row + min(y0 + 1, source_height - 1)
            column0 = x0 * features + feature_start
            column1 = min(x0 + 1, source_width - 1) * features + feature_start
            target_column = qx * features + feature_start
            s00 = source_rows[row0, column0:column0 + length]
            s10 = source_rows[row0, column1:column1 + length]
            s01 = source_rows[row1, column0:column0 + length]
            s11 = source_rows[row1, column1:column1 + length]
            t = target_rows[qy, target_column:target_column + length]
            if per_pixel:
                w = target_weight_rows[qy, target_column:target_column + length]
            else:
                w = target_weight_rows[0, feature_start:features]
            part = np.float32(0.0)
            for k in range(length):
                value = (
                    w00 * np.float32(s00[k]) + w10 * np.float32(s10[k])
                    + w01 * np.float32(s01[k]) + w11 * np.float32(s11[k])
                )
                d = value - np.float32(t[k])
                part += w[k] * d * d
            total += part
            if orientation_weight > 0.0:
                nearest_x = int(sample_x + np.float32(0.5))
                nearest_y = int(sample_y + np.float32(0.5))
                turn = source_angle[frame, nearest_y, nearest_x] - theta - target_angle[qy, qx]
                total += orientation_weight * min(abs(math.tan(turn)), orientation_clamp)
            if total > bound:
                return total
    return total


@inline_kernel
def _flow_pair_cost(cost, tx, ty, frame, x, y, theta, cos_t, sin_t, bound):
    """The costs of a candidate at both flow-aligned angles: θ (``cos_t``, ``sin_t`` given) with
    the features as they are, and θ + π with the swapped features, as two :func:`_rotated_cost`
    calls would give them (up to the order of summation).

    θ lays the source flow at the centre onto the target's, so the flows there agree at θ and
    are opposite at θ + π. Turned by π the patch samples the source at the offsets of θ
    mirrored through the centre: each bilinear sample serves both angles, θ's target pixel
    ``q + d`` and θ + π's ``q − d``. Stops once both partial sums exceed ``bound``."""
    source_rows = cost.source_rows
    target_rows = cost.target_rows
    target_weight_rows = cost.target_weight_rows
    swapped_rows = cost.swapped_rows
    swapped_weight_rows = cost.swapped_weight_rows
    source_angle = cost.source_angle
    target_angle = cost.target_angle
    orientation_weight = cost.orientation_weight
    orientation_clamp = cost.orientation_clamp
    feature_start = cost.feature_start
    radius = cost.radius
    source_height = cost.source.shape[1]
    source_width = cost.source.shape[2]
    features = source_rows.shape[1] // source_width
    height = target_rows.shape[0]
    width = target_rows.shape[1] // features
    length = features - feature_start
    per_pixel = target_weight_rows.shape[0] * target_weight_rows.shape[1] > features
    high_x = np.float32(source_width - 1)
    high_y = np.float32(source_height - 1)
    one = np.float32(1.0)
    flipped = theta + np.float32(math.pi)
    frame_row = frame * source_height
    first = np.float32(0.0)
    second = np.float32(0.0)
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            qx = tx + dx
            qy = ty + dy
            mx = tx - dx
            my = ty - dy
            use_first = first <= bound and 0 <= qx < width and 0 <= qy < height
            use_second = second <= bound and 0 <= mx < width and 0 <= my < height
            if not (use_first or use_second):
                continue
            sample_x = min(max(x + cos_t * np.float32(dx) - sin_t * np.float32(dy), np.float32(0.0)), high_x)
            sample_y = min(max(y + sin_t * np.float32(dx) + cos_t * np.float32(dy), np.float32(0.0)), high_y)
            x0 = int(sample_x)
            y0 = int(sample_y)
            fx = sample_x - np.float32(x0)
            fy = sample_y - np.float32(y0)
            w00 = (one - fx) * (one - fy)
            w10 = fx * (one - fy)
            w01 = (one - fx) * fy
            w11 = fx * fy
            row0 = frame_row + y0
            row1 = frame_row + min(y0 + 1, source_height - 1)
            column0 = x0 * features + feature_start
            column1 = min(x0 + 1, source_width - 1) * features + feature_start
            s00 = source_rows[row0, column0:column0 + length]
            s10 = source_rows[row0, column1:column1 + length]
            s01 = source_rows[row1, column0:column0 + length]
            s11 = source_rows[row1, column1:column1 + length]
            first_column = qx * features + feature_start
            second_column = mx * features + feature_start
            t = target_rows[qy if use_first else my, first_column if use_first else second_column:][:length]
            u = swapped_rows[my if use_second else qy, second_column if use_second else first_column:][:length]
            if per_pixel:
                w = target_weight_rows[qy if use_first else my, first_column if use_first else second_column:][:length]
                v = swapped_weight_rows[my if use_second else qy, second_column if use_second else first_column:][:length]
            else:
                w = target_weight_rows[0, feature_start:features]
                v = swapped_weight_rows[0, feature_start:features]
            part_first = np.float32(0.0)
            part_second = np.float32(0.0)
            for k in range(length):
                value = (
                    w00 * np.float32(s00[k]) + w10 * np.float32(s10[k])
                    + w01 * np.float32(s01[k]) + w11 * np.float32(s11[k])
                )
                d = value - np.float32(t[k])
                part_first += w[k] * d * d
                e = value - np.float32(u[k])
                part_second += v[k] * e * e
            if orientation_weight > 0.0:
                nearest_x = int(sample_x + np.float32(0.5))
                nearest_y = int(sample_y + np.float32(0.5))
                along = source_angle[frame, nearest_y, nearest_x]
                if use_first:
                    part_first += orientation_weight * min(abs(math.tan(along - theta - target_angle[qy, qx])),
                                                           orientation_clamp)
                if use_second:
                    part_second += orientation_weight * min(abs(math.tan(along - flipped - target_angle[my, mx])),
                                                            orientation_clamp)
            if use_first:
                first += part_first
            if use_second:
                second += part_second
    return first, second


@inline_kernel
def _prefetch_window(cost, frame, x, y):
    """Start loading the source rows the cost of integer candidate ``(frame, x, y)`` reads."""
    source_rows = cost.source_rows
    radius = cost.radius
    source_height = cost.source.shape[1]
    source_width = cost.source.shape[2]
    features = source_rows.shape[1] // source_width
    first = max(x - radius, 0) * features
    last = (min(x + radius, source_width - 1) + 1) * features - 1
    line = 64 // source_rows.itemsize
    for dy in range(-radius, radius + 1):
        row = (frame * source_height + min(max(y + dy, 0), source_height - 1)) * source_rows.shape[1]
        for index in range(row + first, row + last, line):
            prefetch(source_rows, index)
        prefetch(source_rows, row + last)


@kernel
def _evaluate(cost, nnf_frame, nnf_coords, out, part, parts):
    height, width = nnf_frame.shape
    for ty in range(part, height, parts):
        for tx in range(width):
            frame = nnf_frame[ty, tx]
            if frame < 0:
                out[ty, tx] = np.inf
                continue
            out[ty, tx] = _patch_cost(
                cost, np.int64(tx), np.int64(ty), np.int64(frame), nnf_coords[ty, tx, 0], nnf_coords[ty, tx, 1],
                nnf_coords[ty, tx, 2], np.float32(np.inf),
            )


@dataclass(frozen=True)
class PatchCost:
    """Kernel-ready description of the patch distance at one pyramid level.

    Build it with :func:`build_patch_cost`. Features are ordered: colour, guides without
    a weight map, then guides grouped by weight map. They are stored as 16-bit codes
    ``round((value − offset) · scale)`` per feature, spanning the feature's range (half
    the cache footprint of float32; the random search is bound by cache misses); the cost
    weighs squared code differences by ``weight / scale²``.

    Attributes
    ----------
    source_features : ndarray, shape (T, Hs, Ws, F), uint16
    target_features : ndarray, shape (H, W, F), uint16
        Its first ``colour_channels`` features are rewritten after every vote.
    feature_offset, feature_scale : ndarray, shape (F,), float32
        Quantization of each feature; swapped features share theirs.
    feature_weights : ndarray, shape (F,), float32
        ``weight / scale²``: the weight of a squared code difference.
    colour_channels : int
    plain_end : int
        Features ``[0, plain_end)`` have no per-pixel weight map.
    group_ends : ndarray, shape (M,), int64
        Map m weighs features ``[group_ends[m-1] (or plain_end), group_ends[m])``.
    weight_maps : ndarray, shape (M, H, W), float32
    opposite_feature : ndarray, shape (F,), int64
        Source feature compared with target feature f when the flows are opposite.
    use_opposite : bool
    source_angle, target_angle : ndarray, (T, Hs, Ws) and (H, W), float32
        Flow orientations (radians); unused with rotation 'none', then any 1-pixel arrays (numba needs arrays).
    orientation_weight, orientation_clamp : float
    source_segment : ndarray, shape (T, Hs, Ws), int32
    target_segment : ndarray, shape (H, W), int32
    patch_size : int
    target_weights : ndarray, shape (H, W, F) or (1, 1, F), float32
        ``feature_weights`` times each feature's weight map at each target pixel (one row
        when there are no maps), for the rotated cost.
    swapped_features, swapped_weights : ndarray
        ``target_features`` and ``target_weights`` with the features permuted by
        ``opposite_feature`` (the same arrays when nothing is swapped): where the flows are
        opposite the rotated cost compares them with the unpermuted source.
    feature_start : int
        First feature summed (``colour_channels`` for a guides-only pass).
    """

    source_features: np.ndarray
    target_features: np.ndarray
    feature_offset: np.ndarray
    feature_scale: np.ndarray
    feature_weights: np.ndarray
    colour_channels: int
    plain_end: int
    group_ends: np.ndarray
    weight_maps: np.ndarray
    opposite_feature: np.ndarray
    use_opposite: bool
    source_angle: np.ndarray
    target_angle: np.ndarray
    orientation_weight: float
    orientation_clamp: float
    source_segment: np.ndarray
    target_segment: np.ndarray
    patch_size: int
    target_weights: np.ndarray
    swapped_features: np.ndarray
    swapped_weights: np.ndarray
    feature_start: int = 0

    def guides_only(self):
        """The same cost with the colour features left out."""
        return replace(self, feature_start=self.colour_channels)

    def set_target_colour(self, colour):
        """Store the current target colour (H, W, Cc) float32 into the target features."""
        columns = np.arange(self.colour_channels)
        _quantize(colour, self.feature_offset, self.feature_scale, self.target_features, columns)
        if self.swapped_features is not self.target_features:  # colours are never swapped
            _quantize(colour, self.feature_offset, self.feature_scale, self.swapped_features, columns)

    def kernel_cost(self):
        """This cost as the kernels take it (see :class:`KernelCost`)."""
        frames, source_height, source_width, features = self.source_features.shape
        height, width = self.target_features.shape[:2]
        return KernelCost(
            self.source_features, self.target_features,
            self.source_features.reshape(frames * source_height, source_width * features),
            self.target_features.reshape(height, width * features), self.feature_weights,
            np.tile(self.feature_weights, self.patch_size), self.feature_start, self.plain_end, self.group_ends,
            self.weight_maps, self.opposite_feature, self.source_angle, self.target_angle,
            np.float32(self.orientation_weight), np.float32(self.orientation_clamp), self.use_opposite,
            self.patch_size // 2, _rows(self.target_weights), _rows(self.swapped_features), _rows(self.swapped_weights),
            plain=(
                self.group_ends.shape[0] == 0 and self.feature_start == 0 and not self.use_opposite
                and self.orientation_weight == 0.0
            ),
        )


class KernelCost(NamedTuple):
    """A :class:`PatchCost` as one argument of numba kernels (a named tuple): its arrays,
    the views the kernels read, and scalars in the kernels' types.

    Attributes
    ----------
    source, target : ndarray
        ``source_features`` and ``target_features``.
    source_rows, target_rows : ndarray, shape (T·Hs, Ws·F) and (H, W·F), uint16
        The same codes, a row of pixels per row.
    run_weights : ndarray, shape (n·F,), float32
        ``feature_weights`` repeated for the n pixels of a window row.
    radius : int
        ``patch_size // 2``.
    target_weight_rows, swapped_rows, swapped_weight_rows : ndarray
        ``target_weights``, ``swapped_features`` and ``swapped_weights``, a row of pixels per row.
    plain : bool
        The cost is the weighted SSD of all features: no weight map, no swap, no orientation term.
    feature_weights, feature_start, plain_end, group_ends, weight_maps, opposite_feature, source_angle,
    target_angle, orientation_weight, orientation_clamp, use_opposite
        As in :class:`PatchCost`.
    """

    source: np.ndarray
    target: np.ndarray
    source_rows: np.ndarray
    target_rows: np.ndarray
    feature_weights: np.ndarray
    run_weights: np.ndarray
    feature_start: int
    plain_end: int
    group_ends: np.ndarray
    weight_maps: np.ndarray
    opposite_feature: np.ndarray
    source_angle: np.ndarray
    target_angle: np.ndarray
    orientation_weight: np.float32
    orientation_clamp: np.float32
    use_opposite: bool
    radius: int
    target_weight_rows: np.ndarray
    swapped_rows: np.ndarray
    swapped_weight_rows: np.ndarray
    plain: bool


def _rows(array):
    """(H, W, F) as (H, W·F)."""
    return array.reshape(array.shape[0], -1)


@dataclass(frozen=True)
class SourceFeatures:
    """The source half of a :class:`PatchCost`: quantized features and their layout.

    Build it with :func:`quantize_source`; it can serve many targets (every frame of a
    sequence) as long as their values lie inside the quantization ranges (others are
    clipped to them).

    Attributes
    ----------
    codes : ndarray, shape (T, Hs, Ws, F), uint16
        Colour, guides without a weight map, then guides grouped by weight map.
    offset, scale : ndarray, shape (F,), float32
        Quantization of each feature: ``round((value − offset) · scale)``.
    colour_channels : int
    guide_order : ndarray of int, shape (G,)
        The caller's guide channel stored at each guide feature.
    guide_columns : ndarray of int, shape (G,)
        The feature storing each of the caller's guide channels.
    guide_weight_map : ndarray of int, shape (G,)
        Weight map of each guide (caller's order), -1 for none.
    opposite_feature : ndarray, shape (F,), int64
    use_opposite : bool
    """

    codes: np.ndarray
    offset: np.ndarray
    scale: np.ndarray
    colour_channels: int
    guide_order: np.ndarray
    guide_columns: np.ndarray
    guide_weight_map: np.ndarray
    opposite_feature: np.ndarray
    use_opposite: bool


def quantize_source(source_colour, source_guides, *, guide_weight_map=None, opposite_guide=None, low=None, high=None):
    """Quantize the source features over ranges that also cover given target values.

    Parameters
    ----------
    source_colour : ndarray, shape (T, Hs, Ws, Cc), float32
    source_guides : ndarray, shape (T, Hs, Ws, G), float32
    guide_weight_map : array-like of int, shape (G,), optional
        Index of the weight map that scales each guide channel, -1 for none.
    opposite_guide : array-like of int, shape (G,), optional
        Source guide channel compared with guide g when flows are opposite.
    low, high : array-like, shape (Cc + G,), optional
        Values (colour, then guides in the caller's order) each range must include
        besides the source's own, e.g. the target's extremes.

    Returns
    -------
    SourceFeatures
    """
    source_colour = np.asarray(source_colour, np.float32)
    source_guides = np.asarray(source_guides, np.float32)
    frames, source_height, source_width, colours = source_colour.shape
    guides = source_guides.shape[3]
    if guide_weight_map is None:
        guide_weight_map = np.full(guides, -1, np.int64)
    guide_weight_map = np.asarray(guide_weight_map, np.int64).reshape(guides)
    # order guides: no map first, then by map index (stable)
    order = np.argsort(np.where(guide_weight_map < 0, -1, guide_weight_map), kind="stable")
    position = np.empty(guides, np.int64)
    position[order] = np.arange(guides)
    opposite_feature = np.arange(colours + guides, dtype=np.int64)
    use_opposite = opposite_guide is not None
    if use_opposite:
        opposite_guide = np.asarray(opposite_guide, np.int64).reshape(guides)
        opposite_feature[colours + position] = colours + position[opposite_guide]
        if (opposite_feature[opposite_feature] != np.arange(colours + guides)).any():
            raise ValueError(f"opposite_guide must swap guides (applied twice give each back), got {opposite_guide}")
    low_bound = np.concatenate([_channel_min(source_colour), _channel_min(source_guides)[order]])
    high_bound = np.concatenate([_channel_max(source_colour), _channel_max(source_guides)[order]])
    feature_order = np.concatenate([np.arange(colours), colours + order])
    if low is not None:
        low_bound = np.minimum(low_bound, np.asarray(low, np.float64).reshape(colours + guides)[feature_order])
    if high is not None:
        high_bound = np.maximum(high_bound, np.asarray(high, np.float64).reshape(colours + guides)[feature_order])
    for _ in range(colours + guides):  # features swapped with each other share one range
        low_bound = np.minimum(low_bound, low_bound[opposite_feature])
        high_bound = np.maximum(high_bound, high_bound[opposite_feature])
    span = high_bound - low_bound
    scale = np.where(span > 0, _CODE_MAX / np.where(span > 0, span, 1.0), 1.0).astype(np.float32)
    offset = low_bound.astype(np.float32)
    codes = np.empty((frames, source_height, source_width, colours + guides), _CODE)
    _quantize(source_colour, offset, scale, codes, np.arange(colours))
    _quantize(source_guides, offset, scale, codes, colours + position)  # no reordered copy of the guides
    return SourceFeatures(
        codes=codes, offset=offset, scale=scale, colour_channels=colours, guide_order=order,
        guide_columns=colours + position, guide_weight_map=guide_weight_map, opposite_feature=opposite_feature, use_opposite=use_opposite,
    )


def build_patch_cost(*, source_colour, source_guides, target_colour, target_guides, colour_weights, guide_weights,
                     guide_weight_map=None, weight_maps=None, opposite_guide=None, source_angle=None,
                     target_angle=None, orientation_weight=0.0, orientation_clamp=10.0, source_segment=None,
                     target_segment=None, patch_size=5):
    """Assemble a :class:`PatchCost` from colour and guide channels.

    The quantization ranges span both the source and the target values.

    Parameters
    ----------
    source_colour : ndarray, shape (T, Hs, Ws, Cc), float32
    source_guides : ndarray, shape (T, Hs, Ws, G), float32
    target_colour : ndarray, shape (H, W, Cc), float32
        The current synthesized colour.
    target_guides : ndarray, shape (H, W, G), float32
    colour_weights, guide_weights, weight_maps, source_angle, target_angle, orientation_weight,
    orientation_clamp, source_segment, target_segment, patch_size
        As in :func:`target_patch_cost`.
    guide_weight_map, opposite_guide
        As in :func:`quantize_source` (swapped guides must have equal weights).

    Returns
    -------
    PatchCost
    """
    target_colour = np.asarray(target_colour, np.float32)
    target_guides = np.asarray(target_guides, np.float32)
    features = quantize_source(
        source_colour, source_guides, guide_weight_map=guide_weight_map, opposite_guide=opposite_guide,
        low=np.concatenate([_channel_min(target_colour), _channel_min(target_guides)]),
        high=np.concatenate([_channel_max(target_colour), _channel_max(target_guides)]),
    )
    return target_patch_cost(
        features, target_colour=target_colour, target_guides=target_guides, colour_weights=colour_weights,
        guide_weights=guide_weights, weight_maps=weight_maps, source_angle=source_angle, target_angle=target_angle,
        orientation_weight=orientation_weight, orientation_clamp=orientation_clamp, source_segment=source_segment,
        target_segment=target_segment, patch_size=patch_size,
    )


def target_patch_cost(features, *, target_colour, target_guides, colour_weights, guide_weights, weight_maps=None,
                      source_angle=None, target_angle=None, orientation_weight=0.0, orientation_clamp=10.0,
                      source_segment=None, target_segment=None, patch_size=5):
    """Assemble a :class:`PatchCost` of a target against quantized source features.

    Parameters
    ----------
    features : SourceFeatures
    target_colour : ndarray, shape (H, W, Cc), float32
        The current synthesized colour.
    target_guides : ndarray, shape (H, W, G), float32
        Guides in the caller's order (as given to :func:`quantize_source`).
    colour_weights : array-like, shape (Cc,)
    guide_weights : array-like, shape (G,)
        Non-negative weights.
    weight_maps : ndarray, shape (M, H, W), float32, optional
        Per-target-pixel weight multipliers (``features.guide_weight_map`` indexes them).
    source_angle, target_angle : ndarray, (T, Hs, Ws) and (H, W), float32, optional
        Flow orientations in radians.
    orientation_weight, orientation_clamp : float
        Weight and clamp of the ``|tan|`` orientation term.
    source_segment, target_segment : ndarray of int, optional
        Segment labels (default: all 0).
    patch_size : int

    Returns
    -------
    PatchCost
    """
    frames, source_height, source_width = features.codes.shape[:3]
    colours = features.colour_channels
    guides = features.guide_order.shape[0]
    target_guides = np.asarray(target_guides, np.float32)
    height, width = target_guides.shape[:2]
    if target_guides.shape[2] != guides:
        raise ValueError(f"target_guides must have {guides} channels, got {target_guides.shape[2]}")
    colour_weights = np.asarray(colour_weights, np.float32).reshape(colours)
    guide_weights = np.asarray(guide_weights, np.float32).reshape(guides)
    if (colour_weights < 0).any() or (guide_weights < 0).any():
        raise ValueError("weights must be non-negative")
    guide_weight_map = features.guide_weight_map
    maps = 0 if weight_maps is None else weight_maps.shape[0]
    if guide_weight_map.max(initial=-1) >= maps:
        raise ValueError(f"guide_weight_map refers to map {guide_weight_map.max()} but {maps} weight maps were given")
    group_ends = np.array([colours + np.count_nonzero(guide_weight_map <= m) for m in range(maps)], np.int64)
    plain_end = colours + int(np.count_nonzero(guide_weight_map < 0))
    weights = np.concatenate([colour_weights, guide_weights[features.guide_order]])
    if (weights[features.opposite_feature] != weights).any():
        raise ValueError("guides swapped by opposite_guide must have equal weights")
    offset, scale = features.offset, features.scale
    target_codes = np.empty((height, width, colours + guides), _CODE)
    _quantize(target_colour, offset, scale, target_codes, np.arange(colours))
    _quantize(target_guides, offset, scale, target_codes, features.guide_columns)
    needs_angles = features.use_opposite or orientation_weight > 0
    if needs_angles and (source_angle is None or target_angle is None):
        raise ValueError("the orientation term and opposite-flow swapping need source_angle and target_angle")
    if source_angle is None:
        source_angle = np.zeros((1, 1, 1), np.float32)
        target_angle = np.zeros((1, 1), np.float32)
    if source_segment is None:
        source_segment = np.zeros((frames, source_height, source_width), np.int32)
    if target_segment is None:
        target_segment = np.zeros((height, width), np.int32)
    if weight_maps is None:
        weight_maps = np.zeros((0, height, width), np.float32)
    feature_weights = (weights / scale.astype(np.float64) ** 2).astype(np.float32)
    group = np.concatenate([np.full(plain_end, -1), np.repeat(np.arange(maps), np.diff(group_ends, prepend=plain_end))])
    if maps:
        target_weights = np.empty((height, width, colours + guides), np.float32)
        for feature in range(colours + guides):
            if group[feature] < 0:
                target_weights[:, :, feature] = feature_weights[feature]
            else:
                np.multiply(weight_maps[group[feature]], feature_weights[feature], out=target_weights[:, :, feature])
    else:
        target_weights = feature_weights.reshape(1, 1, -1).copy()
    swap = features.opposite_feature
    # contiguous: indexing the last axis lays the features out first, and every kernel_cost() would copy them
    swapped_codes = np.ascontiguousarray(target_codes[..., swap]) if features.use_opposite else target_codes
    swapped_weights = target_weights
    if features.use_opposite and (group[swap] != group).any():
        swapped_weights = np.ascontiguousarray(target_weights[..., swap])
    return PatchCost(
        source_features=features.codes,
        target_features=target_codes,
        feature_offset=offset,
        feature_scale=scale,
        feature_weights=feature_weights,
        colour_channels=colours,
        plain_end=plain_end,
        group_ends=group_ends,
        weight_maps=np.ascontiguousarray(weight_maps, np.float32),
        opposite_feature=features.opposite_feature,
        use_opposite=features.use_opposite,
        source_angle=np.ascontiguousarray(source_angle, np.float32),
        target_angle=np.ascontiguousarray(target_angle, np.float32),
        orientation_weight=float(orientation_weight),
        orientation_clamp=float(orientation_clamp),
        source_segment=np.ascontiguousarray(source_segment, np.int32),
        target_segment=np.ascontiguousarray(target_segment, np.int32),
        patch_size=int(patch_size),
        target_weights=target_weights,
        swapped_features=swapped_codes,
        swapped_weights=swapped_weights,
    )


def _channel_min(values):
    return values.reshape(-1, values.shape[-1]).min(axis=0, initial=np.inf).astype(np.float64)


def _channel_max(values):
    return values.reshape(-1, values.shape[-1]).max(axis=0, initial=-np.inf).astype(np.float64)


@kernel
def _quantize_rows(values, offset, scale, out, columns, part, parts):
    """Part ``part`` of ``parts`` contiguous blocks of rows (not every ``parts``-th row: neighbouring rows
    share cache lines)."""
    block = (values.shape[0] + parts - 1) // parts
    for i in range(part * block, min(values.shape[0], (part + 1) * block)):
        for c in range(values.shape[1]):
            code = min(max((values[i, c] - offset[columns[c]]) * scale[columns[c]], 0.0), _CODE_MAX)
            out[i, columns[c]] = int(code + 0.5)


def _quantize(values, offset, scale, codes, columns):
    """Store channel c of ``values`` as ``round((value − offset) · scale)`` of feature
    ``columns[c]``, clipped to the code range, into ``codes`` (shape (..., F), C-contiguous)."""
    values = np.ascontiguousarray(values, np.float32)
    run_parts(_quantize_rows, values.reshape(-1, values.shape[-1]), offset, scale, codes.reshape(-1, codes.shape[-1]),
                   np.asarray(columns, np.int64))

def patch_errors(cost, nnf):
    """Patch cost (without the uniformity penalty) of every match of ``nnf``.

    Returns
    -------
    ndarray, shape (H, W), float32; ``inf`` where the NNF has no match.
    """
    out = np.empty(nnf.shape, np.float32)
    run_parts(_evaluate, cost.kernel_cost(), nnf.frame, nnf.coords, out)
    return out
