"""Where a run's files live: a local directory or any URL pyarrow/fsspec can write.

``Store(out)`` wraps the output location of a run so that the runner, its
workers (local processes or Dask workers on other machines) and the table
readers use one set of operations:

* a local path (``runs/x``, ``/data/x`` or ``file:///data/x``) is written with
  plain ``os`` calls, each file to a temporary name, fsync'ed and renamed, and
  the directory fsync'ed after the rename, so a crash (even a power cut) never
  leaves a half-written file under a final name (part files skip the directory
  fsync: a rename a power cut undoes only makes resume redo that chunk);
* a URL (``s3://bucket/x``, ``gs://…``, ``hdfs://…``, ``memory://x`` or any
  other protocol fsspec knows) goes through ``pyarrow.fs``: pyarrow's own
  filesystems first, fsspec's (wrapped in ``pyarrow.fs.FSSpecHandler``) for the
  rest. The file is written to a temporary name and moved; on object stores
  an object only appears once its upload completes, which gives the same
  guarantee.

A ``Store`` pickles as its URL, so it travels to worker processes cheaply.
"""

from __future__ import annotations

import fcntl
import json
import os
import posixpath
import shutil
import time
from pathlib import Path

from hhscatter.errors import OutputError

TMP_MARK = ".tmp-"  # temporary files are ".<final name>.tmp-<pid>"
LOCK_FILE = ".hhscatter.lock"  # the pid of the run directory's writer (the lock itself is on the directory: Store.lock)
LOCK_TRIES = 20  # Store.lock tries this often, 10 ms apart, before the directory counts as locked


class LockedError(OutputError):
    """Another process holds the run directory's write lock."""


def _is_url(out) -> bool:
    return isinstance(out, str) and "://" in out and not out.startswith("file://")


class Store:
    """Store(out) -> output location; ``out`` a local path or a URL (see module doc)."""

    def __init__(self, out):
        if isinstance(out, Store):
            out = out.url
        self.url = str(out)
        self.local = not _is_url(out)
        if self.local:
            p = self.url.removeprefix("file://")
            self.root = str(Path(p).expanduser().resolve())
            self._fs = None
        else:
            self._fs, self.root = _filesystem(self.url)
            self.root = self.root.rstrip("/")

    def __reduce__(self):
        return (Store, (self.url,))

    def __repr__(self):
        return f"Store({self.url!r})"

    # -- paths ---------------------------------------------------------------
    def path(self, *parts) -> str:
        """path(*parts) -> full path (local path or filesystem path) of root/parts."""
        return (
            posixpath.join(self.root, *[str(p) for p in parts if p])
            if not self.local
            else os.path.join(self.root, *[str(p) for p in parts if p])
        )

    def display(self, rel: str = "") -> str:
        """A path as the user gave it (URL kept), for messages."""
        if not rel:
            return self.url
        return self.url.rstrip("/") + "/" + rel if not self.local else os.path.join(self.url, rel)

    @property
    def filesystem(self):
        """pyarrow filesystem for pyarrow.dataset / parquet calls (None for local paths)."""
        return self._fs

    # -- queries -------------------------------------------------------------
    def exists(self, rel: str = "") -> bool:
        if self.local:
            return os.path.exists(self.path(rel))
        import pyarrow.fs as pafs  # deferred: pyarrow loads on first use

        return self._fs.get_file_info(self.path(rel)).type != pafs.FileType.NotFound

    def is_dir(self, rel: str = "") -> bool:
        if self.local:
            return os.path.isdir(self.path(rel))
        import pyarrow.fs as pafs  # deferred: pyarrow loads on first use

        return self._fs.get_file_info(self.path(rel)).type == pafs.FileType.Directory

    def listdir(self, rel: str = "") -> list[str]:
        """listdir(rel) -> names (not paths) directly under root/rel; [] if missing."""
        if self.local:
            try:
                return sorted(os.listdir(self.path(rel)))
            except (FileNotFoundError, NotADirectoryError):
                return []
        import pyarrow.fs as pafs  # deferred: pyarrow loads on first use

        if not self.is_dir(rel):
            return []
        infos = self._fs.get_file_info(pafs.FileSelector(self.path(rel), recursive=False))
        return sorted(posixpath.basename(i.path.rstrip("/")) for i in infos)

    def files(self, rel: str = "", *, recursive: bool = True) -> list[str]:
        """files(rel) -> relative paths (to root/rel) of all files below root/rel, sorted."""
        base = self.path(rel)
        if self.local:
            out = []
            for dirpath, _, names in os.walk(base):
                for n in names:
                    out.append(os.path.relpath(os.path.join(dirpath, n), base).replace(os.sep, "/"))
                if not recursive:
                    break
            return sorted(out)
        import pyarrow.fs as pafs  # deferred: pyarrow loads on first use

        if not self.is_dir(rel):
            return []
        infos = self._fs.get_file_info(pafs.FileSelector(base, recursive=recursive))
        return sorted(posixpath.relpath(i.path, base) for i in infos if i.type == pafs.FileType.File)

    def read_text(self, rel: str) -> str:
        if self.local:
            return Path(self.path(rel)).read_text()
        with self._fs.open_input_stream(self.path(rel)) as fh:
            return fh.read().decode()

    def open_input(self, rel: str):
        """open_input(rel) -> a random-access file for pyarrow.parquet."""
        if self.local:
            return self.path(rel)
        return self._fs.open_input_file(self.path(rel))

    # -- one writer ----------------------------------------------------------
    def lock(self) -> int | None:
        """lock() -> file descriptor of root holding an exclusive ``flock`` on the run directory itself (local paths).

        The lock is on the directory, not on a file in it: deleting or replacing ``.hhscatter.lock`` (which only
        notes the holder's pid, for messages) does not free it. The kernel drops the lock when the holder exits,
        however it ends (kill -9 included), so a killed run never leaves it stuck. Raises :class:`LockedError`
        naming the holder's pid if another process holds it. Release with :meth:`unlock`. URLs (object stores)
        have no such lock: returns None.
        """
        if not self.local:
            return None

        self.makedirs()
        fd = os.open(self.root, os.O_RDONLY | os.O_DIRECTORY)
        for attempt in range(LOCK_TRIES):  # a reader's momentary shared probe (writer()) is waited out
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if attempt + 1 < LOCK_TRIES:
                    time.sleep(0.01)
        else:
            os.close(fd)
            raise LockedError(f"{self.display()} is being written by another process (pid {self._holder()})")
        try:  # the holder's pid, for the message of a second writer
            pid_fd = os.open(self.path(LOCK_FILE), os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            try:
                os.write(pid_fd, str(os.getpid()).encode())
            finally:
                os.close(pid_fd)
        except OSError:
            os.close(fd)
            raise
        return fd

    def _holder(self) -> str:
        try:
            return Path(self.path(LOCK_FILE)).read_text().strip() or "?"
        except OSError:
            return "?"

    def writer(self) -> str | None:
        """writer() -> the pid (text; "?" when its note is gone) of the process that holds the run directory's write
        lock now, or None (no writer, a missing directory, or a URL).

        A shared ``flock`` probe, released at once (:meth:`lock` waits such a probe out).
        """
        if not self.local or not os.path.isdir(self.root):
            return None
        fd = os.open(self.root, os.O_RDONLY | os.O_DIRECTORY)
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return self._holder()
        finally:
            os.close(fd)  # (closing the descriptor releases the probe)
        return None

    @staticmethod
    def unlock(fd) -> None:
        """unlock(fd) -> None: release a lock taken by :meth:`lock` (None: no-op)."""
        if fd is not None:
            os.close(fd)

    # -- changes -------------------------------------------------------------
    def makedirs(self, rel: str = ""):
        if self.local:
            os.makedirs(self.path(rel), exist_ok=True)
        else:
            self._fs.create_dir(self.path(rel), recursive=True)

    def remove(self, rel: str):
        """Delete a file or a whole directory tree under root (missing: no-op)."""
        if self.local:
            p = self.path(rel)
            if os.path.isdir(p):
                shutil.rmtree(p)
            elif os.path.lexists(p):
                os.unlink(p)
            return
        if self.is_dir(rel):
            self._fs.delete_dir(self.path(rel))
        elif self.exists(rel):
            self._fs.delete_file(self.path(rel))

    def write_atomic(self, rel: str, write, *, sync_dir: bool = True) -> None:
        """write_atomic(rel, write, sync_dir=True) -> None: ``write(target, filesystem)`` writes a temp file,
        then rename.

        ``target`` is a path (local) or a path on ``filesystem``. On any
        failure the temporary file is removed and the error propagates; a
        previous file under the final name is never touched until the rename.
        ``sync_dir=False`` (local): the file is fsync'ed before its rename as always (a file under its final
        name is complete), but the directory is not fsync'ed after it, so a power cut may undo the rename:
        for files whose absence is redone on resume (part files: a chunk is complete only when all its parts
        are there), this saves the directory fsync (5-8 ms per part measured, as much as writing it).
        """
        final = self.path(rel)
        head, name = os.path.split(final) if self.local else posixpath.split(final)
        tmp = (os.path.join if self.local else posixpath.join)(head, f".{name}{TMP_MARK}{os.getpid()}")
        self.makedirs(os.path.dirname(rel) if self.local else posixpath.dirname(rel))
        try:
            write(tmp, self._fs)
            if self.local:
                with open(tmp, "rb") as fh:
                    os.fsync(fh.fileno())
                os.replace(tmp, final)
                if sync_dir:
                    _fsync_dir(head)
            else:
                self._fs.move(tmp, final)
        except BaseException:
            try:
                if self.local:
                    if os.path.exists(tmp):
                        os.unlink(tmp)
                elif self.exists(posixpath.relpath(tmp, self.root)):
                    self._fs.delete_file(tmp)
            except OSError:
                pass
            raise

    def write_text(self, rel: str, text: str) -> None:
        """Write a small text file atomically."""

        def write(target, fs):
            if fs is None:
                with open(target, "w") as fh:
                    fh.write(text)
            else:
                with fs.open_output_stream(target) as fh:
                    fh.write(text.encode())

        self.write_atomic(rel, write)

    def write_json(self, rel: str, doc) -> None:
        self.write_text(rel, json.dumps(doc, indent=2, sort_keys=True))

    def remove_temporaries(self, rel: str = "") -> int:
        """Delete temporary files left by killed writers below root/rel; return how many."""
        n = 0
        for f in self.files(rel):
            base = posixpath.basename(f)
            if base.startswith(".") and TMP_MARK in base:
                self.remove(posixpath.join(rel, f) if rel else f)
                n += 1
        return n


def _fsync_dir(path):
    """fsync a directory so a rename in it survives a power cut (no-op where unsupported)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _filesystem(url: str):
    """_filesystem(url) -> (pyarrow.fs.FileSystem, path): pyarrow's own first, then fsspec's."""
    import pyarrow.fs as pafs  # deferred: pyarrow loads on first use

    try:
        return pafs.FileSystem.from_uri(url)
    except Exception:  # noqa: BLE001, S110 - pyarrow lacks this protocol (or its build lacks it): try fsspec
        pass
    try:
        import fsspec  # deferred: fsspec loads on first use
    except ImportError:
        raise ValueError(
            f"out: {url!r}: pyarrow cannot open this URL and fsspec is not installed (pip install fsspec)"
        ) from None
    try:
        fs, path = fsspec.core.url_to_fs(url)
    except (ValueError, ImportError) as exc:
        raise ValueError(f"out: {url!r}: no filesystem for this URL ({exc})") from None
    return pafs.PyFileSystem(pafs.FSSpecHandler(fs)), path
