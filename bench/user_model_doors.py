"""The door x content matrix of a user's model (tests/test_user_doors.py): each content through each door, the
command line's exit status and verdict (or its one line), as a Markdown table.

    python bench/user_model_doors.py
"""

import importlib.util
import tempfile
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / "tests" / "test_user_doors.py"


def main() -> None:
    spec = importlib.util.spec_from_file_location("test_user_doors", TESTS)
    doors = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(doors)
    print("| content | " + " | ".join(doors.DOORS) + " | expected |")
    print("|---" * (len(doors.DOORS) + 2) + "|")
    for content, (_, expected, _) in doors.CONTENTS.items():
        cells = []
        for door in doors.DOORS:
            if (door, content) not in doors.CASES:
                cells.append("n/a")
                continue
            with tempfile.TemporaryDirectory() as tmp:
                status, said, _ = doors.outcome(Path(tmp), door, content)
            cells.append(f"{status} {said}" if status != doors.INVALID else f"2: {said}")
        print(f"| {content} | " + " | ".join(cells) + f" | {expected} |")


if __name__ == "__main__":
    main()
