"""The README's generated reference: train-file fields and mesh stiffness models.

``python -m gearcheck.train.docs [README.md]`` rewrites the blocks between the README's
``<!-- NAME:begin -->``/``<!-- NAME:end -->`` markers (NAME: schema, models, references, measurements);
``tests/test_readme.py`` fails when they are stale.
"""

from __future__ import annotations

import sys
from pathlib import Path

from gearcheck.train.mesh_stiffness import MODELS
from gearcheck.train.schema import MEASUREMENTS_FILE, _row, markdown_reference
from gearcheck.shared.citations import REFERENCES


def models_reference() -> str:
    """One table of every mesh stiffness model's parameters."""
    rows = ["| model | parameter | type | unit | default | range | meaning |", "|---|---|---|---|---|---|---|"]
    for name, cls in MODELS.items():
        doc = (cls.__doc__ or "").strip().splitlines()[0]
        rows.append(f"| `{name}` | | | | | | {doc} |")
        for key, spec in cls.parameters.fields.items():
            rows.append(_row(key, spec).replace(f"| `{key}` |", f"| | `{key}` |", 1))
    return "\n".join(rows) + "\n"


def references_table() -> str:
    """The table of gearcheck's references, by key."""
    rows = ["| key | reference |", "|---|---|"]
    rows += [f"| `{key}` | {ref.citation} |" for key, ref in REFERENCES.items()]
    return "\n".join(rows) + "\n"


def measurements_reference() -> str:
    """The field-by-field reference of a measurements file (``--measurements``)."""
    return markdown_reference(MEASUREMENTS_FILE)


BLOCKS = {"schema": markdown_reference, "models": models_reference, "references": references_table,
          "measurements": measurements_reference}


def _split(text: str, name: str) -> tuple[str, str, str]:
    """(everything up to and with the begin marker, the block, the end marker and the rest)."""
    begin, end = f"<!-- {name}:begin -->\n", f"<!-- {name}:end -->"
    head, rest = text.split(begin, 1)
    inside, tail = rest.split(end, 1)
    return head + begin, inside, end + tail


def block(text: str, name: str) -> str:
    return _split(text, name)[1]


def update_readme(path) -> bool:
    """Rewrite every generated block of the README; True when something changed."""
    path = Path(path)
    text = original = path.read_text(encoding="utf-8")
    for name, make in BLOCKS.items():
        head, _, tail = _split(text, name)
        text = head + make() + tail
    path.write_text(text, encoding="utf-8")
    return text != original


if __name__ == "__main__":
    target = sys.argv[1] if len(sys.argv) > 1 else "README.md"
    print(f"{target}: {'updated' if update_readme(target) else 'already current'}")
