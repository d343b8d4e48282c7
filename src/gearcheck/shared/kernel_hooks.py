"""Hooks of a compiled kernel that each kind of part fills with its own compiled function.

A kind of part whose forces move with time hands a numba kernel its data as a named tuple of arrays, its
*group*, and its functions on that group through a :class:`Hook`.  The kernel takes every kind's group in one
tuple and calls ``hook.each(groups, args)`` (``args`` a tuple), which numba, when it compiles the kernel, replaces
by one call of each group's registered function, ``function(group, args)``, in the tuple's order; a group that
registered no function for the hook is skipped.  So the kernel names no kind of part, and a new kind adds its
group and its functions in its own element file.

A hook that ``threads`` a value, ``hook.each(groups, args, value)``, passes it to each function,
``function(group, args, value)``, replaces it by what the function returns (a running index: the next free slot
of an array the groups fill one after the other), and returns it.

The hook is inlined into the kernel, and so is a function registered with ``inline="always"`` (numba then
passes its arrays without reference counting): a hook costs nothing at run time.  Its body for a tuple of groups
is the list of those calls written out (:func:`_flat`): numba compiles an inlined overload on its own as well, and
a recursion on the tuple's tail had it compile every tail, each with its groups' functions inlined again (the
lumped kernel compiled in 55-66 s, 15 s written out, its results the same to the bit).
"""

from __future__ import annotations

from numba.extending import overload


class Hook:
    """One operation of a kernel that each group's kind implements (see the module docstring)."""

    def __init__(self, name: str, threads: bool = False):
        self.name = name
        self.threads = threads
        self.functions: dict[type, object] = {}
        self.each = _each_of(self)

    def register(self, group: type, function) -> None:
        """``function(group, args[, value])`` (numba-compiled) is this hook for the named tuple class ``group``."""
        self.functions[group] = function

    def __repr__(self) -> str:
        return f"Hook({self.name!r}, {sorted(g.__name__ for g in self.functions)})"


def _each_of(hook: Hook):
    """``each(groups, args)``, or ``each(groups, args, value)`` for a hook that threads one: the hook's function
    of every group in ``groups``, in order (the functions registered when numba compiles the caller)."""

    def each(groups, args, value=None):
        raise TypeError(f"{hook.name}: a compiled hook, called only from numba-compiled code")

    each.__name__ = each.__qualname__ = f"each_{hook.name}"

    @overload(each, inline="always")
    def _each(groups, args, value=None):
        functions = [hook.functions.get(group.instance_class) for group in groups]
        return _flat(functions, hook.threads)

    return each


def _flat(functions, threads: bool):
    """``each``'s body for one tuple of groups: a call of each group's function (None: none), in order, written out
    (a recursion on the tuple's tail had numba compile every tail again, the groups' functions inlined in each)."""
    lines, names = ["def each(groups, args, value=None):"], {}
    for i, function in enumerate(functions):
        if function is not None:
            names[f"f{i}"] = function
            lines.append(f"    value = f{i}(groups[{i}], args, value)" if threads else f"    f{i}(groups[{i}], args)")
    lines.append("    return value")
    exec("\n".join(lines), names)  # noqa: S102 -- gearcheck's own registered kernels, no input reaches this text
    return names["each"]
