"""Slow, obvious reference versions of engine kernels, for tests on tiny inputs."""


# --- guides (issue 4): Laplace fill, extent accumulation -----------


def naive_harmonic_fill(values, fixed, domain):
    """Exact solution of the 5-point Laplace equation on ``domain`` with Dirichlet data
    on ``fixed`` and zero normal derivative elsewhere, by a scipy sparse direct solve."""
    import numpy as np
    import scipy.sparse
    import scipy.sparse.linalg

    height, width = domain.shape
    unknown = domain & ~fixed
    index = -np.ones(domain.shape, dtype=np.int64)
    index[unknown] = np.arange(unknown.sum())
    rows, cols, data = [], [], []
    rhs = np.zeros((unknown.sum(), 2))
    for y, x in zip(*np.nonzero(unknown)):
        i = index[y, x]
        count = 0
        for ny, nx in ((y - 1, x), (y + 1, x), (y, x - 1), (y, x + 1)):
            if 0 <= ny < height and 0 <= nx < width and domain[ny, nx]:
                count += 1
                if fixed[ny, nx]:
                    rhs[i] += values[ny, nx]
                else:
                    rows.append(i)
                    cols.append(index[ny, nx])
                    data.append(-1.0)
        rows.append(i)
        cols.append(i)
        data.append(float(count))
    matrix = scipy.sparse.csr_matrix((data, (rows, cols)), shape=(len(rhs), len(rhs)))
    out = np.zeros(values.shape)
    out[fixed & domain] = values[fixed & domain]
    if len(rhs):
        solution = np.stack([scipy.sparse.linalg.spsolve(matrix, rhs[:, c]) for c in range(2)], axis=1)
        out[unknown] = solution
    return out


def naive_extent(flows, masks):
    """ext+ and ext− by the definitions: acc+_j = m_j (acc+_{j-1} + f_j), acc+_0 = 0;
    acc−_j = m_j (acc−_{j+1} + f_{j+1}), acc−_{T-1} = 0; returns (T, H, W) lengths each."""
    import numpy as np

    count = len(flows)
    forward = []
    acc = np.zeros(flows[0].shape)
    for j in range(count):
        acc = np.where(masks[j][..., None], acc + (flows[j] if j > 0 else 0.0), 0.0)
        forward.append(np.hypot(acc[..., 0], acc[..., 1]))
    backward = [None] * count
    acc = np.zeros(flows[0].shape)
    for j in range(count - 1, -1, -1):
        acc = np.where(masks[j][..., None], acc + (flows[j + 1] if j < count - 1 else 0.0), 0.0)
        backward[j] = np.hypot(acc[..., 0], acc[..., 1])
    return np.array(forward), np.array(backward)


def naive_advect_pigment(u, v, pigment, substeps):
    """Upwind advection of a cell-centred field by face velocities u (H, W+1), v (H+1, W):
    each substep moves dt·u·(upwind cell value) across every interior face."""
    import numpy as np

    pigment = np.array(pigment, dtype=np.float64)
    height, width = pigment.shape
    dt = 1.0 / substeps
    for _ in range(substeps):
        new = pigment.copy()
        for y in range(height):
            for x in range(1, width):
                donor = pigment[y, x - 1] if u[y, x] > 0 else pigment[y, x]
                moved = dt * u[y, x] * donor
                new[y, x - 1] -= moved
                new[y, x] += moved
        for y in range(1, height):
            for x in range(width):
                donor = pigment[y - 1, x] if v[y, x] > 0 else pigment[y, x]
                moved = dt * v[y, x] * donor
                new[y - 1, x] -= moved
                new[y, x] += moved
        pigment = new
    return pigment


def naive_arrival_times(inside, cost):
    """Shortest 8-neighbour path time from the boundary (Bellman–Ford relaxation)."""
    import numpy as np

    height, width = inside.shape
    times = np.full((height, width), np.inf)
    for y in range(height):
        for x in range(width):
            if not inside[y, x]:
                continue
            neighbours = [(y + dy, x + dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
            if any(not (0 <= ny < height and 0 <= nx < width) or not inside[ny, nx] for ny, nx in neighbours):
                times[y, x] = 0.5 * cost[y, x]
    changed = True
    while changed:
        changed = False
        for y in range(height):
            for x in range(width):
                if not inside[y, x]:
                    continue
                for dy in (-1, 0, 1):
                    for dx in (-1, 0, 1):
                        ny, nx = y + dy, x + dx
                        if (dy, dx) == (0, 0) or not (0 <= ny < height and 0 <= nx < width) or not inside[ny, nx]:
                            continue
                        step = np.sqrt(2.0) if dy and dx else 1.0
                        candidate = times[ny, nx] + 0.5 * (cost[y, x] + cost[ny, nx]) * step
                        if candidate < times[y, x] - 1e-12:
                            times[y, x] = candidate
                            changed = True
    return times


# --- patch synthesis engine (issue 3) ----------------------------------------


def naive_bilinear(image, x, y):
    """Bilinear sample of (H, W, C) ``image`` at (x, y), coordinates clamped to the image."""
    import math

    import numpy as np

    height, width = image.shape[:2]
    x = min(max(x, 0.0), width - 1.0)
    y = min(max(y, 0.0), height - 1.0)
    x0, y0 = int(math.floor(x)), int(math.floor(y))
    x1, y1 = min(x0 + 1, width - 1), min(y0 + 1, height - 1)
    fx, fy = x - x0, y - y0
    top = (1 - fx) * image[y0, x0].astype(np.float64) + fx * image[y0, x1]
    bottom = (1 - fx) * image[y1, x0].astype(np.float64) + fx * image[y1, x1]
    return (1 - fy) * top + fy * bottom


def naive_window_offsets(patch_size):
    radius = patch_size // 2
    return [(dx, dy) for dy in range(-radius, radius + 1) for dx in range(-radius, radius + 1)]


def naive_rotate(theta, dx, dy):
    """R(θ)(dx, dy) with R = [[cos, −sin], [sin, cos]]."""
    import math

    return math.cos(theta) * dx - math.sin(theta) * dy, math.sin(theta) * dx + math.cos(theta) * dy


def naive_patch_cost(source, target, weights, frame, x, y, theta, tx, ty, patch_size):
    """Σ over the window's in-target pixels of Σ_c w_c (S(p + R(θ)d) − T(q + d))², float64."""
    import numpy as np

    total = 0.0
    for dx, dy in naive_window_offsets(patch_size):
        qx, qy = tx + dx, ty + dy
        if not (0 <= qx < target.shape[1] and 0 <= qy < target.shape[0]):
            continue
        ox, oy = naive_rotate(theta, dx, dy)
        value = naive_bilinear(source[frame], x + ox, y + oy)
        total += float(np.sum(np.asarray(weights) * (value - target[qy, qx]) ** 2))
    return total


def naive_vote(source, frames, coords, patch_size):
    """Average of every covering patch's collocated (rotated, bilinear) source sample."""
    import numpy as np

    height, width = frames.shape
    out = np.zeros((height, width, source.shape[3]))
    for ty in range(height):
        for tx in range(width):
            samples = []
            for dx, dy in naive_window_offsets(patch_size):
                nx, ny = tx - dx, ty - dy
                if 0 <= nx < width and 0 <= ny < height and frames[ny, nx] >= 0:
                    x, y, theta = coords[ny, nx]
                    ox, oy = naive_rotate(theta, dx, dy)
                    samples.append(naive_bilinear(source[frames[ny, nx]], x + ox, y + oy))
            if samples:
                out[ty, tx] = np.mean(samples, axis=0)
    return out


def naive_occurrence(frames, coords, source_shape, patch_size, frame_radius):
    """Ω*: +1 for each voxel of each match's rotated n×n×(2r+1) footprint (nearest pixel)."""
    import math

    import numpy as np

    out = np.zeros(source_shape, np.int64)
    for ty, tx in zip(*np.nonzero(frames >= 0)):
        x, y, theta = coords[ty, tx]
        for dx, dy in naive_window_offsets(patch_size):
            ox, oy = naive_rotate(theta, dx, dy)
            px, py = int(math.floor(x + ox + 0.5)), int(math.floor(y + oy + 0.5))
            if 0 <= px < source_shape[2] and 0 <= py < source_shape[1]:
                for frame in range(frames[ty, tx] - frame_radius, frames[ty, tx] + frame_radius + 1):
                    if 0 <= frame < source_shape[0]:
                        out[frame, py, px] += 1
    return out


def naive_exact_nnf(source, target, weights, patch_size):
    """Brute-force best unrotated match (frame, x, y) and its cost for every target pixel."""
    import numpy as np

    frames, source_height, source_width = source.shape[:3]
    height, width = target.shape[:2]
    best = np.zeros((height, width), np.float64)
    for ty in range(height):
        for tx in range(width):
            costs = [
                naive_patch_cost(source, target, weights, f, sx, sy, 0.0, tx, ty, patch_size)
                for f in range(frames) for sy in range(source_height) for sx in range(source_width)
            ]
            best[ty, tx] = min(costs)
    return best


def naive_downsample(image):
    """Halve (H, W, C): taps (1, 3, 3, 1)/8 at 2k−1 .. 2k+2, clamped, separable, float64."""
    import numpy as np

    taps = np.array([1, 3, 3, 1]) / 8.0
    height, width = image.shape[:2]
    out = np.zeros(((height + 1) // 2, (width + 1) // 2) + image.shape[2:])
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            for i, wy in enumerate(taps):
                for j, wx in enumerate(taps):
                    fy = min(max(2 * y - 1 + i, 0), height - 1)
                    fx = min(max(2 * x - 1 + j, 0), width - 1)
                    out[y, x] += wy * wx * image[fy, fx]
    return out


# --- stylize (issue 6): SHIFTNNF, temporal modulation ---------------


def naive_shift_frames(frames, coords, motion, target_angle, ext_plus, ext_minus, source_angle):
    """Shifted source frame per target pixel by brute force over every Δi (smallest |Δi| on ties)."""
    import math

    import numpy as np

    count, height, width = ext_plus.shape
    out = np.array(frames, copy=True)
    for ty, tx in np.ndindex(frames.shape):
        i = int(frames[ty, tx])
        if i < 0:
            continue
        sx = min(max(int(math.floor(coords[ty, tx, 0] + 0.5)), 0), width - 1)
        sy = min(max(int(math.floor(coords[ty, tx, 1] + 0.5)), 0), height - 1)
        turn = float(source_angle[i, sy, sx]) - float(coords[ty, tx, 2]) - float(target_angle[ty, tx])
        if math.cos(turn) < 0:
            options = [(abs(motion[ty, tx] - (ext_minus[k, sy, sx] - ext_minus[i, sy, sx])), i - k, k) for k in range(i, -1, -1)]
        else:
            options = [(abs(motion[ty, tx] - (ext_plus[k, sy, sx] - ext_plus[i, sy, sx])), k - i, k) for k in range(i, count)]
        out[ty, tx] = min(options)[2]
    return out


def naive_inside(rings, x, y, even_odd):
    """Whether point (x, y) is inside closed polygon rings, by the winding number of each edge crossing a ray to +x."""
    winding = 0
    for ring in rings:
        for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1]):
            if (y0 <= y) != (y1 <= y):
                crossing = x0 + (y - y0) / (y1 - y0) * (x1 - x0)
                if crossing > x:
                    winding += 1 if y1 > y0 else -1
    return winding % 2 != 0 if even_odd else winding != 0


def naive_scatter_vote(source, frames, coords, patch_size, weight, shape):
    """Completeness vote: each matched source patch adds ``weight`` × its pixels (edges repeated) around its match."""
    import numpy as np

    total = np.zeros(shape + (source.shape[2],))
    weights = np.zeros(shape)
    for sy in range(source.shape[0]):
        for sx in range(source.shape[1]):
            if frames[sy, sx] < 0:
                continue
            tx, ty = int(np.floor(coords[sy, sx, 0] + 0.5)), int(np.floor(coords[sy, sx, 1] + 0.5))
            for dx, dy in naive_window_offsets(patch_size):
                if 0 <= tx + dx < shape[1] and 0 <= ty + dy < shape[0]:
                    py = min(max(sy + dy, 0), source.shape[0] - 1)
                    px = min(max(sx + dx, 0), source.shape[1] - 1)
                    total[ty + dy, tx + dx] += weight * source[py, px]
                    weights[ty + dy, tx + dx] += weight
    return total, weights


def naive_shift(before, after, weight, radius=4):
    """The (dx, dy) that best moves ``before`` onto ``after`` where ``weight`` (H, W) > 0 in ``after``: the integer
    shift of least weighted SSD over every shift within ``radius``, refined by a parabola through its neighbours."""
    import numpy as np

    height, width = weight.shape
    costs = np.full((2 * radius + 1, 2 * radius + 1), np.inf)
    ys, xs = np.nonzero(weight > 0)
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            sy, sx = ys - dy, xs - dx
            keep = (sy >= 0) & (sy < height) & (sx >= 0) & (sx < width)
            diff = after[ys[keep], xs[keep]] - before[sy[keep], sx[keep]]
            costs[dy + radius, dx + radius] = (weight[ys[keep], xs[keep], None] * diff ** 2).sum() / keep.sum()
    iy, ix = np.unravel_index(np.argmin(costs), costs.shape)
    shift = []
    for axis, (i, line) in enumerate(((ix, costs[iy]), (iy, costs[:, ix]))):
        offset = 0.0
        if 0 < i < len(line) - 1:
            curvature = line[i - 1] - 2 * line[i] + line[i + 1]
            if curvature > 0:
                offset = 0.5 * (line[i - 1] - line[i + 1]) / curvature
        shift.append(i - radius + offset)
    return np.array(shift)


def naive_patch_distance(image, sources, centres, patch_size):
    """For each (x, y) in ``centres``, the least mean squared difference between ``image``'s patch there and any
    whole patch of any of ``sources`` (each (H, W, C)); their mean."""
    import numpy as np

    half = patch_size // 2
    best = []
    windows = [np.lib.stride_tricks.sliding_window_view(source, (patch_size, patch_size), axis=(0, 1))
               .reshape(-1, source.shape[2] * patch_size * patch_size) for source in sources]
    library = np.concatenate(windows)
    for x, y in centres:
        patch = image[y - half:y + half + 1, x - half:x + half + 1].transpose(2, 0, 1).reshape(-1)
        best.append(((library - patch) ** 2).mean(axis=1).min())
    return float(np.mean(best))


def naive_match_histograms(colour, nnf_frame, target_segment, tables, strength, blend=None):
    """Histogram matching pixel by pixel: per segment and channel, the k-th smallest of its n votes moves to the
    value at level (k + ½)/n of the match-weighted mixture of its frames' quantiles; with ``blend``, a pixel
    mixes its own value with the other segments' remappings read as functions of the value (np.interp)."""
    import numpy as np

    frames, labels, channels, quantiles = tables.shape
    height, width = nnf_frame.shape
    members = {label: [(y, x) for y in range(height) for x in range(width)
                       if nnf_frame[y, x] >= 0 and target_segment[y, x] == label] for label in range(labels)}
    remapped = colour.astype(np.float64)
    curves = {}  # label -> per channel (sorted votes, their remapped values)
    for label, pixels in members.items():
        mixture = [(frame, sum(nnf_frame[y, x] == frame for y, x in pixels)) for frame in range(frames)
                   if not np.isnan(tables[frame, label, 0, 0])]
        mixture = [(frame, uses) for frame, uses in mixture if uses > 0]
        if not pixels or not mixture:
            continue
        total = sum(uses for _, uses in mixture)
        curves[label] = []
        for channel in range(channels):
            points = sorted((float(tables[frame, label, channel, q]), uses / (total * quantiles))
                            for frame, uses in mixture for q in range(quantiles))
            weights = np.array([weight for _, weight in points])
            levels = np.cumsum(weights) - 0.5 * weights
            votes = sorted((float(colour[y, x, channel]), (y, x)) for y, x in pixels)
            moved = [np.interp((rank + 0.5) / len(votes), levels, [value for value, _ in points])
                     for rank in range(len(votes))]
            for (_, (y, x)), value in zip(votes, moved):
                remapped[y, x, channel] = value
            curves[label].append(([value for value, _ in votes], moved))
    out = remapped.copy()
    if blend is not None:
        for label, pixels in members.items():
            for y, x in pixels:
                own = blend[label, y, x] if label in curves else 0.0
                others = {other: blend[other, y, x] for other in curves if other != label and blend[other, y, x] > 0}
                if not others:
                    continue
                total = own + sum(others.values())
                for channel in range(channels):
                    mixed = own * remapped[y, x, channel] + sum(
                        weight * np.interp(colour[y, x, channel], *curves[other][channel])
                        for other, weight in others.items())
                    out[y, x, channel] = mixed / total
    return colour + strength * (out - colour)
