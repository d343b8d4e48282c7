"""Time functions written in a train file as data: a small, safe grammar of expressions in ``t``.

``operating.torque_expression = "50 * sin(2 * pi * 12.5 * t) * exp(-t / 0.2)"`` is read by Python's own parser
(``ast``, expression mode) and every node is checked against the grammar before anything is evaluated: numbers,
the variable ``t`` (s), the constants ``pi`` and ``e``, ``+ - * / **``, unary ``+ -``, parentheses, comparisons
(``t < 0.1``, true 1 and false 0: steps and windows) and the functions of :data:`FUNCTIONS` (``min``/``max`` of
two).  No names, attributes, subscripts, calls of anything else or literals other than numbers can appear, so an
expression can compute a number and nothing more: unlike ``torque_function`` it needs no ``--trust``.  It is
evaluated by numpy over an array of times; every constant is a float (``10 ** 10 ** 10`` is infinite, not a
billion-digit integer), and a value that is not finite is refused naming the time.
"""

from __future__ import annotations

import ast
import math
import operator
import warnings

import numpy as np

from gearcheck.shared.errors import GearcheckError

MAX_LENGTH = 1000  # characters: a formula, not a program
MAX_DEPTH = 50  # nested operations
FUNCTIONS = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt,
             "abs": np.abs, "tanh": np.tanh, "sign": np.sign, "floor": np.floor, "min": np.minimum,
             "max": np.maximum}
CONSTANTS = {"pi": math.pi, "e": math.e}
OPERATORS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
             ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Lt: operator.lt,
             ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge}
GRAMMAR = ("numbers, t, pi, e, + - * / **, comparisons (< <= > >=), parentheses and "
           + ", ".join(FUNCTIONS))


class Expression:
    """A checked expression of ``t``; calling it evaluates it at an array of times (s).  ``label`` starts every
    error (the train file and field)."""

    def __init__(self, text: str, label: str):
        self.text, self.label = text, label
        if not isinstance(text, str) or not text.strip() or len(text) > MAX_LENGTH:
            raise GearcheckError(f"{label}: an expression of t of 1 to {MAX_LENGTH} characters")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", SyntaxWarning)  # "1and t": dubious syntax is no expression either
                self.tree = ast.parse(text.strip(), mode="eval").body
        except (SyntaxError, SyntaxWarning, ValueError, RecursionError, MemoryError) as exc:
            raise GearcheckError(f"{label}: {text!r} is no expression ({getattr(exc, 'msg', exc)})") from None
        self._check(self.tree, 0)

    def _check(self, node, depth: int) -> None:
        if depth > MAX_DEPTH:
            raise GearcheckError(f"{self.label}: nested deeper than {MAX_DEPTH} operations")
        allowed = (isinstance(node, ast.Constant) and type(node.value) in (int, float)
                   or isinstance(node, ast.Name) and (node.id == "t" or node.id in CONSTANTS)
                   or isinstance(node, ast.BinOp) and type(node.op) in OPERATORS
                   or isinstance(node, ast.UnaryOp) and type(node.op) in OPERATORS
                   or isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in OPERATORS
                   or isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
                   and not node.keywords and len(node.args) == (2 if node.func.id in ("min", "max") else 1))
        if not allowed:
            what = ast.get_source_segment(self.text.strip(), node) or type(node).__name__
            raise GearcheckError(f"{self.label}: {what!r} is not in the grammar of expressions ({GRAMMAR})")
        children = node.args if isinstance(node, ast.Call) else list(ast.iter_child_nodes(node))
        for child in children:
            if not isinstance(child, (ast.operator, ast.unaryop, ast.cmpop, ast.expr_context)):
                self._check(child, depth + 1)

    def __call__(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        with np.errstate(all="ignore"):
            value = np.broadcast_to(np.asarray(self._value(self.tree, t), dtype=float), t.shape)
        bad = ~np.isfinite(value)
        if np.any(bad):
            raise GearcheckError(f"{self.label}: {self.text!r} is not finite at t = {float(t[bad][0]):g} s")
        return np.array(value)

    def _value(self, node, t):
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, ast.Name):
            return t if node.id == "t" else CONSTANTS[node.id]
        if isinstance(node, ast.BinOp):
            return OPERATORS[type(node.op)](np.asarray(self._value(node.left, t)),
                                            np.asarray(self._value(node.right, t)))
        if isinstance(node, ast.UnaryOp):
            return OPERATORS[type(node.op)](np.asarray(self._value(node.operand, t)))
        if isinstance(node, ast.Compare):
            return OPERATORS[type(node.ops[0])](self._value(node.left, t), self._value(node.comparators[0], t)) * 1.0
        return FUNCTIONS[node.func.id](*(self._value(a, t) for a in node.args))
