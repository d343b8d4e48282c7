"""The history of cross-checks: one record per (commit, train) in a SQLite file, and change points.

Why SQLite: the store is one file that CI restores and saves whole; no server; an append is one
transaction (an interrupted run leaves the previous store), and the primary key (commit, train)
makes appending again an upsert; any SQLite client, pandas or a spreadsheet import reads it.  A
Parquet dataset would be either one small file per run (thousands of files to carry between CI
runs) or one file rewritten on every append.

Schema ``gearcheck.history`` version 1 (in the table ``meta``)::

    commits(commit_id PRIMARY KEY, date, seq)   date: ISO 8601 UTC; seq: order of first appearance
    runs(commit_id, train, verdict, failures, unresolved, moved, steady_state, duration_s, input_speed_rpm,
         gearcheck_version, mujoco_version, numpy_version, python, machine, git_revision, train_sha256,
         PRIMARY KEY (commit_id, train))       failures, unresolved, moved: JSON lists
    metrics(commit_id, train, position, item, metric, kind, unit, value, tolerance, status, gated,
            PRIMARY KEY (commit_id, train, item, metric))

A run's metrics (``item`` / ``metric``): per quantity (``item`` its name) ``nrmse`` (gated against
``tolerance`` when the quantity is), ``reference.rms``, ``reference.peak_to_peak``, ``test.rms``,
``test.peak_to_peak`` (in the quantity's unit), ``integration_error.reference`` and
``integration_error.test`` (with the quantity's tolerance, which their sum must stay below); per
mode (``item`` "mode N") ``rel_error`` (gated), ``reference.frequency`` and ``test.frequency`` (Hz);
``item`` "wall_time" and "cpu_time" (this process's, its threads included; reports up to gearcheck 0.2.0 have wall
time only): one metric per timed step (s).

Change points (:func:`change_points`): point ``i`` of a metric's series over commits is where the
metric moved when both the point and the median of the next ``CONFIRM`` points (itself included)
differ, on the same side, from the median of the previous ``WINDOW`` points (counted from the last
change point) by more than the threshold ``max(K * sigma, TOLERANCE_SHARE * tolerance,
relative * |median|, ROUND_OFF)``.  ``sigma`` is the noise: the median absolute difference of
successive points among the previous ``NOISE_WINDOW`` (never across a change point) and in the
confirming window, over 0.6745 * sqrt(2) (a standard deviation for Gaussian noise), times
``1 + 2 / n`` for ``n`` differences and ``sqrt(1 + 1 / m)`` for a level from ``m`` points (a noise or
a level known from few points asks for a larger move).  Deterministic metrics (gearcheck's, on one
machine and one set of versions) have no noise, and the floors decide.  A single outlier is no
change point (the median after it is at the old level); a step is marked once, at its first commit,
and its new level becomes the reference; a move at the latest commit has nothing after it to
confirm it and is marked at once.
"""

from __future__ import annotations

import contextlib
import functools
import datetime as _dt
import json
import math
import sqlite3
from pathlib import Path
from statistics import median

import pandas as pd

from gearcheck.shared.errors import GearcheckError, shown

SCHEMA = "gearcheck.history"
SCHEMA_VERSION = 2  # 2: the sides' metrics named reference.* and test.* (1: lumped.* and mujoco.*)
REPORT_SCHEMA, REPORT_SCHEMA_VERSION = "gearcheck.crosscheck", 2  # what it records
RENAMED = (("lumped", "reference"), ("mujoco", "test"))  # version 1's side names, version 2's

WINDOW = 8  # points before a candidate whose median is the level it moved from
CONFIRM = 3  # points from a candidate on whose median the move must persist
NOISE_WINDOW = 30  # points before a candidate whose successive differences measure the noise
K = 4.0  # noise multiples a move must exceed
TOLERANCE_SHARE = 0.1  # a gated metric moves when it moves by this share of its tolerance
RELATIVE_FLOOR = 0.01  # a physical value (amplitude, frequency) moves when it moves by this part of itself
ROUND_OFF = 1e-12  # moves below this (in the metric's unit) are round-off
TIMES = ("wall_time", "cpu_time")  # the report's timings of its steps (its ``volatile`` part)
_NOISE = 0.6745 * math.sqrt(2.0)  # median |x_j - x_j-1| of Gaussian noise, in standard deviations

_TABLES = """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE commits (commit_id TEXT PRIMARY KEY, date TEXT NOT NULL, seq INTEGER NOT NULL UNIQUE);
CREATE TABLE runs (
    commit_id TEXT NOT NULL REFERENCES commits(commit_id), train TEXT NOT NULL, verdict TEXT NOT NULL,
    failures TEXT NOT NULL, unresolved TEXT NOT NULL, moved TEXT, steady_state INTEGER,
    duration_s REAL, input_speed_rpm REAL, gearcheck_version TEXT, mujoco_version TEXT, numpy_version TEXT,
    python TEXT, machine TEXT, git_revision TEXT, train_sha256 TEXT,
    PRIMARY KEY (commit_id, train)) WITHOUT ROWID;
CREATE TABLE metrics (
    commit_id TEXT NOT NULL, train TEXT NOT NULL, position INTEGER NOT NULL, item TEXT NOT NULL,
    metric TEXT NOT NULL, kind TEXT, unit TEXT, value REAL, tolerance REAL, status TEXT, gated INTEGER NOT NULL,
    PRIMARY KEY (commit_id, train, item, metric),
    FOREIGN KEY (commit_id, train) REFERENCES runs(commit_id, train)) WITHOUT ROWID;
"""


@functools.cache
def columns() -> dict[str, set[str]]:
    """Each table's columns, as _TABLES makes them (read back from a store made in memory, when first asked)."""
    con = sqlite3.connect(":memory:")
    try:
        con.executescript(_TABLES)
        tables = [row[0] for row in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")]
        return {t: {row[1] for row in con.execute(f"PRAGMA table_info({t})")} for t in tables}
    finally:
        con.close()

MAX_COMMIT = 200  # characters of a commit id: a git hash is 40, a tag or build name a few dozen
_ORDERED = "(SELECT commit_id, date, row_number() OVER (ORDER BY date, seq) - 1 AS place FROM commits)"
_RUN_COLUMNS = ("verdict", "failures", "unresolved", "moved", "steady_state", "duration_s", "input_speed_rpm",
                "gearcheck_version", "mujoco_version", "numpy_version", "python", "machine", "git_revision",
                "train_sha256")


def check_store(store) -> None:
    """Refuse, before any run, a store that exists and is not a history store of this schema version, or a
    folder; a missing one is made by the first :func:`append`."""
    if Path(store).exists() or Path(store).is_symlink():
        with _connect(store):
            pass


def checked_commit(store, commit) -> str:
    """``commit`` stripped, or GearcheckError unless it is one line of printable characters (checked before a run
    that will record under it)."""
    if not isinstance(commit, str) or not commit.strip():
        raise GearcheckError(f"history store {store}: a commit id is required to record a run, got {shown(commit)}")
    commit = commit.strip()
    if len(commit) > MAX_COMMIT or not commit.isprintable():
        raise GearcheckError(f"history store {store}: commit id {shown(commit)}: one line of at most {MAX_COMMIT} "
                             "printable characters (a revision, tag or build name)")
    return commit


def append(store, data: dict, commit: str, date: str | None = None, machine: str | None = None) -> None:
    """Record the cross-check ``data`` (a report.json dict) of ``commit`` in the SQLite file ``store``
    (made if missing), in one transaction; a record of the same commit and train is replaced.

    ``date``: the commit's date, ISO 8601 (default: now; a commit already recorded keeps its date unless
    one is given); ``machine``: where it ran (default: the report's provenance)."""
    commit = checked_commit(store, commit)
    kind = (data.get("schema"), data.get("schema_version")) if isinstance(data, dict) else type(data).__name__
    if kind != (REPORT_SCHEMA, REPORT_SCHEMA_VERSION):
        raise GearcheckError(f"history store {store}: records {REPORT_SCHEMA} version {REPORT_SCHEMA_VERSION} "
                             f"reports, not {kind}")
    when = _utc(date) if date is not None else None
    try:
        train, run, metrics = _record(data, machine)
    except (KeyError, TypeError, AttributeError) as exc:
        raise GearcheckError(f"history store {store}: the report cannot be recorded: missing or malformed field "
                             f"{exc}") from None
    with _connect(store, write=True) as con:
        con.execute("BEGIN IMMEDIATE")
        try:
            if not con.execute("SELECT count(*) FROM sqlite_master").fetchone()[0]:
                for statement in _TABLES.split(";")[:-1]:
                    con.execute(statement)
                con.executemany("INSERT INTO meta VALUES (?, ?)",
                                [("schema", SCHEMA), ("schema_version", str(SCHEMA_VERSION))])
            _check(con, store, upgrade=True)
            known = con.execute("SELECT date FROM commits WHERE commit_id = ?", (commit,)).fetchone()
            if known is None:
                seq = con.execute("SELECT coalesce(max(seq), 0) + 1 FROM commits").fetchone()[0]
                con.execute("INSERT INTO commits VALUES (?, ?, ?)", (commit, when or _utc(None), seq))
            elif when is not None:
                con.execute("UPDATE commits SET date = ? WHERE commit_id = ?", (when, commit))
            con.execute("DELETE FROM metrics WHERE commit_id = ? AND train = ?", (commit, train))
            con.execute("DELETE FROM runs WHERE commit_id = ? AND train = ?", (commit, train))
            con.execute(f"INSERT INTO runs (commit_id, train, {', '.join(_RUN_COLUMNS)}) "
                        f"VALUES ({', '.join('?' * (len(_RUN_COLUMNS) + 2))})",
                        (commit, train, *(run[c] for c in _RUN_COLUMNS)))
            con.executemany("INSERT INTO metrics VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                            [(commit, train, position, *row) for position, row in enumerate(metrics)])
            con.execute("COMMIT")
        except BaseException:
            if con.in_transaction:
                con.execute("ROLLBACK")
            raise


def read(store) -> pd.DataFrame:
    """Every recorded metric, long format, in commit order: ``order`` (the commit's place), ``commit``,
    ``date``, ``train``, ``verdict``, ``position``, ``item``, ``metric``, ``kind``, ``unit``, ``value``,
    ``tolerance``, ``status``, ``gated``."""
    with _connect(store) as con:
        frame = pd.read_sql_query(
            "SELECT c.place AS 'order', m.commit_id AS 'commit', c.date, m.train, r.verdict, m.position, m.item, "
            "m.metric, m.kind, m.unit, m.value, m.tolerance, m.status, m.gated "
            f"FROM metrics m JOIN runs r USING (commit_id, train) JOIN {_ORDERED} c USING (commit_id) "
            "ORDER BY c.place, m.train, m.position", con)
    frame["gated"] = frame["gated"].astype(bool)
    return frame


def runs(store) -> pd.DataFrame:
    """One row per recorded run, in commit order: ``order``, ``commit``, ``date``, ``train`` and the run's
    verdict, failures, unresolved and moved (lists), steady state, settings, versions and machine."""
    with _connect(store) as con:
        frame = pd.read_sql_query(
            f"SELECT c.place AS 'order', r.commit_id AS 'commit', c.date, r.train, "
            f"{', '.join('r.' + c for c in _RUN_COLUMNS)} "
            f"FROM runs r JOIN {_ORDERED} c USING (commit_id) ORDER BY c.place, r.train", con)
    for column in ("failures", "unresolved", "moved"):
        frame[column] = [_json_list(v, store, column, commit) for v, commit in zip(frame[column], frame["commit"])]
    return frame


def _json_list(text, store, column: str, commit: str) -> list | None:
    """A recorded JSON list (None where none was recorded); GearcheckError naming the record otherwise."""
    if text is None:
        return None
    try:
        value = json.loads(text)
    except (TypeError, ValueError):
        value = None
    if not isinstance(value, list):
        raise GearcheckError(f"history store {store}: runs.{column} of commit {shown(commit)} is not a JSON list: "
                             f"{shown(text)}")
    return value


def commits(store) -> list[str]:
    """The recorded commits in order: by date, then by first appearance in the store."""
    with _connect(store) as con:
        return [row[0] for row in con.execute(f"SELECT commit_id FROM {_ORDERED} ORDER BY place")]


def change_points(values, tolerance: float | None = None, relative: float = 0.0, k: float = K,
                  window: int = WINDOW, confirm: int = CONFIRM) -> list[int]:
    """Indices in ``values`` (a metric over commits, oldest first; NaN or None: not recorded, skipped) where
    the metric moved beyond its noise (the rule is in the module doc): ``tolerance`` the metric's gate,
    ``relative`` the part of its level it must move by."""
    where = [i for i, v in enumerate(values) if v is not None and math.isfinite(v)]
    x = [float(values[i]) for i in where]
    fixed = max(ROUND_OFF, TOLERANCE_SHARE * tolerance if tolerance else 0.0)
    found, marked, start = [], set(), 0
    for i in range(1, len(x)):
        before, after = x[max(start, i - window):i], x[i:i + confirm]
        level, new = median(before), median(after)
        steps = [abs(x[j] - x[j - 1]) for j in range(max(1, i - NOISE_WINDOW), i) if j not in marked]
        steps += [abs(b - a) for a, b in zip(after, after[1:])]
        sigma = median(steps) / _NOISE * (1 + 2 / len(steps)) * math.sqrt(1 + 1 / len(before)) if steps else 0.0
        threshold = max(k * sigma, fixed, relative * abs(level))
        jump, shift = x[i] - level, new - level
        if abs(jump) > threshold and abs(shift) > threshold and jump * shift > 0:
            found.append(where[i])
            marked.add(i)
            start = i
    return found


def rule(item: str, unit: str | None, tolerance: float | None) -> dict | None:
    """The keywords of :func:`change_points` for a recorded metric: its tolerance, and ``relative`` for a
    physical value (not a ratio); None for times, which are the machine's, not the code's."""
    if item in TIMES:
        return None
    return {"tolerance": tolerance, "relative": 0.0 if unit in ("1", None) else RELATIVE_FLOOR}


def _record(data: dict, machine: str | None) -> tuple[str, dict, list[tuple]]:
    """The train's name, the run's row and its metric rows (item, metric, kind, unit, value, tolerance, status,
    gated); KeyError, TypeError or AttributeError where the report lacks a field or has one malformed."""
    prov, verdict, settings = data.get("provenance") or {}, data["verdict"], data.get("settings") or {}
    run = {
        "verdict": verdict["verdict"], "failures": json.dumps(verdict.get("failures") or []),
        "unresolved": json.dumps(verdict.get("unresolved") or []),
        "moved": None if verdict.get("moved_from_baseline") is None else json.dumps(verdict["moved_from_baseline"]),
        "steady_state": _flag((data.get("steady_state") or {}).get("detected")),
        "duration_s": _value(settings.get("duration")), "input_speed_rpm": _value(settings.get("input_speed")),
        "gearcheck_version": prov.get("gearcheck_version"), "mujoco_version": prov.get("mujoco_version"),
        "numpy_version": prov.get("numpy_version"), "python": prov.get("python"),
        "machine": machine or prov.get("machine"), "git_revision": prov.get("git_revision"),
        "train_sha256": prov.get("train_sha256"),
    }
    rows = []
    for q in data.get("quantities") or []:
        tol, status = _value(q.get("tolerance_nrmse")), q.get("status")
        rows.append((q["name"], "nrmse", q["kind"], "1", _value(q["errors"]["nrmse"]), tol, status,
                     tol is not None and status != "negligible"))
        for solver in ("reference", "test"):
            for stat in ("rms", "peak_to_peak"):
                rows.append((q["name"], f"{solver}.{stat}", q["kind"], q["unit"],
                             _value((q.get(solver) or {}).get(stat)), None, None, False))
        for solver in ("reference", "test"):
            rows.append((q["name"], f"integration_error.{solver}", q["kind"], "1",
                         _value((q.get("integration_error") or {}).get(solver)), tol, None, False))
    mode_tol = _value(data.get("modes_tolerance"))
    for m in data.get("modes") or []:
        item = f"mode {m['mode']}"
        rows.append((item, "rel_error", m.get("type"), "1", _value(m["rel_error"]), mode_tol, m.get("status"),
                     mode_tol is not None))
        for solver in ("reference", "test"):
            rows.append((item, f"{solver}.frequency", m.get("type"), "Hz", _value(m.get(solver)), None, None, False))
    for clock in TIMES:
        for name, value in sorted(((data.get("volatile") or {}).get(clock) or {}).items()):
            rows.append((clock, name, clock, "s", _value(value), None, None, False))
    return data["train"]["name"], run, rows


def _value(field):
    """A number of report.json (``{"value": x, "unit": u}`` or a bare number) as a float, or None."""
    value = field.get("value") if isinstance(field, dict) else field
    if value is None or isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def _flag(value) -> int | None:
    return None if value is None else int(bool(value))


def _utc(date: str | None) -> str:
    """An ISO 8601 date-time as UTC ``YYYY-MM-DDTHH:MM:SSZ`` (naive: taken as UTC), or now."""
    if date is None:
        moment = _dt.datetime.now(_dt.timezone.utc)
    else:
        try:
            moment = _dt.datetime.fromisoformat(date.strip())
        except (ValueError, AttributeError):
            raise GearcheckError(f"commit date {date!r}: not an ISO 8601 date") from None
        if moment.tzinfo is None:
            moment = moment.replace(tzinfo=_dt.timezone.utc)
    return moment.astimezone(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


@contextlib.contextmanager
def _connect(store, write: bool = False):
    """An open connection to ``store`` (checked to be a history store unless it is new and ``write``); every
    SQLite error is a one-line GearcheckError naming the file."""
    path = Path(store)
    if path.is_dir():
        raise GearcheckError(f"history store {store}: is a folder, not a file")
    if not write and not path.is_file():
        raise GearcheckError(f"history store {store}: no such file")
    con = None
    try:
        if write:
            con = sqlite3.connect(path, timeout=30, isolation_level=None)
        else:
            con = sqlite3.connect(path.absolute().as_uri() + "?mode=ro", uri=True, timeout=30)
            _check(con, store)
        yield con
    except (sqlite3.Error, pd.errors.DatabaseError) as exc:
        raise GearcheckError(f"history store {store}: cannot be {'written' if write else 'read'} ({exc})") from None
    finally:
        if con is not None:
            con.close()


def _upgrade(con: sqlite3.Connection) -> None:
    """Version 1 to 2: the sides' metrics renamed, lumped.* to reference.* and mujoco.* to test.* (and
    integration_error.lumped to integration_error.reference, ...), as report.json version 2 keys them."""
    for old, new in RENAMED:
        con.execute("UPDATE metrics SET metric = ? || substr(metric, ?) WHERE metric LIKE ?",
                    (new, len(old) + 1, f"{old}.%"))
        con.execute("UPDATE metrics SET metric = ? WHERE metric = ?",
                    (f"integration_error.{new}", f"integration_error.{old}"))
    con.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION),))


def _check(con: sqlite3.Connection, store, upgrade: bool = False) -> None:
    """Refuse a SQLite file that is not a history store of this schema version; with ``upgrade`` (inside a write
    transaction) bring a version 1 store to version 2 first (:func:`_upgrade`)."""
    tables = {row[0] for row in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    if "meta" not in tables:
        raise GearcheckError(f"history store {store}: a SQLite file but not a gearcheck history store")
    meta = dict(con.execute("SELECT key, value FROM meta").fetchall())
    if upgrade and meta.get("schema") == SCHEMA and meta.get("schema_version") == "1":
        _upgrade(con)
        meta["schema_version"] = str(SCHEMA_VERSION)
    if meta.get("schema") == SCHEMA and meta.get("schema_version") == "1":
        raise GearcheckError(f"history store {store}: version 1; recording a run in it (--history) brings it to "
                             f"version {SCHEMA_VERSION}, whose metrics name the sides reference and test")
    if meta.get("schema") != SCHEMA or meta.get("schema_version") != str(SCHEMA_VERSION):
        raise GearcheckError(f"history store {store}: schema {meta.get('schema')} version "
                             f"{meta.get('schema_version')}, this gearcheck reads {SCHEMA} version {SCHEMA_VERSION}")
    for table, expected in columns().items():  # each table with the columns this version reads
        found = {row[1] for row in con.execute(f"PRAGMA table_info({table})")}
        if not found:
            raise GearcheckError(f"history store {store}: the table {table} is missing")
        if expected - found:
            raise GearcheckError(f"history store {store}: the table {table} lacks the column "
                                 f"{sorted(expected - found)[0]}")
