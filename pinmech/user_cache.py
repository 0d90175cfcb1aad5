"""Generated model files (a drawn linkage's URDF, a rewritten MJCF) in a folder only this user can touch.

Pinocchio's parsers read files, so a model pinmech generates is written to disk first. The
shared temporary folder is open to every local user, so a file there is used only when:

  * its folder `$TMPDIR/pinmech-<uid>` is a real folder (not a symbolic link), owned by this
    user, with no permission for anyone else (mode 0700); otherwise this process makes a
    fresh private folder (`tempfile.mkdtemp`, 0700, removed at exit) and uses that;
  * the file is named by the SHA-256 of its text, is a regular file owned by this user, and
    holds exactly that text when read back; otherwise it is written anew;
  * it is written through `tempfile.mkstemp` (an unpredictable name, created exclusively)
    and renamed into place whole.

A built file (a compiled kernel, the kernel generator: `cached_build`) is named by the
SHA-256 of everything it is built from, and used only where it and its record, a file
beside it holding the SHA-256 of its bytes, are regular files of this user's and the
bytes read back match the record; otherwise it is built anew.
"""

from __future__ import annotations

import atexit
import hashlib
import os
import shutil
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator

_fallback: Path | None = None


def cached_text(kind: str, suffix: str, text: str) -> Path:
    """A file holding exactly `text` in this user's private cache folder.

    Args:
        kind: the file name's prefix ("linkage", "mjcf").
        suffix: its extension (".urdf", ".xml").
        text: the content (UTF-8).
    """
    data = text.encode("utf-8", errors="surrogateescape")
    folder = private_folder()
    path = folder / f"{kind}-{hashlib.sha256(data).hexdigest()}{suffix}"
    if not _holds(path, data):
        _write(folder, path, data)
    return path


def cached_build(kind: str, key: str, suffix: str, build: Callable[[Path], None]) -> tuple[Path, bool]:
    """A built file in this user's private cache folder, and whether it was there already.

    Processes that ask for the same file at once (test workers, a study's workers) build it
    once: the first takes the file's lock and builds, the others wait on the lock and then
    find it built.

    Args:
        kind: the file name's prefix ("kernel", "kernelgen").
        key: the SHA-256 (hex) of everything the file is built from.
        suffix: its extension (".so", "").
        build: writes the file at the path it is given (in the same folder).
    """
    folder = private_folder()
    path = folder / f"{kind}-{key}{suffix}"
    record = folder / f"{kind}-{key}{suffix}.sha256"
    if _verified(path, record):
        return path, True
    with _locked(folder / f".{path.name}.lock"):
        if _verified(path, record):  # built by another process while this one waited
            return path, True
        handle, name = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
        os.close(handle)
        try:
            build(Path(name))
            os.chmod(name, 0o700)
            digest = _digest(Path(name))
            if digest is None:
                raise OSError(f"{name}: the build wrote no file")
            _write(folder, record, digest.encode("ascii"))
            os.replace(name, path)
        except BaseException:
            Path(name).unlink(missing_ok=True)
            raise
    return path, False


def cached_path(kind: str, key: str, suffix: str) -> Path | None:
    """The built file `cached_build` keeps for (kind, key, suffix), where it is there and
    verified; None where it is not (nothing is built)."""
    folder = private_folder()
    path = folder / f"{kind}-{key}{suffix}"
    return path if _verified(path, folder / f"{kind}-{key}{suffix}.sha256") else None


def _verified(path: Path, record: Path) -> bool:
    """`path` is a regular file of this user's whose SHA-256 its `record` holds."""
    digest = _digest(path)
    return digest is not None and _holds(record, digest.encode("ascii"))


@contextmanager
def _locked(lock: Path) -> Iterator[None]:
    """An exclusive lock on `lock` (made 0600 if absent) for the block; none where the
    system has no `fcntl` (Windows: two processes may then build the same file twice)."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    fd = os.open(lock, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def _digest(path: Path) -> str | None:
    """The SHA-256 of a regular file of this user's (read without following links), or None."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    with os.fdopen(fd, "rb") as handle:
        info = os.fstat(handle.fileno())
        if not stat.S_ISREG(info.st_mode) or (_uid() is not None and info.st_uid != _uid()):
            return None
        return hashlib.file_digest(handle, "sha256").hexdigest() if hasattr(hashlib, "file_digest") else \
            hashlib.sha256(handle.read()).hexdigest()


def private_folder() -> Path:
    """`$TMPDIR/pinmech-<uid>` if it is this user's alone (made so if absent), else a fresh
    folder of this process's own."""
    folder = Path(tempfile.gettempdir()) / f"pinmech-{_uid() if _uid() is not None else 'user'}"
    try:
        os.mkdir(folder, 0o700)
    except FileExistsError:
        pass
    except OSError:
        return _own_folder()
    return folder if is_private(folder) else _own_folder()


def is_private(folder: Path) -> bool:
    """A real folder (not a link) owned by this user, with no access for group or others."""
    try:
        info = os.lstat(folder)
    except OSError:
        return False
    if not stat.S_ISDIR(info.st_mode):
        return False
    if _uid() is None:  # no owners to compare (Windows): the folder of the user's own temp
        return True
    return info.st_uid == _uid() and stat.S_IMODE(info.st_mode) & 0o077 == 0


def _holds(path: Path, data: bytes) -> bool:
    """The file is a regular file of this user's holding exactly `data` (read without following links)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return False
    with os.fdopen(fd, "rb") as handle:
        info = os.fstat(handle.fileno())
        if not stat.S_ISREG(info.st_mode) or (_uid() is not None and info.st_uid != _uid()):
            return False
        return handle.read(len(data) + 1) == data


def _write(folder: Path, path: Path, data: bytes) -> None:
    """Through a new file of an unpredictable name, renamed over `path` when whole."""
    handle, name = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
        os.replace(name, path)
    except BaseException:
        Path(name).unlink(missing_ok=True)
        raise


def _own_folder() -> Path:
    """A private folder for this process (0700, unpredictable name), removed at exit."""
    global _fallback
    if _fallback is None or not is_private(_fallback):
        _fallback = Path(tempfile.mkdtemp(prefix="pinmech-"))
        atexit.register(shutil.rmtree, _fallback, ignore_errors=True)
    return _fallback


def _uid() -> int | None:
    return os.getuid() if hasattr(os, "getuid") else None
