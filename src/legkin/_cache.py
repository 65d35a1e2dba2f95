"""numba's on-disk cache of legkin's kernels, made to degrade and never break (issue 25).

numba caches a compiled kernel in two files: an index (``<kernel>-<line>.pyXY.nbi``: numba's version, the source
file's stamp, and which data file holds each signature) and one data file per signature (``...<k>.nbc``: the
pickled machine code). numba trusts both: a truncated index raised ``EOFError`` in every later process, garbage
``UnpicklingError``, a data file with flipped bytes aborted the process (SIGABRT in LLVM's object loader) and one
swapped with another kernel's crashed it (SIGSEGV); and with no writable cache directory every call raised
``RuntimeError: no locator available``, even with a complete cache to read. legkin's kernels use this cache instead:

* **Checked files.** Every file legkin writes starts with :data:`MAGIC` and the SHA-256 of its own file name and
  contents; a file whose digest does not match (truncated, garbage, flipped bytes, another kernel's file swapped
  in) is discarded with a :class:`~legkin.errors.CacheWarning` naming it, and the kernel compiled again (and
  cached anew). An index in numba's own format (written by an earlier legkin) is stale, not damaged: it is
  replaced silently, as numba replaces the index of another numba version.
* **No writable location.** numba's locators (``NUMBA_CACHE_DIR``, the package's ``__pycache__``, the user-wide
  cache directory) each need a writable directory. When none is, :class:`ReadOnlyLocator` reads the first of
  them that holds the kernel's index, and a kernel found nowhere is compiled in memory; one
  :class:`~legkin.errors.CacheWarning` per process says so (set ``NUMBA_CACHE_DIR`` to a writable directory).

This goes through numba's cache classes (``numba.core.caching``: ``FunctionCache``, ``IndexDataCacheFile``, the
locators), which numba does not document as an extension API; :data:`CHECKED_NUMBA` lists the numba versions it was
checked on, and ``tests/test_faults.py`` fails on any other, so that a new numba is checked before it is declared.
"""

from __future__ import annotations

import hashlib
import io
import os
import pickle
import sys
import threading
import warnings
from typing import Any

import numba
from numba.core import caching, config

from .errors import CacheWarning

#: The numba minor versions whose ``numba.core.caching`` internals this module was read and tested against: the floor
#: of pyproject.toml (0.60) and 0.68 (the same ``IndexDataCacheFile`` methods, ``Cache.__init__`` and file layout).
CHECKED_NUMBA = ((0, 60), (0, 68))

#: The first bytes of every cache file legkin writes (then the 32-byte SHA-256 of the file's name and contents).
MAGIC = b"LEGKINC1"

_warned: set[str] = set()
_warn_lock = threading.Lock()


def _warn_once(key: str, message: str) -> None:
    """One :class:`CacheWarning` per ``key`` and process."""
    with _warn_lock:
        if key in _warned:
            return
        _warned.add(key)
    warnings.warn(message, CacheWarning, stacklevel=2)


class DamagedCacheFile(Exception):
    """A cache file whose checksum or contents do not match (internal: the file is discarded, never raised out)."""


def _sealed(name: str, payload: bytes) -> bytes:
    """``payload`` as written to the file ``name``: :data:`MAGIC`, its digest, then the payload."""
    return MAGIC + hashlib.sha256(name.encode() + b"\0" + payload).digest() + payload


def _unsealed(name: str, raw: bytes) -> bytes:
    """The payload of a file read as ``raw`` from the file ``name``; :class:`DamagedCacheFile` when it does not match
    its digest (truncated, altered, or written under another name)."""
    head = len(MAGIC) + 32
    if len(raw) < head or not raw.startswith(MAGIC):
        raise DamagedCacheFile("not a legkin cache file" if len(raw) >= head else f"truncated ({len(raw)} bytes)")
    payload = raw[head:]
    if hashlib.sha256(name.encode() + b"\0" + payload).digest() != raw[len(MAGIC):head]:
        raise DamagedCacheFile("checksum mismatch (truncated, altered, or another kernel's file)")
    return payload


def _numba_format(raw: bytes) -> bool:
    """True if ``raw`` is an index in numba's own format (a pickled version string first): a stale index of an earlier
    legkin, not a damaged one."""
    try:
        return isinstance(pickle.load(io.BytesIO(raw)), str)
    except Exception:  # noqa: BLE001 - any unpickling failure: not numba's format
        return False


class CheckedCacheFile(caching.IndexDataCacheFile):
    """numba's index and data files, each sealed with a digest of its name and contents (:func:`_sealed`)."""

    def _read(self, path: str) -> bytes | None:
        """The bytes of ``path``; None when it does not exist or cannot be read (a cache miss)."""
        try:
            with open(path, "rb") as f:
                return f.read()
        except OSError:
            return None

    def _discard(self, path: str, reason: str) -> None:
        """Warn that ``path`` is damaged and remove it (if the directory is writable)."""
        _warn_once(f"damaged:{path}", f"legkin: damaged numba cache file {path} ({reason}): discarded, the kernel "
                                      "is compiled again")
        try:
            os.remove(path)
        except OSError:
            pass

    def _load_index(self) -> dict[Any, str]:
        raw = self._read(self._index_path)
        if raw is None or (not raw.startswith(MAGIC) and _numba_format(raw)):
            return {}  # no index yet, or numba's own format: stale, replaced on the next save
        try:
            stream = io.BytesIO(_unsealed(self._index_name, raw))
            version = pickle.load(stream)
            if version != self._version:
                return {}
            stamp, overloads = pickle.loads(stream.read())
            prefix = self._index_name[: -len(".nbi")]
            if not all(isinstance(n, str) and n.startswith(prefix) for n in overloads.values()):
                raise DamagedCacheFile("names another kernel's data files")
        except Exception as exc:  # noqa: BLE001 - whatever a damaged file makes pickle raise
            self._discard(self._index_path, str(exc) or type(exc).__name__)
            return {}
        return overloads if stamp == self._source_stamp else {}

    def _save_index(self, overloads: dict[Any, str]) -> None:
        body = pickle.dumps(self._version, protocol=-1) + self._dump((self._source_stamp, overloads))
        with self._open_for_write(self._index_path) as f:
            f.write(_sealed(self._index_name, body))

    def _load_data(self, name: str) -> Any:
        path = self._data_path(name)
        raw = self._read(path)
        if raw is None:
            raise FileNotFoundError(path)  # numba's load(): a data file removed while the index names it
        try:
            return pickle.loads(_unsealed(name, raw))
        except Exception as exc:  # noqa: BLE001 - whatever a damaged file makes pickle raise
            self._discard(path, str(exc) or type(exc).__name__)
            raise FileNotFoundError(path) from exc

    def _save_data(self, name: str, data: Any) -> None:
        with self._open_for_write(self._data_path(name)) as f:
            f.write(_sealed(name, self._dump(data)))


def _locator_base() -> type:
    """numba's in-tree locator class (named ``_InTreeCacheLocator`` up to numba 0.6x, ``InTreeCacheLocator`` after)."""
    base: type = getattr(caching, "InTreeCacheLocator", None) or getattr(caching, "_InTreeCacheLocator")
    return base


class ReadOnlyLocator(_locator_base()):  # type: ignore[misc]
    """The last locator: no cache directory is writable. Reads the first of numba's cache directories that holds the
    kernel's index (``NUMBA_CACHE_DIR``, the package's ``__pycache__``, the user-wide cache), else points at the
    package's ``__pycache__``; writing fails there and the kernel lives in memory (:meth:`KernelCache.save_overload`).
    """

    def __init__(self, py_func: Any, py_file: str) -> None:
        super().__init__(py_func, py_file)
        stem = os.path.splitext(os.path.basename(py_file))[0]
        base = f"{stem}.{py_func.__qualname__}-{py_func.__code__.co_firstlineno}".replace("<", "").replace(">", "")
        index = f"{base}.py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}.nbi"
        for path in self._candidates(py_func, py_file):
            if os.path.isfile(os.path.join(path, index)):
                self._cache_path = path
                break
        _warn_once("write", "legkin: no writable numba cache directory (NUMBA_CACHE_DIR, the package's "
                                "__pycache__, the user cache directory): kernels load from a cache found there, "
                                "others compile in memory in each process; set NUMBA_CACHE_DIR to a writable "
                                "directory to keep them")

    @staticmethod
    def _candidates(py_func: Any, py_file: str) -> list[str]:
        """The cache directories of numba's own locators, in numba's order (nothing touched on disk)."""
        out = []
        cls: Any
        for cls in KernelCacheImpl._locator_classes[:-1]:
            if "IPython" in cls.__name__ or "Zip" in cls.__name__ or ("UserProvided" in cls.__name__
                                                                        and not getattr(config, "CACHE_DIR", "")):
                continue
            out.append(cls(py_func, py_file).get_cache_path())
        return out

    def ensure_cache_path(self) -> None:  # noqa: D102 - numba API: nothing to create, nothing is written here
        pass


class KernelCacheImpl(caching.FunctionCache._impl_class):  # type: ignore[misc,name-defined,valid-type]
    """numba's compile-result cache with :class:`ReadOnlyLocator` after numba's own locators."""

    _locator_classes = [*caching.FunctionCache._impl_class._locator_classes, ReadOnlyLocator]


class KernelCache(caching.FunctionCache):
    """numba's ``FunctionCache`` on :class:`CheckedCacheFile` and :class:`KernelCacheImpl`; a failed write (a
    read-only or full disk) leaves the kernel compiled in memory, with one warning per process."""

    _impl_class = KernelCacheImpl

    def __init__(self, py_func: Any) -> None:
        super().__init__(py_func)
        numba_file = self._cache_file
        self._cache_file = CheckedCacheFile(self._cache_path, self._impl.filename_base, numba_file._source_stamp)

    def save_overload(self, sig: Any, data: Any) -> None:  # noqa: D102 - numba API
        try:
            super().save_overload(sig, data)
        except OSError as exc:
            _warn_once("write", f"legkin: cannot write numba's cache in {self._cache_path} ({exc.strerror or exc}): "
                                "the kernels compiled in this process are not cached")


def numba_checked() -> bool:
    """True if the installed numba's minor version is one of :data:`CHECKED_NUMBA`."""
    return tuple(int(x) for x in numba.__version__.split(".")[:2]) in CHECKED_NUMBA


def function_cache(py_func: Any) -> Any:
    """The cache of one kernel: a :class:`KernelCache`; numba's ``NullCache`` (compiled in memory, one warning per
    process) if numba's cache classes are not what this module expects (a numba not in :data:`CHECKED_NUMBA`)."""
    try:
        return KernelCache(py_func)
    except Exception as exc:  # noqa: BLE001 - a numba whose cache internals changed: never break a call for it
        _warn_once("numba", f"legkin: numba {numba.__version__}'s cache cannot be used ({type(exc).__name__}: "
                            f"{exc}): kernels compile in memory in each process")
        return caching.NullCache()
