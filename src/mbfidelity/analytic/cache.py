"""Persistent cache of what is expensive and deterministic: symbolic derivations and the
source code of their compiled numeric functions.

An entry is keyed by the content it depends on: the system's module and the rest of
`systems/` that is not another mechanism (the description), the structural parameters
it is built for (`System.structure_tag`: the number of elements of a chain), the
derivation and compilation code of `analytic/`, and the SymPy and Python versions. Any change to them
gives a new key, so an entry is never stale; old keys are simply not read again.

Location: ``$MBFIDELITY_CACHE_DIR`` if set, otherwise the user cache directory of
`platformdirs`. ``MBFIDELITY_NO_CACHE=1`` (the commands' ``--no-cache``) bypasses it:
everything is recomputed and nothing is written. Results are bitwise identical either way:
a cached function is the same source text, executed the same way.

Every file holds the SHA-256 of its payload in front of it; a partial, truncated or
corrupted file fails the check and is rebuilt, never trusted. Files are written to a
temporary name in the same directory and renamed, so two processes filling the same entry
at once each leave a complete file (the last rename wins; both contents are equal).
"""
from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

#: bump when the layout or the meaning of an entry changes
FORMAT = "1"

_ANALYTIC_SOURCES = ("cache.py", "derivation.py", "numeric.py")


def enabled() -> bool:
    return os.environ.get("MBFIDELITY_NO_CACHE", "") not in ("1", "true", "yes")


def disable() -> None:
    """No reads and no writes in this process and in the workers it starts."""
    os.environ["MBFIDELITY_NO_CACHE"] = "1"


def directory() -> Path:
    override = os.environ.get("MBFIDELITY_CACHE_DIR")
    if override:
        return Path(override)
    import platformdirs

    return Path(platformdirs.user_cache_dir("mbfidelity"))


@lru_cache(maxsize=None)
def _file_digest(path: str) -> bytes:
    return hashlib.sha256(Path(path).read_bytes()).digest()


def system_key(module_file: str, structure: str = "") -> str:
    """Content key of one mechanism's entries (see the module docstring). `structure`
    ("N=16"): the structural parameters the mechanism is built for, part of the key
    (a chain of 16 elements is another derivation than one of 8)."""
    import sympy

    here = Path(__file__).parent
    systems_dir = Path(module_file).parent
    h = hashlib.sha256()
    h.update(f"{FORMAT}|sympy {sympy.__version__}|python {sys.version_info[:2]}".encode())
    if structure:
        h.update(f"|structure {structure}".encode())
    # the description machinery: systems/ files that are not mechanism modules (those of
    # the package itself too, for a mechanism in one of its groups, systems/<group>/)
    package = here.parent / "systems"
    folders = [package, systems_dir] if package in systems_dir.parents else [systems_dir]
    shared = [p for folder in folders for p in sorted(folder.glob("*.py"))
              if p.name.startswith("_") or p.name == "model.py"]
    for path in [Path(module_file), *shared, *(here / n for n in _ANALYTIC_SOURCES)]:
        h.update(path.name.encode())
        h.update(_file_digest(str(path)))
    return h.hexdigest()[:32]


def analytic_digest() -> str:
    """Digest of every module of `analytic/`: part of the name of entries computed by more
    of it than the derivation (the errata comparisons)."""
    h = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(_file_digest(str(path)))
    return h.hexdigest()[:16]


def load(key: str, name: str) -> bytes | None:
    """The payload of entry `name` under `key`, or None (missing, disabled, corrupted)."""
    if not enabled():
        return None
    path = directory() / key / name
    try:
        blob = path.read_bytes()
    except OSError:
        return None
    digest, _, payload = blob.partition(b"\n")
    if digest != hashlib.sha256(payload).hexdigest().encode():
        return None
    return payload


def store(key: str, name: str, payload: bytes) -> None:
    """Write entry `name` atomically (temporary file, then rename). A cache that cannot
    be written (read-only disk, full disk) is skipped: it only costs time."""
    if not enabled():
        return
    folder = directory() / key
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload)
            os.replace(tmp, folder / name)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return
