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
