"""The published JSON Schemas (draft 2020-12) of gearcheck's files: ``report.schema.json``
(:func:`gearcheck.compare.presentation.report.report_schema`) and ``train.schema.json``
(:func:`gearcheck.train.json_schema.train_schema`).  ``python -m gearcheck.compare.presentation.schemas DIR`` writes
them into DIR; the repository ships them in ``schemas/``, and the tests keep those current."""

from __future__ import annotations

import sys
from pathlib import Path

from gearcheck.compare.presentation.report import report_schema
from gearcheck.train.json_schema import schema_text, train_schema

SCHEMA_FILES = {"report.schema.json": report_schema, "train.schema.json": train_schema}


def write_schemas(directory) -> list[Path]:
    """Write the JSON Schemas of report.json and of the train file into ``directory``; return their paths."""
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    for name, make in SCHEMA_FILES.items():
        (out / name).write_text(schema_text(make()), encoding="utf-8")
    return [out / name for name in SCHEMA_FILES]


if __name__ == "__main__":
    for written in write_schemas(sys.argv[1] if len(sys.argv) > 1 else "schemas"):
        print(written)
