"""Image and array files: atomic writes, PNG reading and writing.

Every product of a render is written to a temporary file in the destination folder and
renamed into place, so a killed render never leaves a partial file under a final name.
"""

from __future__ import annotations

import contextlib
import glob
import os
import re
import tempfile
import warnings
from pathlib import Path

import numpy as np

from fluidymation.errors import InputError


_PRINTF = re.compile(r"%0?(\d*)d")
MAX_IMAGE_PIXELS = 2**25  # 32 Mpx (8192 x 4096): an image read as float RGBA takes 512 MiB
_UMASK = os.umask(0o022)
os.umask(_UMASK)  # read once: written files get the mode a plain open() would give them, not mkstemp's 0600


def is_sequence_pattern(text: str) -> bool:
    """Whether ``text`` names several files: a printf number (``%04d``) or glob characters."""
    return bool(_PRINTF.search(text)) or any(char in text for char in "*?[")


def sequence_paths(spec: str) -> list[Path]:
    """Files matching a printf pattern (``frames/%04d.png``) or a glob, in natural number order."""
    if _PRINTF.search(spec):
        pieces = _PRINTF.split(spec)  # text, width, text, width, ..., text
        regex = "".join(re.escape(piece) if k % 2 == 0 else r"\d{%d,}" % int(piece or 1)
                        for k, piece in enumerate(pieces))
        files = [Path(p) for p in glob.glob(_PRINTF.sub("*", spec)) if re.fullmatch(regex, p)]
    else:
        files = [Path(p) for p in glob.glob(spec)]
    return sorted(files, key=_natural_key)


def _natural_key(path: Path):
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", str(path))]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path next to ``path``; on success rename it over ``path`` (with the mode the umask gives)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part" + path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_bytes(path: str | os.PathLike, data: bytes) -> None:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | os.PathLike, text: str) -> None:
    write_bytes(path, text.encode("utf-8"))


def to_uint8(image: np.ndarray) -> np.ndarray:
    """Float image in [0, 1] (or already uint8) to uint8, rounding to nearest."""
    if image.dtype == np.uint8:
        return image
    return np.clip(np.rint(np.asarray(image, dtype=np.float32) * 255.0), 0, 255).astype(np.uint8)


def write_png(path: str | os.PathLike, image: np.ndarray) -> None:
    """Write an (H, W), (H, W, 3) or (H, W, 4) image, float in [0, 1] or uint8, as PNG."""
    import imageio.v3 as iio  # loaded on use: checking a scene reads and writes no images

    with atomic_path(path) as tmp:
        iio.imwrite(tmp, to_uint8(image), extension=".png")


def write_npy(path: str | os.PathLike, array: np.ndarray) -> None:
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            np.save(handle, array)


def read_image(path: str | os.PathLike, *, channels: int | None = None) -> np.ndarray:
    """Read an image file as float32 in [0, 1], shape (H, W, C).

    ``channels`` (1, 3 or 4) converts: grey is repeated, alpha is dropped or set to 1.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: {'a folder, not an image file' if path.is_dir() else 'no such file'}")
    _check_declared_size(path)
    import imageio.v3 as iio  # loaded on use, as in write_png

    try:
        data = iio.imread(path)
    except Exception as exc:
        raise InputError(f"{path}: not a readable image ({exc})") from None
    if data.ndim == 2:
        data = data[:, :, None]
    if data.ndim != 3:
        raise InputError(f"{path}: expected a single image, got an array of shape {data.shape}")
    scale = float(np.iinfo(data.dtype).max) if np.issubdtype(data.dtype, np.integer) else 1.0
    image = data.astype(np.float32) / np.float32(scale)
    if not np.isfinite(image).all():  # a floating-point image (TIFF, EXR) with NaN or infinite values
        raise InputError(f"{path}: the image holds values that are not finite numbers (NaN or infinity)")
    image = np.clip(image, 0.0, 1.0)  # floating-point images may stray outside [0, 1]
    if channels is None:
        return image
    return _convert_channels(image, channels)


def _check_declared_size(path: Path) -> None:
    """An InputError when the image's header declares more than :data:`MAX_IMAGE_PIXELS` (checked before decoding;
    files Pillow cannot open are left to imageio)."""
    from PIL import Image

    limit = f"over the limit of {MAX_IMAGE_PIXELS / 2**20:g} megapixels"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                width, height = image.size
    except Image.DecompressionBombError:  # Pillow's own limit is above ours
        raise InputError(f"{path}: the image's header declares a size {limit}") from None
    except (OSError, ValueError, SyntaxError):
        return
    if width * height > MAX_IMAGE_PIXELS:
        raise InputError(f"{path}: the image is {width}x{height} px, {limit}")


def _convert_channels(image: np.ndarray, channels: int) -> np.ndarray:
    have = image.shape[2]
    if have == channels:
        return image
    colour = image[:, :, :1].repeat(3, axis=2) if have in (1, 2) else image[:, :, :3]
    if channels == 1:
        return colour.mean(axis=2, keepdims=True) if have >= 3 else image[:, :, :1]
    if channels == 3:
        return colour
    alpha = image[:, :, 3:4] if have == 4 else image[:, :, 1:2] if have == 2 else np.ones_like(image[:, :, :1])
    return np.concatenate([colour, alpha], axis=2)
