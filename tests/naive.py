"""Slow, obvious reference versions of engine kernels, for tests on tiny inputs."""


# --- guides (issue 4): signed distance, boundary flow, Laplace fill, extent -----------


def naive_signed_distance(mask):
    """Brute force: distance to the nearest pixel centre of the other side, minus 0.5."""
    import numpy as np

    mask = np.asarray(mask, dtype=bool)
    ys, xs = np.nonzero(mask)
    oys, oxs = np.nonzero(~mask)
    out = np.empty(mask.shape, dtype=np.float64)
    for y in range(mask.shape[0]):
        for x in range(mask.shape[1]):
            if mask[y, x]:
                out[y, x] = np.sqrt(((oys - y) ** 2 + (oxs - x) ** 2).min()) - 0.5
            else:
                out[y, x] = 0.5 - np.sqrt(((ys - y) ** 2 + (xs - x) ** 2).min())
    return out


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
