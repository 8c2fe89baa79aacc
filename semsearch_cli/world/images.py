"""Map images as gray levels, read safely: the size is checked from the file's header before
the pixels are decoded, 16-bit images are scaled to 8 bits, colour is converted to gray, and
every problem is a :class:`~semsearch_cli.errors.ScenarioError` naming the file."""

from __future__ import annotations

import struct
from pathlib import Path

import cv2
import numpy as np

from ..errors import ScenarioError
from ..files import blame, user_file

MAX_CELLS = 25_000_000  # 5000 x 5000: the largest map accepted (memory per run, docs/usage.md "Limits")
MIN_SIDE = 3  # cells: a map narrower than this holds no free cell inside a wall


def _png_size(path: Path) -> tuple[int, int] | None:
    """(width, height) from a PNG's IHDR chunk, or None for another format."""
    with open(path, "rb") as fh:
        head = fh.read(24)
    if len(head) == 24 and head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":
        return struct.unpack(">II", head[16:24])
    return None


def read_gray(path: str | Path, what: str, owner: str | None = None, field: str = "") -> np.ndarray:
    """(H, W) uint8 gray levels of an image file (PNG, PGM, ...): 16-bit images are scaled to
    0-255 (v / 257), colour is converted to gray, an alpha channel dropped. Refused: a missing or
    unreadable file, an image of more than :data:`MAX_CELLS` cells or narrower than
    :data:`MIN_SIDE`, a file no image decoder reads."""
    path = user_file(path, what, owner, field)
    file, where = blame(path, what, owner)
    size = _png_size(path)
    if size is not None and size[0] * size[1] > MAX_CELLS:
        raise ScenarioError(file, field, f"{where} is {size[0]} x {size[1]} pixels; at most {MAX_CELLS:,} cells "
                            "(5000 x 5000) are accepted: crop it or save it at a coarser resolution")
    try:
        img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    except cv2.error as exc:
        raise ScenarioError(file, field, f"{where} cannot be decoded ({str(exc).strip().splitlines()[-1]})") from None
    if img is None:
        raise ScenarioError(file, field, f"{where} is not a readable image (expected a PNG or PGM: dark = wall, light = free)")
    if img.ndim == 3:
        img = cv2.cvtColor(img, cv2.COLOR_BGRA2GRAY if img.shape[2] == 4 else cv2.COLOR_BGR2GRAY)
    if img.dtype == np.uint16:
        img = (img.astype(np.uint32) * 255 // 65535).astype(np.uint8)
    elif img.dtype != np.uint8:
        raise ScenarioError(file, field, f"{where} has {img.dtype} pixels; save it as an 8- or 16-bit image")
    H, W = img.shape
    if H * W > MAX_CELLS:
        raise ScenarioError(file, field, f"{where} is {W} x {H} pixels; at most {MAX_CELLS:,} cells (5000 x 5000) are accepted")
    if min(H, W) < MIN_SIDE:
        raise ScenarioError(file, field, f"{where} is {W} x {H} pixels: too small to hold a robot")
    return img
