"""Reading the files a user names: train files, measurement and tolerance files, torque profiles, model
files, recorded results, baselines.

Every read is bounded: a file is opened without blocking (a FIFO never waits for a writer), refused unless it is a
regular file (not a folder, FIFO, device or socket), and read to at most its kind's limit (a file that grows while
it is read too); an array archive (``.npz``, ``.mat``) has the sizes its headers declare checked before anything
is decompressed.  Every failure is a :class:`~gearcheck.shared.errors.GearcheckError` naming the file and what is
wrong: missing, not a regular file, unreadable, too large, not UTF-8 (with the byte offset), not TOML, or nested
deeper than Python's parser recurses.
"""

from __future__ import annotations

import glob
import io
import math
import os
import stat
import tomllib
import zipfile
from pathlib import Path

import numpy as np

from gearcheck.shared.errors import GearcheckError, TrainFileError, one_line

MAX_BYTES = 16 * 1024 * 1024
"""Text files (train, measurements, torque tables, baselines): the largest shipped train file is some 10 kB."""
MAX_DATA_BYTES = 256 * 1024 * 1024
"""Data files (recorded results, model matrices), on disk and as their headers declare them decompressed: a
recorded run of a million samples of 30 signals is 240 MB of doubles; a model of 2000 coordinates, 32 MB a
matrix."""


def read_bytes(path: str | Path, what: str = "file", limit: int = MAX_BYTES) -> bytes:
    """The bytes of ``path``, a regular file of at most ``limit`` bytes; ``what`` names it in messages."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC)
    except FileNotFoundError:
        raise GearcheckError(f"{path}: no such {what}") from None
    except OSError as exc:
        raise GearcheckError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise GearcheckError(f"{path}: is a directory, not a {what}")
        if not stat.S_ISREG(info.st_mode):
            raise GearcheckError(f"{path}: is not a regular file (a FIFO, device or socket), not a {what}")
        too_large = GearcheckError(f"{path}: {info.st_size / 2**20:.1f} MiB is too large for a {what} "
                                   f"(at most {limit / 2**20:g} MiB)")
        if info.st_size > limit:
            raise too_large
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(2**20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        data = b"".join(chunks)
    except OSError as exc:
        raise GearcheckError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise too_large
    return data


def read_arrays(path: str | Path, what: str, limit: int = MAX_DATA_BYTES, **loadmat) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` (no Python objects) or ``.mat`` file (``loadmat``: scipy's options), their
    declared sizes checked against ``limit`` before they are read; errors name the file."""
    path = Path(path)
    stream = io.BytesIO(read_bytes(path, what, limit))
    if path.suffix.lower() == ".npz" and not zipfile.is_zipfile(stream):
        raise TrainFileError(str(path), "", "not an .npz archive")
    try:
        declared = _npz_sizes(stream, path) if path.suffix.lower() == ".npz" else _mat_sizes(stream)
        if declared > limit:
            raise GearcheckError(f"{path}: its arrays declare {declared / 2**20:.1f} MiB, too large for a {what} "
                                 f"(at most {limit / 2**20:g} MiB)")
        stream.seek(0)
        if path.suffix.lower() == ".npz":
            with np.load(stream, allow_pickle=False) as archive:
                return {k: archive[k] for k in archive.files}
        import scipy.io

        return {k: v for k, v in scipy.io.loadmat(stream, **loadmat).items() if not k.startswith("__")}
    except GearcheckError:
        raise
    except NotImplementedError:  # MATLAB v7.3 files are HDF5
        raise TrainFileError(str(path), "", "a MATLAB v7.3 (HDF5) file: save it with save(..., '-v7')") from None
    except Exception as exc:  # the readers raise many kinds on a damaged file
        raise TrainFileError(str(path), "", f"cannot be read as {path.suffix}: {one_line(exc)}") from None


def _npz_sizes(stream, path: Path) -> int:
    """The bytes the arrays of an .npz archive declare in their headers (``.npy`` format 1 or 2); none may hold
    Python objects."""
    total = 0
    with zipfile.ZipFile(stream) as archive:
        for name in archive.namelist():
            with archive.open(name) as member:
                version = np.lib.format.read_magic(member)
                header = np.lib.format.read_array_header_1_0 if version == (1, 0) else \
                    np.lib.format.read_array_header_2_0
                shape, _, dtype = header(member)
                if dtype.hasobject:
                    raise TrainFileError(str(path), name.removesuffix(".npy"), "saved as Python objects: save names "
                                         "as a string array (np.array(names, dtype=str)) and numbers as numeric "
                                         "arrays")
                total += math.prod(shape) * dtype.itemsize
    return total


def _mat_sizes(stream) -> int:
    """The bytes the variables of a .mat file declare (8 per element, 16 complex)."""
    import scipy.io

    return sum(math.prod(shape) * (16 if kind == "complex" else 8) for _, shape, kind in scipy.io.whosmat(stream))


def read_text(path: str | Path, what: str = "file") -> str:
    """The UTF-8 text of ``path``; ``what`` names it in messages ("train file", "measurements file")."""
    data = read_bytes(path, what)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        byte = data[exc.start:exc.start + 1]
        raise GearcheckError(f"{path}: the {what} is not UTF-8 text (byte {exc.start}: {byte!r})") from None


def parse_toml(text: str, source: str) -> dict:
    """The TOML document of ``text``; errors name ``source``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise TrainFileError(source, "", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise TrainFileError(source, "", "not valid TOML: nested too deeply") from None
    except ValueError as exc:  # an integer past Python's 4300 digits
        raise TrainFileError(source, "", f"not valid TOML: {str(exc).split(';')[0]}") from None


def read_toml(path: str | Path, what: str = "file") -> dict:
    return parse_toml(read_text(path, what), str(path))


GLOB_CHARACTERS = frozenset("*?[")
MAX_TRAINS = 10000  # a fleet's train files, after folders and patterns are expanded


def train_list(items: list[str], option: str = "TRAIN") -> list[str]:
    """The trains a fleet names, in order, each once: a preset name or train file as it is, a folder as every
    ``*.toml`` directly in it (sorted), a pattern with ``*``, ``?`` or ``[`` that names no file as the files it
    matches (sorted; ``**`` reaches into subfolders).  A folder or pattern that yields no file is refused."""
    trains: list[str] = []
    seen: set[str] = set()
    for item in items:
        path = Path(item)
        if path.is_dir():
            found = sorted(str(p) for p in path.glob("*.toml") if p.is_file())
            if not found:
                raise GearcheckError(f"{option} {item}: a folder with no .toml train file in it")
        elif GLOB_CHARACTERS & set(item) and not path.exists():
            found = sorted(p for p in glob.glob(item, recursive=True) if Path(p).is_file())
            if not found:
                raise GearcheckError(f"{option} {item!r}: the pattern matches no file")
        else:
            found = [item]
        for train in found:  # a file named twice (a.toml, ./a.toml) runs once
            key = os.path.realpath(train) if Path(train).exists() else train
            if key not in seen:
                seen.add(key)
                trains.append(train)
        if len(trains) > MAX_TRAINS:
            raise GearcheckError(f"{option}: more than {MAX_TRAINS} trains")
    return trains


def report_folders(trains: list[str]) -> list[str]:
    """A folder name per train of a fleet, unique: a preset's name, a file's stem, and where two files share a stem
    as many of their parent folders' names in front (``a-train``, ``b-train``) as tell them apart."""
    parts = [tuple(x for x in Path(t).with_suffix("").parts if x not in (os.sep, "..", "."))
             if t.endswith(".toml") else (t,) for t in trains]
    depth = [1] * len(parts)
    while True:
        names = ["-".join(p[-d:]) for p, d in zip(parts, depth)]
        clashes = {n for n in names if names.count(n) > 1}
        grow = [i for i, n in enumerate(names) if n in clashes and depth[i] < len(parts[i])]
        if not grow:
            break
        for i in grow:
            depth[i] += 1
    # the same path written two ways (./a.toml, a.toml) or nothing left to tell apart: numbered
    return [f"{n}-{i + 1}" if n in clashes else n for i, n in enumerate(names)]
