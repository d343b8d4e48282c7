"""Where the points of a sweep (or the samples of a study) run: a local process pool, any ``concurrent.futures``
executor, or a Dask cluster.

Each backend takes ``run`` (a module-level function of one point), the points (picklable; on Dask with a
``key``) and ``finished(point, result)``, called in this process as each point ends.  The local pool starts fresh
processes from a fork server that preloads ``run``'s module, never runs the calling script again, and ends
cleanly on Ctrl-C (its workers leave the signal to the parent); a Dask worker runs each point with glibc's
malloc thresholds as a plain process has them.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import re
import select
import signal
import sys
import threading
import time

from gearcheck.shared.errors import GearcheckError, one_line
from gearcheck.shared import trust

CONNECT_TIMEOUT = "10s"  # to a Dask scheduler


def _worker_init(grants: dict[str, str | None], parent: int) -> None:
    """Workers leave Ctrl-C to the parent, which cancels the pending points and ends them; they end as soon as the
    parent does (killed outright, it cannot end them: a watch on its process does, and the fork server, whose
    children they are, then ends too); they run with the parent's grants (:mod:`gearcheck.shared.trust`), whatever
    the fork server's environment was when it started."""
    threading.Thread(target=_end_with, args=(parent,), daemon=True, name="end with the parent").start()
    trust.restore(grants)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # blocked since the fork server (_workers_starting)


def _end_with(pid: int) -> None:
    """End this process when the process ``pid`` ends: a wait on its pidfd (Linux), else a check every second."""
    try:
        fd = os.pidfd_open(pid)
        select.select([fd], [], [])  # readable once it has ended
    except (AttributeError, OSError):  # no pidfd here, or the parent is already gone
        while True:
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                break
            except PermissionError:  # alive, another user's: cannot be ours
                pass
            time.sleep(1.0)
    os._exit(1)


def run_pool(run, pending, workers: int, finished) -> None:
    """``run`` (a module-level function) on each point of ``pending`` in ``workers`` fresh processes (forkserver,
    which preloads ``run``'s module), ``finished(point, result)`` as each ends; on Ctrl-C or an error the pending
    points are cancelled and the pool's workers ended."""
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([run.__module__])
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_worker_init,
                               initargs=(trust.grants(), os.getpid()))
    _closed_pipes_raise()
    try:
        run_futures(pool, run, pending, finished, start=_workers_starting)
    except BaseException:
        processes = list((getattr(pool, "_processes", None) or {}).values())
        manager = getattr(pool, "_executor_manager_thread", None)  # shutdown() forgets it
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:  # the pool's own workers, which this call started
            if process.is_alive():
                process.terminate()
        for process in processes:
            process.join(timeout=10)
        if manager is not None:  # it closes its wake-up pipe as it ends: Python 3.11's exit hook then skips it,
            manager.join(timeout=10)  # where it raced the close (EBADF and a traceback after "interrupted")
        raise
    pool.shutdown()


def _closed_pipes_raise() -> None:
    """From the pool's start to the end of the process, a write to a closed pipe raises (Python's own default)
    instead of ending the process: the command line ends on SIGPIPE when its output is closed (``gearcheck ... |
    head``), but the pool's pipes to its fork server, resource tracker and workers close under it at Ctrl-C, also
    while the process exits (it died of SIGPIPE after printing that it was interrupted, in half the runs of
    tests/test_sweep_interrupt.py), and multiprocessing handles that."""
    with contextlib.suppress(ValueError):  # not the main thread: its disposition is the main thread's to set
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)


@contextlib.contextmanager
def _workers_starting():
    """While the pool starts its workers (the first submissions): Ctrl-C held back until they have started (the
    fork server's imports, a second or two), so that it finds every worker in the pool, which ends them all (one
    requested of the fork server when Ctrl-C came would start after the parent is gone, and fail there with a
    traceback, or wait for points forever); the fork server started with SIGINT blocked, so that Ctrl-C, which
    reaches it too, is no traceback in its imports (it ignores SIGINT after them); the script hidden."""
    from multiprocessing import forkserver, resource_tracker

    held, installed = [], False
    try:
        previous, installed = signal.signal(signal.SIGINT, lambda signum, frame: held.append(signum)), True
    except ValueError:  # not the main thread, which alone gets KeyboardInterrupt
        pass
    try:
        resource_tracker.ensure_running()  # before the mask: starting, it unblocks SIGINT
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:  # the fork server inherits the mask (and its workers: see _worker_init)
            forkserver.ensure_running()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        with _script_hidden():
            yield
    finally:
        if installed:
            signal.signal(signal.SIGINT, signal.SIG_DFL if previous is None else previous)
            if held:
                signal.raise_signal(signal.SIGINT)  # the Ctrl-C held back, now


@contextlib.contextmanager
def _script_hidden():
    """Hide the script that runs the sweep from multiprocessing while the pool starts its workers (on the first
    submissions): they need nothing from it (the points and ``run`` are gearcheck's), so a script
    without the ``if __name__ == "__main__":`` guard is not run again in every worker, as it would be by
    multiprocessing's start methods other than fork."""
    main = sys.modules.get("__main__")
    saved = {name: getattr(main, name) for name in ("__file__", "__spec__") if hasattr(main, name)}
    try:
        if "__spec__" in saved:
            main.__spec__ = None
        if "__file__" in saved:
            del main.__file__
        yield
    finally:
        for name, value in saved.items():
            setattr(main, name, value)


def run_futures(executor, run, pending, finished, start=contextlib.nullcontext) -> None:
    """``run`` on each point of ``pending`` through ``executor`` (its submissions inside ``start()``),
    ``finished(point, result)`` as each ends; the rest cancelled on an error or Ctrl-C."""
    from concurrent.futures import as_completed

    with start():
        futures = {executor.submit(run, p): p for p in pending}
    try:
        for future in as_completed(futures):
            finished(futures[future], future.result())
    except BaseException:
        for future in futures:
            future.cancel()
        raise


def connect(scheduler):
    """(a ``distributed.Client``, whether this call opened it) for an address or a client; refused with one
    line when dask.distributed is missing or the scheduler cannot be reached."""
    try:
        import distributed
    except ImportError:
        raise GearcheckError(f"scheduler={scheduler}: needs dask.distributed (pip install 'gearcheck[cluster]')"
                             ) from None
    if isinstance(scheduler, distributed.Client):
        return scheduler, False
    if not isinstance(scheduler, str) or not re.fullmatch(r"[a-z+]+://\S+|\S+:\d+", scheduler):
        raise GearcheckError(f"scheduler={scheduler!r}: give the scheduler's address, "
                             "e.g. tcp://scheduler.example.org:8786")
    try:
        return distributed.Client(scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False), True
    except Exception as exc:  # OSError, TimeoutError, ValueError: whatever stops the connection
        raise GearcheckError(f"scheduler={scheduler}: cannot reach the Dask scheduler ({one_line(exc)})") from None


def run_dask(run, pending, scheduler, finished) -> None:
    """``run`` on each point of ``pending`` on a Dask cluster (``scheduler``: an address or a client),
    ``finished(point, result)`` as each ends; the rest cancelled on an error or Ctrl-C."""
    import distributed

    client, opened = connect(scheduler)
    try:
        # through _dask_point: Dask's workers pin glibc's malloc thresholds, up to 1.5 x the CPU per point
        futures = {client.submit(_dask_point, run, p, key=f"gearcheck-point-{p.key}", pure=False): p
                   for p in pending}
        try:
            for future in distributed.as_completed(list(futures), loop=client.loop):
                finished(futures[future], future.result())
        except BaseException:
            client.cancel(list(futures))
            raise
    finally:
        if opened:
            client.close()


def _dask_point(run, point):
    """``run(point)`` on a Dask worker, with glibc's malloc thresholds as in a plain process while it runs.
    Dask's nanny starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which also pins glibc's mmap threshold at
    128 KiB: every large array of a solver is then mapped and unmapped again and its pages faulted in anew (on
    the hub drive 1.25 to 1.5 times the CPU time per point, the extra all system time).  Dask's values come back, and
    the freed memory goes back to the system, when the worker's last running point ends."""
    with _MALLOC:
        return run(point)


class _MallocThresholds:
    """While any point runs in this process (a Dask worker may run several at once), glibc's trim and mmap
    thresholds, where the environment fixed them (MALLOC_TRIM_THRESHOLD_ without MALLOC_MMAP_THRESHOLD_), raised
    to the ceiling of glibc's own dynamic rule (32 MiB mmap, 64 MiB trim); elsewhere nothing changes."""

    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD, MMAP_DEFAULT = -1, -3, 128 * 1024

    def __init__(self):
        import threading

        self.lock = threading.Lock()
        self.running = 0
        self.libc = None  # glibc, once known to apply; False where it does not
        self.trim = 0

    def _glibc(self):
        if self.libc is None:
            self.libc = False
            text = os.environ.get("MALLOC_TRIM_THRESHOLD_")
            if sys.platform.startswith("linux") and text and "MALLOC_MMAP_THRESHOLD_" not in os.environ:
                try:
                    import ctypes

                    trim, libc = int(text), ctypes.CDLL("libc.so.6")
                    libc.mallopt, libc.malloc_trim  # glibc's own (not musl's)
                except (ValueError, OSError, AttributeError):
                    pass
                else:
                    self.libc, self.trim = libc, trim
        return self.libc

    def __enter__(self):
        with self.lock:
            if self.running == 0 and self._glibc():
                self.libc.mallopt(self.M_MMAP_THRESHOLD, 32 << 20)
                self.libc.mallopt(self.M_TRIM_THRESHOLD, 64 << 20)
            self.running += 1

    def __exit__(self, *exc) -> None:
        with self.lock:
            self.running -= 1
            if self.running == 0 and self.libc:
                self.libc.mallopt(self.M_MMAP_THRESHOLD, self.MMAP_DEFAULT)
                self.libc.mallopt(self.M_TRIM_THRESHOLD, self.trim)
                self.libc.malloc_trim(0)


_MALLOC = _MallocThresholds()
