"""The check of a selection argument (``plot(signals=...)``, ``plot(types=...)``): each value one of the known ones,
else a GearcheckError that names the parameter, the value and the nearest known one."""

from __future__ import annotations

from gearcheck.shared.errors import GearcheckError, did_you_mean


def chosen(parameter: str, values, known, what: str) -> list:
    """``values`` (one or several) as a list, each one of ``known``; else a GearcheckError naming ``parameter``,
    the value and what it should be (``what``), with the nearest known one."""
    known = list(known)
    values = [values] if isinstance(values, (str, int)) else list(values)
    for value in values:
        if value not in known:
            hint = did_you_mean(str(value), map(str, known)) or f" (choose from {', '.join(map(str, known[:8]))})"
            raise GearcheckError(f"{parameter}: {value!r} is not {what}{hint}")
    return values
