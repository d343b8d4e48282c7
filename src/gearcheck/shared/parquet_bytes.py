"""Parquet tables held in memory (a sweep point's, a cache file's, a profile's): written, and read in the calling
thread.

``pyarrow.parquet.read_table`` reads a buffer through Arrow's dataset scanner, whose I/O threads can still hold
the buffer, a Python object, after the call has returned; one of them releasing it while the interpreter exits
takes the GIL after finalization and aborts the process ("terminate called without an active exception": a
script that swept demo-3p on 2 workers ended so in 1 of 12 to 20 runs).  :class:`pyarrow.parquet.ParquetFile`
reads the file whole in this thread, and the buffer is released here.  Its columns are decoded in this thread too
(``use_threads=False``; by default Arrow's CPU threads decode them, slices of the buffer in hand: a point's table is
a few hundred kB, and the same abort was seen once more, in 1552 tests, while they did), and a table's metadata
alone is read the same way (:func:`metadata`).
"""

from __future__ import annotations

import pyarrow as pa
import pyarrow.parquet as pq


def read_table(data: bytes) -> pa.Table:
    """The table (schema metadata included) of the Parquet file ``data``."""
    return pq.ParquetFile(pa.BufferReader(data)).read(use_threads=False)


def metadata(data: bytes) -> dict:
    """The schema metadata of the Parquet file ``data`` ({} where it has none), its columns not read."""
    return pq.ParquetFile(pa.BufferReader(data)).schema_arrow.metadata or {}


def to_bytes(table: pa.Table) -> bytes:
    """``table`` as a Parquet file (zstd), the same bytes for the same table."""
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink, compression="zstd")
    return sink.getvalue().to_pybytes()
