"""Where numba keeps gearcheck's compiled kernels.

numba caches a kernel beside its source (``__pycache__``) or, where that is read-only, in the user's cache folder;
with neither writable (a read-only install used by a user without a writable home) it refuses to define the
kernel at all ("cannot cache function: no locator available"), and its module could not be imported.  There
:func:`ensure_cache_folder`, called by each module of cached kernels before it defines them (not by ``import
gearcheck``, which loads no numba), points numba at a private folder of this user in the system's temporary folder,
and the kernels compile there once per machine instead.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from gearcheck.shared.outputs import private_folder


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def ensure_cache_folder(sources: Path) -> Path | None:
    """Give numba a cache folder when neither ``sources``' ``__pycache__`` nor the user's cache folder can be
    written (and the user named none, ``NUMBA_CACHE_DIR``); returns the folder given, or None."""
    from numba.core import config
    from numba.misc.appdirs import AppDirs

    if config.CACHE_DIR or _writable(sources / "__pycache__") or \
            _writable(Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)):
        return None
    folder = Path(tempfile.gettempdir()) / f"gearcheck-numba-{os.getuid()}"
    if not private_folder(folder):
        folder = Path(tempfile.mkdtemp(prefix="gearcheck-numba-"))  # that one is not this user's own: a new one
    config.CACHE_DIR = str(folder)
    return folder
