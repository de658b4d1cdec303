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
    values = out[matched]
    own = target_segment[matched]
    mixed = np.zeros(values.shape, np.float64)
    total = np.zeros(len(values), np.float64)
    for label in range(labels):
        members = own == label
        remapping = _segment_remapping(values[members], nnf_frame[matched][members], tables[:, label])
        if remapping is None:
            continue
        weight = (members if blend is None else blend[label][matched]).astype(np.float64)
        for channel, (order, wanted) in enumerate(remapping):
            moved = np.interp(values[:, channel], values[members, channel][order], wanted)
            moved[np.flatnonzero(members)[order]] = wanted  # ties within the segment keep their own ranks
            mixed[:, channel] += weight * moved
        total += weight
    remapped = total > 0
    target = mixed[remapped] / total[remapped, None]
    values[remapped] += np.float32(strength) * (target.astype(np.float32) - values[remapped])
    out[matched] = values
    return out


def _segment_remapping(values: np.ndarray, frames_used: np.ndarray, table: np.ndarray):
    """Per channel, (the order that sorts the segment's votes, the values they move to in that order), or
    None without a reference.

    ``table`` is one label's :func:`quantile_tables` part, (T, C, QUANTILES); the reference
    is the mixture of the frames ``frames_used`` names, each weighted by its count."""
    if len(values) == 0:
        return None
    frames, channels, quantiles = table.shape
    uses = np.bincount(frames_used, minlength=frames)[:frames].astype(np.float64)
    uses[np.isnan(table[:, 0, 0])] = 0.0
    used = np.flatnonzero(uses)
    if used.size == 0:
        return None
    weights = np.repeat(uses[used] / (uses[used].sum() * quantiles), quantiles)
    ranks = (np.arange(len(values)) + 0.5) / len(values)  # the quantile each value moves to, by its rank
    remapping = []
    for channel in range(channels):
        pool = table[used, channel].ravel()
        order = np.argsort(pool, kind="stable")
        cumulative = np.cumsum(weights[order]) - 0.5 * weights[order]
        remapping.append((np.argsort(values[:, channel], kind="stable"), np.interp(ranks, cumulative, pool[order])))
    return remapping
