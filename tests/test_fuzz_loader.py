"""Property-based fuzzing of the train-file loader: every preset, mutated (a number nudged, a value
replaced by one of another type or magnitude, a key removed, a key added), either loads or is refused
with gearcheck's own error; nothing else ever escapes.  Fixed seed and a bounded number of examples, so
the suite stays fast and every run tries the same files."""

from __future__ import annotations

import copy
import tomllib

import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearcheck.train.loader import load_text, preset_names, preset_text
from gearcheck.shared.errors import GearcheckError

DOCUMENTS = {name: tomllib.loads(preset_text(name)) for name in preset_names()}
OUTCOMES = {"loaded": 0, "refused": 0}


def paths(node, prefix=()):
    """Every (path to a value) of a parsed TOML document, tables and arrays included."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        yield prefix + (key,)
        yield from paths(value, prefix + (key,))


VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(min_value=-10**30, max_value=10**30),
    st.sampled_from([0, -1, 1, 1e300, -1e300, 1e-300, 5e-324, 2**63, 10**400, -10**400, 0.5, 1e9, True, False, "",
                     "x" * 300, "stage1.sun"]),
    st.text(max_size=20), st.lists(st.floats(allow_nan=False), max_size=3), st.just({}), st.just([]),
    st.dictionaries(st.sampled_from(["model", "mean", "ratio", "x"]), st.floats(allow_nan=False), max_size=2),
)


@st.composite
def mutated(draw):
    name = draw(st.sampled_from(sorted(DOCUMENTS)))
    document = copy.deepcopy(DOCUMENTS[name])
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(list(paths(document))))
        parent = document
        for key in path[:-1]:
            parent = parent[key]
        action = draw(st.sampled_from(["nudge", "nudge", "replace", "replace", "delete", "add"]))
        value = parent[path[-1]]
        if action == "nudge" and isinstance(value, float):  # a plausible change: what a user tries first
            parent[path[-1]] = value * draw(st.floats(0.5, 2.0))
        elif action in ("replace", "nudge"):
            parent[path[-1]] = draw(VALUES)
        elif action == "delete" and isinstance(parent, dict):
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[draw(st.sampled_from(["extra", "mass", "teeth_", "stiffness"]))] = draw(VALUES)
    return name, tomli_w.dumps(document)


@settings(max_examples=400, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated())
def load_or_refuse(case):
    name, text = case
    try:
        load_text(text, f"fuzzed:{name}")
        OUTCOMES["loaded"] += 1
    except GearcheckError as exc:
        assert "\n" not in str(exc)
        OUTCOMES["refused"] += 1


def test_a_mutated_preset_loads_or_is_refused_with_gearchecks_own_error():
    """Any other exception fails the test (hypothesis shows the file); the mutations reach both outcomes."""
    OUTCOMES.update(loaded=0, refused=0)
    load_or_refuse()
    print(f"fuzz outcomes: {OUTCOMES}")
    assert OUTCOMES["loaded"] >= 10 and OUTCOMES["refused"] >= 100
