"""Checksums of a sweep store's points: each point's values, error and index, hashed with
the sweep's own hash, so that a lost or damaged chunk is seen."""

from __future__ import annotations

import hashlib
from collections.abc import Sequence

import numpy as np

from fivdisc.sweep.spec import Sweep


def checksummed(sweep: Sweep) -> list[str]:
    """The variables a point's checksum covers, in order: the reductions, each section's
    values and count, then ``error``."""
    names = [r.name for r in sweep.reductions]
    for section in sweep.sections:
        names += [section.name, section.count_name]
    return [*names, "error"]


def frame_token(token: bytes) -> bytes:
    return len(token).to_bytes(4, "little") + token


NAN_TOKEN = frame_token(b"nan")
BOOL_TOKENS = np.array([frame_token(b"F"), frame_token(b"T")], dtype=object)


def value_tokens(column: np.ndarray) -> list[bytes]:
    """What the checksum hashes of every value of a column, its length ahead (see
    :func:`checksums`): a boolean as T or F, a float as its little-endian bytes (nan for
    NaN), a section's values as their little-endian bytes (one NaN for every NaN), anything
    else as its text."""
    n = len(column)
    if column.dtype == bool:
        return BOOL_TOKENS[column.astype(np.intp)].tolist()
    if column.dtype.kind == "f":
        values = column.reshape(n, -1)
        nan = np.isnan(values)
        size = 8 * values.shape[1]
        framed = np.empty((n, 4 + size), dtype=np.uint8)
        framed[:, :4] = np.frombuffer(size.to_bytes(4, "little"), dtype=np.uint8)
        framed[:, 4:] = np.where(nan, np.nan, values).astype("<f8").view(np.uint8)
        tokens = framed.view(f"V{4 + size}").ravel().tolist()
        if column.ndim == 1:  # a reduction's value: NaN as nan
            for i in np.flatnonzero(nan[:, 0]):
                tokens[i] = NAN_TOKEN
        return tokens
    return [frame_token(str(value).encode()) for value in column.tolist()]


def checksums(digest: str, indices: Sequence[int], columns: Sequence[np.ndarray]
               ) -> np.ndarray:
    """Checksums of points: per point, the BLAKE2b (8 bytes) of the sweep's digest, its
    index and its stored values, in order (`columns`: one per checksummed variable, one
    row per point of `indices`).

    Never 0, the fill value of the ``checksum`` variable (nothing written). Computed a
    column at a time (the values' bytes in one NumPy operation), then one hash per point.
    """
    blake2b = hashlib.blake2b
    sums = np.empty(len(indices), dtype=np.uint64)
    for k, (index, *row) in enumerate(zip(indices, *map(value_tokens, columns), strict=True)):
        head = f"{digest}:{index}".encode()
        sums[k] = int.from_bytes(blake2b(head + b"".join(row), digest_size=8).digest(),
                                 "little") or 1
    return sums
