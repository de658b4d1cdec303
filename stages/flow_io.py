"""Flow field files: ``.npy`` arrays and the Middlebury ``.flo`` format.

A flow is float32 ``(H, W, 2)`` holding ``(dx, dy)`` in px/frame with y pointing down.
A ``.flo`` file is little-endian: the float 202021.25 (the bytes ``PIEH``), the width
and the height as int32, then ``H·W`` interleaved float32 pairs ``(u, v)`` row by row.
Values above 1e9 mark unknown flow in that format; they are read as zero motion.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from fluidymation.errors import InputError
from fluidymation.stages.files import atomic_path

FLO_TAG = b"PIEH"
_NPY_HEADERS = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}
_FLO_UNKNOWN = 1e9


def read_flow(path: str | os.PathLike, *, shape: tuple[int, int] | None = None) -> np.ndarray:
    """Read a flow field from ``.npy`` or ``.flo``.

    Parameters
    ----------
    path : path of a ``.npy`` file holding an (H, W, 2) array, or a ``.flo`` file
    shape : (H, W), optional
        The size the flow must have; a different one is an :class:`InputError`.

    Returns
    -------
    (H, W, 2) float32
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such flow file")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        flow = _read_npy(path, shape)
    elif suffix == ".flo":
        flow = _read_flo(path)
    else:
        raise InputError(f"{path}: unknown flow file type {suffix!r}; use .npy (H, W, 2) or Middlebury .flo")
    if flow.ndim != 3 or flow.shape[2] != 2:
        raise InputError(f"{path}: a flow must have shape (H, W, 2) as (dx, dy), got {flow.shape}")
    if not np.issubdtype(flow.dtype, np.floating):
        raise InputError(f"{path}: a flow must hold floats in px/frame, got dtype {flow.dtype}")
    if shape is not None and flow.shape[:2] != tuple(shape):
        raise InputError(
            f"{path}: flow has size {flow.shape[1]}x{flow.shape[0]} (W x H), "
            f"the masks have {shape[1]}x{shape[0]}"
        )
    flow = np.ascontiguousarray(flow, dtype=np.float32)
    if not np.isfinite(flow).all():
        raise InputError(f"{path}: flow holds NaN or infinite values")
    return flow


def _read_npy(path: Path, shape: tuple[int, int] | None) -> np.ndarray:
    """The array of a ``.npy`` file, its header checked first: never a pickle (object arrays are refused before
    any data is read), a float dtype, an (H, W, 2) shape (of ``shape`` if given) that the file's size holds."""
    try:
        with open(path, "rb") as handle:
            version = np.lib.format.read_magic(handle)
            if version not in _NPY_HEADERS:
                raise ValueError(f"format version {version[0]}.{version[1]}; flows are read from 1.0 and 2.0")
            dims, fortran, dtype = _NPY_HEADERS[version](handle)
            offset = handle.tell()
    except (ValueError, OSError, EOFError, SyntaxError) as exc:
        raise InputError(f"{path}: not a readable .npy array ({exc})") from None
    if dtype.hasobject or not np.issubdtype(dtype, np.floating):
        raise InputError(f"{path}: a flow must hold floats in px/frame, got dtype {dtype}")
    if len(dims) != 3 or dims[2] != 2 or min(dims) < 1:
        raise InputError(f"{path}: a flow must have shape (H, W, 2) as (dx, dy), got {dims}")
    if shape is not None and dims[:2] != tuple(shape):
        raise InputError(f"{path}: flow has size {dims[1]}x{dims[0]} (W x H), the masks have {shape[1]}x{shape[0]}")
    expected = offset + dims[0] * dims[1] * 2 * dtype.itemsize
    if path.stat().st_size != expected:
        raise InputError(f"{path}: the .npy header says {dims[1]}x{dims[0]}x2 {dtype} but the file has "
                         f"{path.stat().st_size} bytes (expected {expected})")
    flow = np.fromfile(path, dtype=dtype, offset=offset)
    return flow.reshape(dims[::-1]).transpose() if fortran else flow.reshape(dims)


def _read_flo(path: Path) -> np.ndarray:
    data = path.read_bytes()
    if len(data) < 12 or data[:4] != FLO_TAG:
        raise InputError(f"{path}: not a Middlebury .flo file (it must start with the bytes 'PIEH')")
    width, height = np.frombuffer(data, dtype="<i4", count=2, offset=4)
    expected = 12 + int(width) * int(height) * 8
    if width <= 0 or height <= 0 or len(data) != expected:
        raise InputError(
            f"{path}: .flo header says {width}x{height} but the file has {len(data)} bytes "
            f"(expected {expected})"
        )
    flow = np.frombuffer(data, dtype="<f4", offset=12).reshape(int(height), int(width), 2).astype(np.float32)
    flow[np.abs(flow) > _FLO_UNKNOWN] = 0.0
    return flow


def write_flo(path: str | os.PathLike, flow: np.ndarray) -> None:
    """Write an ``(H, W, 2)`` flow as a Middlebury ``.flo`` file (atomically)."""
    flow = np.asarray(flow)
    if flow.ndim != 3 or flow.shape[2] != 2:
        raise ValueError(f"write_flo expects an (H, W, 2) flow, got shape {flow.shape}")
    header = FLO_TAG + np.array([flow.shape[1], flow.shape[0]], dtype="<i4").tobytes()
    with atomic_path(path) as tmp:
        tmp.write_bytes(header + np.ascontiguousarray(flow, dtype="<f4").tobytes())
