"""Reading a store's chunk files directly, without Zarr: which chunks exist and decode,
and which points they hold. A check of a large store then opens each file once."""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fivdisc.sweep.store.layout import STRING


def decoder_of(array: Any) -> Callable[[list[bytes]], np.ndarray] | None:
    """A decoder of chunk files of `array` (their bytes -> their values, one row per
    chunk), for the codecs fivdisc's stores use (a ``bytes`` or ``vlen-utf8`` codec, then
    optionally ``zstd``); None for any other. A chunk that does not decode to one chunk's
    values raises (ValueError or a codec's error)."""
    from numcodecs import VLenUTF8
    from numcodecs.zstd import decompress

    meta = array.metadata.to_dict()
    codecs = [(c["name"], c.get("configuration", {})) for c in meta["codecs"]]
    if meta["chunk_key_encoding"] != {"name": "default", "configuration": {"separator": "/"}}:
        return None
    if [name for name, _ in codecs[1:]] not in ([], ["zstd"]):
        return None
    unzip = decompress if len(codecs) == 2 else bytes
    kind, config = codecs[0]
    chunk = tuple(array.chunks)
    size = math.prod(chunk)
    if kind == "bytes" and array.dtype != STRING:
        order = "<" if config.get("endian", "little") == "little" else ">"
        dtype = array.dtype.newbyteorder(order)
        nbytes = size * dtype.itemsize

        def numbers(raws: list[bytes]) -> np.ndarray:
            parts = [unzip(raw) for raw in raws]
            if any(len(part) != nbytes for part in parts):
                raise ValueError("a chunk of the wrong size")
            values = np.frombuffer(b"".join(parts), dtype=dtype).astype(array.dtype)
            return values.reshape(len(raws), *chunk)

        return numbers
    if kind == "vlen-utf8" and array.dtype == STRING:
        text = VLenUTF8()

        def strings(raws: list[bytes]) -> np.ndarray:
            values = [text.decode(unzip(raw)) for raw in raws]
            if any(v.size != size for v in values):
                raise ValueError("a chunk of the wrong size")
            flat = np.concatenate(values) if values else np.empty(0, dtype=object)
            return np.asarray(flat, dtype=STRING).reshape(len(raws), *chunk)

        return strings
    return None


def chunk_files(directory: str, depth: int) -> list[tuple[tuple[int, ...], str]]:
    """(chunk index, file) of every chunk file under an array's ``c`` directory (a
    directory in a file's place is listed too: it fails to read)."""
    level: list[tuple[tuple[int, ...], str]] = [((), directory)]
    for _ in range(depth):
        deeper = []
        for head, path in level:
            try:
                names = os.listdir(path)
            except OSError:  # no chunk written yet, or a file in a directory's place
                continue
            deeper += [((*head, int(name)), f"{path}/{name}") for name in names
                       if name.isdigit()]
        level = deeper
    return level


READ_BYTES = 1 << 16  # bytes per read: most chunks are smaller, larger ones are read on


def read_chunk(file: str) -> bytes | None:
    """The bytes of a chunk file (b"" if it cannot be read), None if it is gone.

    Through the operating system's calls: a third of the cost of a Python file object for
    the files of a few bytes a store is made of."""
    try:
        fd = os.open(file, os.O_RDONLY)
    except FileNotFoundError:
        return None
    except OSError:
        return b""
    try:
        parts = [os.read(fd, READ_BYTES)]
        while len(parts[-1]) == READ_BYTES:
            parts.append(os.read(fd, READ_BYTES))
        return b"".join(parts)
    except OSError:
        return b""
    finally:
        os.close(fd)


def decode_distinct(decode: Callable[[list[bytes]], np.ndarray], raws: list[bytes]
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(rows, index) of chunk files' bytes: every distinct content decoded once (in a
    store of one point per chunk, a flag, an empty error or a repeated value is the same
    few bytes at every point), and per
    chunk the row of its values in `rows`, -1 for a chunk that does not decode."""
    distinct = dict.fromkeys(raws)
    contents = list(distinct)
    try:
        rows = decode(contents)
        valid = np.ones(len(contents), dtype=bool)
    except Exception:  # one chunk or more is damaged: find which (the type varies)
        decoded, valid = [], np.zeros(len(contents), dtype=bool)
        for k, raw in enumerate(contents):
            try:
                decoded.append(decode([raw]))
                valid[k] = True
            except Exception:
                pass
        rows = np.concatenate(decoded) if decoded else np.empty(0)
    code = np.full(len(contents), -1, dtype=np.intp)
    code[valid] = np.arange(int(valid.sum()))
    for k, raw in enumerate(contents):
        distinct[raw] = code[k]
    return rows, np.array([distinct[raw] for raw in raws], dtype=np.intp)


def blocks_of(mask: np.ndarray, grid: Sequence[int], block: Sequence[int]) -> np.ndarray:
    """Per chunk of shape `block` over `grid` (C order), whether any point of `mask` (flat,
    one entry per point) lies in it."""
    counts = [-(-n // b) for n, b in zip(grid, block, strict=True)]
    padded = np.zeros([c * b for c, b in zip(counts, block, strict=True)], dtype=bool)
    padded[tuple(slice(0, n) for n in grid)] = mask.reshape(grid)
    split = padded.reshape([x for cb in zip(counts, block, strict=True) for x in cb])
    return split.any(axis=tuple(range(1, 2 * len(grid), 2))).ravel()


def points_of(per_chunk: np.ndarray, grid: Sequence[int], block: Sequence[int]) -> np.ndarray:
    """Per point (flat, C order), the entry of its chunk: `per_chunk` has one row per
    chunk of shape `block` over `grid` (C order), the chunk's values in that row's
    leading ``block`` axes (anything after them is kept)."""
    counts = [-(-n // b) for n, b in zip(grid, block, strict=True)]
    k = len(grid)
    tail = per_chunk.shape[1 + k:]
    spread = per_chunk.reshape(*counts, *block, *tail)
    # (c0, ..., b0, ...) -> (c0, b0, c1, b1, ...): the padded grid in C order
    order = [x for pair in zip(range(k), range(k, 2 * k), strict=True) for x in pair]
    padded = spread.transpose(*order, *range(2 * k, 2 * k + len(tail)))
    padded = padded.reshape(*[c * b for c, b in zip(counts, block, strict=True)], *tail)
    return padded[tuple(slice(0, n) for n in grid)].reshape(math.prod(grid), *tail)


def written_points(array: Any, grid: Sequence[int]) -> np.ndarray:
    """Per point (flat, C order), whether its chunk file of `array` exists (a chunk never
    written, or lost, reads as the fill value)."""
    block = tuple(array.chunks)[:len(grid)]
    counts = tuple(-(-g // b) for g, b in zip(grid, block, strict=True))
    directory = os.path.join(str(array.store_path.store.root), array.path, "c")
    listed = chunk_files(directory, array.ndim)
    chunks = np.array([c for c, _ in listed], dtype=np.int64).reshape(-1, array.ndim)
    own = ((chunks[:, len(grid):] == 0).all(axis=1)
           & (chunks[:, :len(grid)] < counts).all(axis=1))
    present = np.zeros(math.prod(counts), dtype=bool)
    present[np.ravel_multi_index(tuple(chunks[own, :len(grid)].T), counts)] = True
    return points_of(present.reshape(-1, *(1,) * len(block)) & np.ones((1, *block), bool),
                     grid, block)


def readable_points(array: Any, grid: Sequence[int], points: np.ndarray | None = None,
              undecodable: list[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(values, readable) of a Zarr array over the sweep's `grid` (chunked by blocks of
    points, see :func:`point_chunks`, or one point per chunk in formats 3 and 4), one row
    per point in C order (the order of the sweep's points): values ``(n_points,)``, or
    ``(n_points, max_points)`` for a section's. Only the chunks holding a point flagged
    in `points` (default: all) are read; the other points get the fill value. The chunk
    files that do not decode are appended to `undecodable`.

    Chunk files are listed and decoded here rather than read through Zarr, which costs
    about half a millisecond per chunk (its store reads one file per asynchronous task,
    and a chunk never written costs as much): the checks of a 300 x 300 sweep of one
    point per chunk took over a minute (see ``benchmarks/bench_store.py``). Only the
    chunk files listed are opened, and each distinct content is decoded once. Arrays of
    other codecs are read through Zarr. A chunk cut short or damaged fails to decode (the
    error type varies with the codec, hence the broad excepts); its points are unreadable.
    """
    n = math.prod(grid)
    tail = array.shape[len(grid):]
    values = np.full((n, *tail), array.fill_value, dtype=array.dtype)
    ok = np.ones(n, dtype=bool)
    wanted = np.ones(n, dtype=bool) if points is None else points
    decode = decoder_of(array)
    if decode is None:
        for i in np.flatnonzero(wanted):
            try:
                values[i] = array[np.unravel_index(i, grid)]
            except Exception:
                ok[i] = False
        return values, ok
    chunk = tuple(array.chunks)
    block = chunk[:len(grid)]
    counts = tuple(-(-g // b) for g, b in zip(grid, block, strict=True))
    directory = os.path.join(str(array.store_path.store.root), array.path, "c")
    listed = chunk_files(directory, array.ndim)
    chunks = np.array([c for c, _ in listed], dtype=np.int64).reshape(-1, array.ndim)
    # Chunks of this array's shape only (a section's values: one chunk along its own axis).
    own = (chunks[:, len(grid):] == 0).all(axis=1) & (chunks[:, :len(grid)] < counts).all(axis=1)
    at = np.flatnonzero(own)
    index = np.ravel_multi_index(tuple(chunks[at, :len(grid)].T), counts)
    # Every chunk is read when the undecodable ones are sought (they are removed before
    # a resumed sweep writes into them).
    keep = (np.ones(len(index), dtype=bool) if undecodable is not None
            else blocks_of(wanted, grid, block)[index])
    found, files, raws = [], [], []
    for i, k in zip(index[keep].tolist(), at[keep].tolist(), strict=True):
        raw = read_chunk(listed[k][1])
        if raw is not None:  # None: removed since listed, read as the fill value
            found.append(i)
            files.append(listed[k][1])
            raws.append(raw)
    rows, row = decode_distinct(decode, raws)
    found = np.array(found, dtype=np.intp)
    good = row >= 0
    if undecodable is not None:
        undecodable += [file for file, g in zip(files, good.tolist(), strict=True) if not g]
    per_chunk = np.full((math.prod(counts), *chunk), array.fill_value, dtype=array.dtype)
    if good.any():
        per_chunk[found[good]] = rows[row[good]]
    readable = np.ones(math.prod(counts), dtype=bool)
    readable[found[~good]] = False
    values[wanted] = points_of(per_chunk, grid, block)[wanted]
    ok = points_of(np.broadcast_to(readable.reshape(-1, *(1,) * len(block)),
                                 (len(readable), *block)), grid, block).copy()
    return values, ok
