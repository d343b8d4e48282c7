"""Output places: checked before any work, written whole or not at all, one writer at a time.

:class:`OutputDirectory` wraps everything a command writes into one folder ``out``:

* on entry it refuses a place that cannot be written (``out`` is a file, an ancestor is a file, the
  nearest existing ancestor is not writable) and a folder it must not replace (one that holds files
  and is no earlier output: every output carries a ``MARKER`` file), and takes a lock on ``out``'s real path
  (symbolic links resolved: two paths to one folder are one lock), a file in the user's own folder of locks
  (:func:`lock_folder`, so nothing is written near ``out`` yet, and no other user's file or link is ever opened):
  a second run into the same folder is refused at once, naming the process that holds it.  Holding the lock, it
  clears what a killed run left beside ``out`` (a temporary ``.partial`` folder; a ``.previous`` output put back
  if ``out`` is gone), saying so;
* ``.path`` is a temporary folder beside ``out``, made (with any missing parents) when first asked for;
* on a clean exit the temporary folder replaces ``out`` (exchanged in one step where the system can,
  ``renameat2``; else two renames); on an error or an interruption it is removed, with any parents it made, and
  ``out`` stays as it was: the previous complete output, or nothing.
  Ctrl-C and SIGTERM wait while the folders are made, swapped or removed (a few milliseconds), so
  neither can leave an unrecorded or half-removed folder behind; they take effect right after.  One that comes
  as the run leaves, before they are held, ends it as an interrupted run: the previous output stays.

:func:`write_file` does the same for one file.
"""

from __future__ import annotations

import contextlib
import ctypes
import fcntl
import hashlib
import os
import re
import shutil
import signal
import stat
import sys
import tempfile
from pathlib import Path

from gearcheck.shared.errors import GearcheckError

MARKER = ".gearcheck"
"""The file that marks a folder as gearcheck's output, which the next run into it may replace whole."""


def check_place(out: Path, what: str, folder: bool = True) -> None:
    """Refuse ``out`` (a folder, or a file when not ``folder``; ``what`` names the option, or the Python argument
    as ``name=``) when it cannot be written."""
    out = Path(out)
    named = f"{what}{out}" if what.endswith("=") else f"{what} {out}"
    if out.exists() and out.is_dir() != folder:
        raise GearcheckError(f"{named}: exists and is {'a folder' if out.is_dir() else 'not a folder'}")
    if not folder and out.exists() and not out.is_file():  # replaced whole, a device node would be gone
        raise GearcheckError(f"{named}: is not a regular file (a device, FIFO or socket); gearcheck writes files")
    ancestor = out.absolute().parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise GearcheckError(f"{named}: {ancestor} is a file, not a folder")
    try:  # the only sure test of writing is to write: a file made and gone at once
        with tempfile.TemporaryFile(dir=ancestor):
            pass
    except OSError as exc:
        raise GearcheckError(f"{named}: {ancestor} is not writable ({exc.strerror or exc})") from None


def private_folder(folder: Path) -> bool:
    """Make ``folder`` (mode 0700) if it is missing; whether it is a real folder of this user's that nobody else
    may write (a folder or link planted there by another user is never taken)."""
    with contextlib.suppress(OSError):
        folder.mkdir(mode=0o700)
    try:
        info = os.lstat(folder)
    except OSError:
        return False
    return stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o022


def lock_folder() -> Path:
    """The user's own folder of output locks: ``$XDG_RUNTIME_DIR/gearcheck``, else ``gearcheck-UID`` in the
    system's temporary folder; refused unless it is a :func:`private_folder`."""
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime and os.path.isdir(runtime):
        folder = Path(runtime) / "gearcheck"
    else:
        folder = Path(tempfile.gettempdir()) / f"gearcheck-{os.getuid()}"
    if not private_folder(folder):
        raise GearcheckError(f"{folder}: the folder for gearcheck's locks is not a private folder of this user "
                             "(a link, or another user's, or writable by others): remove it")
    return folder


def _lock_file(out: Path):
    """The lock of the output folder ``out``, open for reading and writing, never through a link."""
    key = hashlib.sha256(str(out).encode()).hexdigest()[:24]
    fd = os.open(lock_folder() / f"{key}.lock", os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    return os.fdopen(fd, "r+")


LEFTOVER = r"\.{name}\.[a-z0-9_]{{8}}\.(partial|previous)"  # mkdtemp's names beside an output (OutputDirectory.path)


def _clear_leftovers(out: Path) -> list[str]:
    """What killed runs left beside ``out`` (the caller holds its lock, so no run is writing them): temporary
    folders removed, and a previous output put back where ``out`` is gone (a kill between two renames).  Returns
    what was done, in words."""
    done = []
    pattern = re.compile(LEFTOVER.format(name=re.escape(out.name)))
    if not out.parent.is_dir():
        return done
    for path in sorted(out.parent.iterdir()):
        kind = pattern.fullmatch(path.name)
        if kind is None or path.is_symlink() or not path.is_dir():
            continue
        if kind[1] == "previous" and not os.path.lexists(out):
            os.rename(path, out)
            done.append(f"put back {out.name}, the output a killed run had set aside as {path.name}")
        else:
            shutil.rmtree(path, ignore_errors=True)
            done.append(f"removed {path.name}, left by a killed run")
    return done


def _umask() -> int:
    """The process's umask (read by setting it, and put back at once)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _make_parents(path: Path) -> list[Path]:
    """mkdir -p, returning the folders it made (deepest last)."""
    made = []
    for parent in reversed(path.absolute().parents):
        if not parent.exists():
            parent.mkdir()
            made.append(parent)
    return made


class OutputDirectory:
    """Context manager: a folder written whole or not at all, one writer at a time (see the module doc)."""

    def __init__(self, out, what: str = "--out"):
        self.out = Path(os.path.normpath(Path(out).absolute()))
        self.given = out
        self.what = what
        self._tmp: Path | None = None
        self._made: list[Path] = []
        self._lock = None

    def __enter__(self) -> "OutputDirectory":
        if self.out == self.out.parent:
            raise GearcheckError(f"{self.what} {self.given}: give a folder of its own, not the file system's root")
        check_place(self.out, self.what)
        if self.out.is_dir() and any(self.out.iterdir()) and not (self.out / MARKER).exists():
            found = ", ".join(sorted(p.name for p in self.out.iterdir())[:3])
            raise GearcheckError(f"{self.what} {self.given}: holds files that gearcheck did not write ({found}, ...), "
                                 "which a run would replace: give a new or empty folder, or an earlier output")
        self.out = Path(os.path.realpath(self.out))  # the folder itself: one lock whatever the path to it
        try:
            self._lock = _lock_file(self.out)
        except OSError as exc:
            raise GearcheckError(f"{self.what} {self.given}: cannot take the output's lock ({exc.strerror or exc})"
                                 ) from None
        try:
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._lock.seek(0)
            holder = self._lock.read().strip() or "another process"
            self._lock.close()
            raise GearcheckError(f"{self.what} {self.given}: another gearcheck run (pid {holder}) is writing it"
                                 ) from None
        self._lock.seek(0)
        self._lock.truncate()
        self._lock.write(str(os.getpid()))
        self._lock.flush()
        try:
            with _signals_deferred():
                for line in _clear_leftovers(self.out):
                    print(f"gearcheck: {self.given}: {line}", file=sys.stderr)
        except BaseException as exc:  # entered no further: the lock goes with it
            self._lock.close()
            if isinstance(exc, OSError):
                raise GearcheckError(f"{self.what} {self.given}: what a killed run left beside it cannot be cleared "
                                     f"({exc.strerror or exc})") from None
            raise
        return self

    @property
    def path(self) -> Path:
        """The temporary folder to write into (made when first asked for)."""
        if self._tmp is None:
            with _signals_deferred():  # a folder made is a folder recorded, so an interruption removes it
                try:
                    self._made = _make_parents(self.out)
                    self._tmp = Path(tempfile.mkdtemp(prefix=f".{self.out.name}.", suffix=".partial",
                                                      dir=self.out.parent))
                    os.chmod(self._tmp, 0o777 & ~_umask())  # the output's, not the temporary folder's 0700
                    (self._tmp / MARKER).write_text("gearcheck output: the next gearcheck run into this folder "
                                                    "replaces it whole\n", encoding="utf-8")
                except OSError as exc:
                    raise GearcheckError(f"{self.what} {self.given}: cannot be written ({exc.strerror or exc})"
                                         ) from None
        return self._tmp

    def __exit__(self, kind, error, trace) -> None:
        try:
            with _signals_deferred():
                self._finish(kind)
        except BaseException:
            if self._lock.closed:  # finished (or failed while finishing): the error stands as it is
                raise
            with _signals_deferred():  # interrupted on the way in, before the signals were held: as interrupted
                self._finish(KeyboardInterrupt)
            raise

    def _finish(self, kind) -> None:
        try:
            if kind is None and self._tmp is not None:
                self._replace()
            elif self._tmp is not None:
                shutil.rmtree(self._tmp, ignore_errors=True)
                for folder in reversed(self._made):
                    try:
                        folder.rmdir()
                    except OSError:
                        break
        finally:
            self._lock.close()

    def _replace(self) -> None:
        if not self.out.exists():
            os.rename(self._tmp, self.out)
            return
        if _exchange(self._tmp, self.out):  # the new output in place, the previous one now at the temporary name
            shutil.rmtree(self._tmp, ignore_errors=True)
            return
        old = self._tmp.with_name(self._tmp.name[:-len(".partial")] + ".previous")
        os.rename(self.out, old)
        try:
            os.rename(self._tmp, self.out)
        except BaseException:
            os.rename(old, self.out)  # the new one could not be put in place: the previous one back
            shutil.rmtree(self._tmp, ignore_errors=True)
            raise
        shutil.rmtree(old, ignore_errors=True)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux's ``renameat2`` with ``RENAME_EXCHANGE``); False where the system or the
    file system cannot."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    return renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0


@contextlib.contextmanager
def _signals_deferred():
    """Hold SIGINT and SIGTERM back, delivered on leaving: meanwhile their handlers only note them, so neither a
    new one nor one that arrived just before but was not yet handled can break in (signals are the main
    thread's: elsewhere nothing is held).  Installing a handler first runs any pending one, so an interruption can
    still come on the way in, before anything here is done."""
    noted = []
    previous = {}
    try:
        for signum in (signal.SIGINT, signal.SIGTERM):
            previous[signum] = signal.signal(signum, lambda number, frame: noted.append(number))
    except ValueError:  # not the main thread
        pass
    except BaseException:
        _restore(previous)
        raise
    try:
        yield
    finally:
        _restore(previous)
        for signum in dict.fromkeys(noted):
            signal.raise_signal(signum)


def _restore(handlers: dict) -> None:
    for signum, handler in handlers.items():
        signal.signal(signum, signal.SIG_DFL if handler is None else handler)


def write_file(path, data: bytes | str, what: str = "-o") -> None:
    """Write ``data`` to ``path`` whole or not at all: through a temporary file in the same folder (signals
    wait the milliseconds this takes, so an interruption leaves the previous file or the new one)."""
    path = Path(path)
    check_place(path, what, folder=False)
    with _signals_deferred():
        try:
            made = _make_parents(path)
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.parent)
        except OSError as exc:
            raise GearcheckError(f"{what} {path}: cannot be written ({exc.strerror or exc})") from None
        try:
            os.fchmod(fd, 0o666 & ~_umask())  # the file's, not the temporary file's 0600
            with os.fdopen(fd, "wb") as f:
                f.write(data.encode("utf-8") if isinstance(data, str) else data)
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            for folder in reversed(made):
                folder.rmdir()
            raise
