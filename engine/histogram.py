"""Histogram matching of a voted target to the exemplar frames it draws from.

Voting averages overlapping patches; where neighbouring matches disagree it blurs, and
the next search then prefers the exemplar's smoother patches, which blur the next vote
less: the texture can wash out towards a fixed point of the energy (measured: local
contrast 0.71–0.98 of the exemplar's depending on the seed alone, equal energies).
Matching the voted colours' histogram to the exemplar's breaks that loop (histogram
matching in the voting step, Kopf et al. 2007, thesis section 2.5; here a rank remapping
of the vote rather than Kopf's reweighting of the contributions). The reference is
not the whole exemplar but the frames the field draws from, each weighted by its number
of matches, so a target painted from early (wet) frames keeps their look: per segment
and channel, the target's values are ranked and replaced by the quantiles of that
mixture of per-frame distributions. Where segments meet, the remappings are blended
(:func:`match_histograms`' ``blend``), so no seam appears along the meeting line.

Each frame's distribution is kept as :data:`QUANTILES` quantiles per segment and
channel, computed once per source (:func:`quantile_tables`).
"""

from __future__ import annotations

import numpy as np

from fluidymation.engine._jit import exact_kernel, run_parts

#: Quantiles kept per frame, segment and channel.
QUANTILES = 64


def quantile_tables(colour: np.ndarray, segment: np.ndarray, labels: int) -> np.ndarray:
    """Every frame's colour distribution per segment label, as quantiles.

    Parameters
    ----------
    colour : ndarray, shape (T, H, W, C), float32
    segment : ndarray, shape (T, H, W), int
        Labels 0..labels−1; others are ignored.
    labels : int

    Returns
    -------
    ndarray, shape (T, labels, C, QUANTILES), float32
        NaN where a frame has no pixel of a label.
    """
    frames, channels = colour.shape[0], colour.shape[3]
    levels = (np.arange(QUANTILES) + 0.5) / QUANTILES
    tables = np.full((frames, labels, channels, QUANTILES), np.nan, np.float32)
    for frame in range(frames):
        for label in range(labels):
            values = colour[frame][segment[frame] == label]
            if values.size:
                tables[frame, label] = np.quantile(values, levels, axis=0).T
    return tables


def join_tables(parts: list[np.ndarray]) -> np.ndarray:
    """Tables of consecutive frame ranges joined along time (labels missing from a part are NaN)."""
    labels = max(part.shape[1] for part in parts)
    return np.concatenate([np.pad(part, ((0, 0), (0, labels - part.shape[1]), (0, 0), (0, 0)), constant_values=np.nan)
                           for part in parts])


def match_histograms(colour: np.ndarray, nnf_frame: np.ndarray, target_segment: np.ndarray, tables: np.ndarray,
                     strength: float, blend: np.ndarray | None = None) -> np.ndarray:
    """Move a voted image's values towards the distribution of the exemplar frames its matches use.

    Each segment gets its own remapping, a monotone function of the value: its pixels'
    ranks onto the quantiles of its source frames (weighted by their matches). Applied
    each to its own segment only, two remappings differ at the segments' meeting line and
    draw a seam there; ``blend`` instead mixes them per pixel with smooth weights, the way
    contrast-limited adaptive equalization interpolates between the mappings of
    neighbouring tiles.

    Parameters
    ----------
    colour : ndarray, shape (H, W, C), float32
        The vote.
    nnf_frame : ndarray, shape (H, W), int
        Matched source frame per pixel (-1: unmatched, left as it is).
    target_segment : ndarray, shape (H, W), int
        Segment label per pixel (matches lie in the same segment).
    tables : ndarray
        From :func:`quantile_tables` for the same source.
    strength : float
        0 keeps the vote, 1 replaces each value by its remapped one.
    blend : ndarray, shape (labels, H, W), float, optional
        How much of each segment's remapping a pixel takes (normalized over the segments
        that have one). Default: all of its own segment's.

    Returns
    -------
    ndarray, shape (H, W, C), float32
        A new image.
    """
    colour = np.ascontiguousarray(colour, np.float32)
    frames, labels, channels, quantiles = tables.shape
    pixels = np.flatnonzero((nnf_frame >= 0) & (target_segment >= 0) & (target_segment < labels))
    own = target_segment.ravel()[pixels].astype(np.int64)
    by_label = np.argsort(own, kind="stable")  # each segment's pixels, in image order
    starts = np.concatenate([[0], np.cumsum(np.bincount(own, minlength=labels))]).astype(np.int64)
    frames_used = nnf_frame.ravel()[pixels]
    references = [_reference(frames_used[by_label[starts[label]:starts[label + 1]]], tables[:, label])
                  for label in range(labels)]
    has_reference = np.array([reference is not None for reference in references], bool)
    longest = max([reference[0].shape[1] for reference in references if reference is not None], default=1)
    levels = np.zeros((labels, channels, longest), np.float64)  # each reference's cumulative weights (ascending)
    values_at = np.zeros((labels, channels, longest), np.float64)  # the pooled quantiles at those levels
    lengths = np.zeros(labels, np.int64)
    for label, reference in enumerate(references):
        if reference is not None:
            lengths[label] = reference[0].shape[1]
            levels[label, :, :lengths[label]], values_at[label, :, :lengths[label]] = reference
    flat = colour.reshape(-1, channels)
    remapped = flat[pixels]  # segments without a reference keep their votes
    ranked = np.empty((channels, pixels.size), np.float32)  # per segment run: its votes ascending ...
    wanted = np.empty((channels, pixels.size), np.float32)  # ... and the values they move to
    sizes = np.diff(starts)
    tasks = np.array([(label, channel) for label in np.argsort(-sizes, kind="stable")
                      if has_reference[label] and sizes[label] > 0 for channel in range(channels)], np.int64)
    run_parts(_remap_segments, flat, pixels, by_label, starts, tasks.reshape(-1, 2), levels, values_at, lengths,
              remapped, ranked, wanted)
    if blend is not None and has_reference.any():
        weights = np.ascontiguousarray(blend, np.float32).reshape(len(blend), -1)
        run_parts(_blend_remappings, flat, pixels, own, weights, has_reference, starts, ranked, wanted, remapped)
    out = colour.copy()
    run_parts(_move_towards, out.reshape(-1, channels), pixels, remapped, np.float32(strength))
    return out


def _reference(frames_used: np.ndarray, table: np.ndarray):
    """A segment's reference distribution, per channel, as (cumulative weights, pooled quantiles), both (C, P)
    and ascending; None without one.

    ``table`` is its label's :func:`quantile_tables` part, (T, C, QUANTILES); the reference is the mixture
    of the frames its pixels' matches ``frames_used`` name, each weighted by its count."""
    frames, channels, quantiles = table.shape
    uses = np.bincount(frames_used, minlength=frames)[:frames].astype(np.float64)
    uses[np.isnan(table[:, 0, 0])] = 0.0
    used = np.flatnonzero(uses)
    if used.size == 0:
        return None
    weights = np.repeat(uses[used] / (uses[used].sum() * quantiles), quantiles)
    pool = table[used].transpose(1, 0, 2).reshape(channels, -1).astype(np.float64)
    order = np.argsort(pool, axis=1, kind="stable")
    ordered_weights = weights[order]
    return np.cumsum(ordered_weights, axis=1) - 0.5 * ordered_weights, np.take_along_axis(pool, order, axis=1)


@exact_kernel
def _interpolate(x, xp, fp, count):
    """``np.interp(x, xp[:count], fp[:count])`` in float64 for ascending ``xp`` (of a run of equal ``xp``, the
    last counts)."""
    if x >= xp[count - 1]:
        return np.float64(fp[count - 1])
    if x < xp[0]:
        return np.float64(fp[0])
    low, high = 0, count - 1  # xp[low] <= x < xp[high]
    while high - low > 1:
        middle = (low + high) // 2
        if xp[middle] <= x:
            low = middle
        else:
            high = middle
    slope = (np.float64(fp[high]) - np.float64(fp[low])) / (np.float64(xp[high]) - np.float64(xp[low]))
    return slope * (x - np.float64(xp[low])) + np.float64(fp[low])


@exact_kernel
def _remap_segments(flat, pixels, by_label, starts, tasks, levels, values_at, lengths, remapped, ranked, wanted,
                    part, parts):
    """Per (segment, channel) task with a reference (``tasks``, largest first, dealt each to the part with the
    least work so far): rank the segment's votes and give the k-th of n the reference's value at level
    (k + ½) / n; ``ranked`` and ``wanted`` keep both in rank order.

    Ranks come from a stable counting sort of the votes rescaled to 16 bits: values closer than 1/65 535 of
    their range keep their image order among themselves, which moves their remapped values by less than that
    range's 1/65 535 as well."""
    load = np.zeros(parts, np.int64)
    counts = np.empty(65536, np.int32)
    values = np.empty(by_label.shape[0], np.float32)
    keys = np.empty(by_label.shape[0], np.int32)
    order = np.empty(by_label.shape[0], np.int32)
    for task in range(tasks.shape[0]):
        label, channel = tasks[task, 0], tasks[task, 1]
        begin, end = starts[label], starts[label + 1]
        count = end - begin
        lightest = 0
        for other in range(parts):
            if load[other] < load[lightest]:
                lightest = other
        load[lightest] += count
        if lightest != part:
            continue
        low = flat[pixels[by_label[begin]], channel]
        high = low
        for member in range(count):
            value = flat[pixels[by_label[begin + member]], channel]
            values[member] = value
            low = min(low, value)
            high = max(high, value)
        scale = np.float32(65535.0 / (np.float64(high) - np.float64(low))) if high > low else np.float32(0.0)
        counts[:] = 0
        for member in range(count):
            keys[member] = int((values[member] - low) * scale + np.float32(0.5))
            counts[keys[member]] += 1
        total = 0
        for key in range(65536):
            total, counts[key] = total + counts[key], total
        for member in range(count):
            order[counts[keys[member]]] = member
            counts[keys[member]] += 1
        # the levels (rank + ½) / count ascend with the rank: walk the reference alongside
        xp, fp, length = levels[label, channel], values_at[label, channel], lengths[label]
        low_index = 0
        for rank in range(count):
            level = (rank + 0.5) / count
            while low_index + 1 < length and xp[low_index + 1] <= level:
                low_index += 1
            if level >= xp[length - 1]:
                moved = np.float32(fp[length - 1])
            elif level < xp[0]:
                moved = np.float32(fp[0])
            else:
                slope = (fp[low_index + 1] - fp[low_index]) / (xp[low_index + 1] - xp[low_index])
                moved = np.float32(slope * (level - xp[low_index]) + fp[low_index])
            member = order[rank]
            remapped[by_label[begin + member], channel] = moved
            ranked[channel, begin + rank] = values[member]
            wanted[channel, begin + rank] = moved


@exact_kernel
def _blend_remappings(flat, pixels, own, weights, has_reference, starts, ranked, wanted, remapped, part, parts):
    """Where a pixel takes some of another segment's remapping, mix them by ``weights`` (labels, H·W), in place.

    The pixel's own remapping keeps its exact (rank) value; another segment's is read as a function of the
    value. Only segments with a reference count. Pixels in blocks of 1024, every ``parts``-th."""
    labels = min(has_reference.shape[0], weights.shape[0])
    channels = flat.shape[1]
    mixed = np.empty(channels, np.float32)
    for block in range(part, (pixels.shape[0] + 1023) // 1024, parts):
        for index in range(block * 1024, min(pixels.shape[0], block * 1024 + 1024)):
            pixel = pixels[index]
            label_here = own[index]
            own_weight = weights[label_here, pixel] if label_here < labels and has_reference[label_here] else \
                np.float32(0.0)
            others = np.float32(0.0)
            for label in range(labels):
                if has_reference[label]:
                    others += weights[label, pixel]
            if not others > own_weight:
                continue
            total = own_weight
            for channel in range(channels):
                mixed[channel] = own_weight * remapped[index, channel]
            for label in range(labels):
                weight = weights[label, pixel]
                if label == label_here or not has_reference[label] or not weight > 0:
                    continue
                begin, count = starts[label], starts[label + 1] - starts[label]
                for channel in range(channels):
                    read = _interpolate(np.float64(flat[pixel, channel]), ranked[channel, begin:begin + count],
                                        wanted[channel, begin:begin + count], count)
                    mixed[channel] = np.float32(np.float64(mixed[channel]) + np.float64(weight) * read)
                total += weight
            if total > 0:
                for channel in range(channels):
                    remapped[index, channel] = mixed[channel] / total


@exact_kernel
def _move_towards(flat, pixels, remapped, strength, part, parts):
    """``flat[pixel] += strength · (remapped − flat[pixel])`` for the matched pixels, in blocks of 1024."""
    for block in range(part, (pixels.shape[0] + 1023) // 1024, parts):
        for index in range(block * 1024, min(pixels.shape[0], block * 1024 + 1024)):
            for channel in range(flat.shape[1]):
                value = flat[pixels[index], channel]
                flat[pixels[index], channel] = value + strength * (remapped[index, channel] - value)
