"""Files made from saved results (the report's figures, the animation frames) kept in the persistent cache
(`analytic.cache`: its folder, its switch ``MBFIDELITY_NO_CACHE``, its checksums and
atomic writes), named by the content they are made from.

A file that is a function of its inputs alone (a figure: the saved series or geometry,
the row's name, its engines in drawing order, the mechanism's coordinate names) and of
the code that makes it is kept under a name that is the digest of all of these: every
array by its dtype, shape and bytes, every number by its type and bits, and the caller's
digest of its code (for the figures: the source of `reports/` and the Matplotlib and
NumPy versions; for the animation frames: the animation module and the system's
description and derivation). Any change to them gives another name, so an entry is never stale, and
a file taken from the cache is the one the maker wrote, byte for byte (the maker must be
deterministic: Matplotlib's PNG output of the same drawing is bitwise the same). An entry
holds every file one call wrote; a call that failed is not stored.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..analytic import cache

#: the cache folder of these files (beside the mechanisms' folders)
FOLDER = "report-files"
#: bump when the layout or the meaning of an entry changes
FORMAT = "1"


def _feed(h: "hashlib._Hash", value: Any) -> None:
    """`value` into the digest `h`, exactly: equal feeds, equal inputs (type included)."""
    if isinstance(value, np.ndarray):
        array = np.ascontiguousarray(value)
        h.update(f"ndarray:{array.dtype.str}:{array.shape}:".encode())
        h.update(array.tobytes())
    elif isinstance(value, dict):
        h.update(f"dict:{len(value)}:".encode())
        for key in sorted(value, key=str):
            h.update(f"key:{key!r}:".encode())
            _feed(h, value[key])
    elif isinstance(value, (list, tuple)):
        h.update(f"{type(value).__name__}:{len(value)}:".encode())
        for item in value:
            _feed(h, item)
    elif isinstance(value, (float, np.floating)):
        h.update(f"{type(value).__name__}:{float(value).hex()};".encode())
    elif value is None or isinstance(value, (bool, int, np.integer, str)):
        h.update(f"{type(value).__name__}:{value!r};".encode())
    else:
        raise TypeError(f"no exact digest of a {type(value).__name__}")


def entry_name(kind: str, inputs: Any, code: bytes) -> str | None:
    """The entry's name for the files of `kind` made from `inputs` by the code whose
    digest is `code` (None where an input has no exact digest: those files are made, not
    cached)."""
    h = hashlib.sha256(f"{FORMAT}|".encode() + code)
    h.update(kind.encode())
    try:
        _feed(h, inputs)
    except TypeError:
        return None
    return f"{kind}-{h.hexdigest()[:32]}.figures"


def _pack(files: dict[str, bytes]) -> bytes:
    header = json.dumps([[name, len(data)] for name, data in files.items()])
    return header.encode() + b"\n" + b"".join(files.values())


def _unpack(payload: bytes) -> dict[str, bytes]:
    header, _, body = payload.partition(b"\n")
    files, at = {}, 0
    for name, size in json.loads(header):
        if Path(name).name != name or size < 0 or at + size > len(body):
            raise ValueError("not an entry of figures")
        files[name] = body[at:at + size]
        at += size
    if at != len(body):
        raise ValueError("not an entry of figures")
    return files


def made(kind: str, inputs: Any, code: bytes, out: Path,
         draw: Callable[[], list[str]]) -> list[str]:
    """`draw()` (the names of the files it wrote in `out`), or the same files written
    from the cache entry of `kind`, `inputs` and `code` when there is one. A name
    starting with "!" is a failure: such a result is returned, never stored."""
    name = entry_name(kind, inputs, code)
    if name is None:
        return draw()
    blob = cache.load(FOLDER, name)
    if blob is not None:
        try:
            files = _unpack(blob)
        except (ValueError, TypeError):  # an unreadable entry is redrawn, never trusted
            files = None
        if files is not None:
            for file_name, data in files.items():
                (out / file_name).write_bytes(data)
            return list(files)
    names = draw()
    if names and not any(n.startswith("!") for n in names):
        cache.store(FOLDER, name, _pack({n: (out / n).read_bytes() for n in names}))
    return names
