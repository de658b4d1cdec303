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
    out = colour.copy()
    frames, labels, channels, quantiles = tables.shape
    matched = (nnf_frame >= 0) & (target_segment >= 0) & (target_segment < labels)
    values = np.ascontiguousarray(out[matched].T)  # (C, N): one contiguous row per channel
    own = target_segment[matched]
    frames_used = nnf_frame[matched]
    # each segment's own pixels take their ranks' values (ties keep distinct ranks); pixels
    # without a remapping keep theirs
    remapped = values.copy()
    remappings = {}
    for label in range(labels):
        members = np.flatnonzero(own == label)
        remapping = _segment_remapping(values[:, members], frames_used[members], tables[:, label])
        if remapping is None:
            continue
        own_values = np.empty((values.shape[0], members.size), np.float32)
        for channel, (order, wanted) in enumerate(remapping):
            own_values[channel, order] = wanted
        remapped[:, members] = own_values
        remappings[label] = (members, remapping)
    if blend is not None and remappings:
        _blend_remappings(values, own, blend[:, matched], remappings, remapped)
    out[matched] = (values + np.float32(strength) * (remapped - values)).T
    return out


def _blend_remappings(values, own, weights, remappings, remapped) -> None:
    """Where a pixel takes some of another segment's remapping, mix them by ``weights`` (labels, N), in place.

    ``values`` and ``remapped`` are (C, N). The pixel's own remapping keeps its exact (rank)
    value; another segment's is read as a function of the value. Only segments with a
    remapping count."""
    available = np.zeros(len(weights), bool)
    available[list(remappings)] = True
    weights = np.where(available[:, None], weights, 0.0).astype(np.float32)
    own_weight = np.take_along_axis(weights, own[None].astype(np.int64), axis=0)[0]
    zone = np.flatnonzero(weights.sum(axis=0) > own_weight)
    if zone.size == 0:
        return
    own_weight = own_weight[zone]
    mixed = own_weight * remapped[:, zone]
    total = own_weight.copy()
    for label, (members, remapping) in remappings.items():
        weight = np.where(own[zone] != label, weights[label, zone], 0.0)
        take = np.flatnonzero(weight > 0)
        for channel, (order, wanted) in enumerate(remapping):
            ranked = values[channel, members[order]]
            mixed[channel, take] += weight[take] * np.interp(values[channel, zone[take]], ranked, wanted)
        total += weight
    has = total > 0
    remapped[:, zone[has]] = mixed[:, has] / total[has]


def _segment_remapping(values: np.ndarray, frames_used: np.ndarray, table: np.ndarray):
    """Per channel, (the order that sorts the segment's votes, the values they move to in that order), or
    None without a reference.

    ``values`` is (C, n), the segment's votes; ``table`` its label's :func:`quantile_tables`
    part, (T, C, QUANTILES); the reference is the mixture of the frames ``frames_used``
    names, each weighted by its count."""
    count = values.shape[1]
    if count == 0:
        return None
    frames, channels, quantiles = table.shape
    uses = np.bincount(frames_used, minlength=frames)[:frames].astype(np.float64)
    uses[np.isnan(table[:, 0, 0])] = 0.0
    used = np.flatnonzero(uses)
    if used.size == 0:
        return None
    weights = np.repeat(uses[used] / (uses[used].sum() * quantiles), quantiles)
    ranks = (np.arange(count) + 0.5) / count  # the quantile each value moves to, by its rank
    remapping = []
    for channel in range(channels):
        pool = table[used, channel].ravel()
        order = np.argsort(pool, kind="stable")
        cumulative = np.cumsum(weights[order]) - 0.5 * weights[order]
        remapping.append((_rank_order(values[channel]),
                          np.interp(ranks, cumulative, pool[order]).astype(np.float32)))
    return remapping


def _rank_order(values: np.ndarray) -> np.ndarray:
    """The order that sorts ``values``, by a stable radix sort of them rescaled to 16 bits.

    Eight times faster than a stable float sort at 60 000 values; values closer than
    1/65 535 of their range keep their index order among themselves, which moves their
    remapped values by less than that range's 1/65 535 as well."""
    low, high = float(values.min()), float(values.max())
    scale = 65535.0 / (high - low) if high > low else 0.0
    return np.argsort(((values - low) * scale + 0.5).astype(np.uint16), kind="stable")
