# SPDX-License-Identifier: MIT
"""Rewards written in the world file: ``{"learn": {"reward": "distance / stroke - touch"}}``.

A reward expression is arithmetic over per-turtle figures of the last control step, evaluated by
numpy over all copies and turtles at once (docs/python.md, "Rewards from the world file"). It is
parsed with Python's own parser and checked against a short grammar: numbers, the names in
``NAMES``, ``pi``, ``+ - * / ** %``, comparisons (1 when true, 0 when false), ``and``, ``or``,
``not``, ``a if c else b`` and the functions in ``FUNCTIONS``. Nothing else is evaluated: no
attribute, subscript, lambda or call of anything outside that table, so a world file from
elsewhere cannot run code.
"""
import ast

import numpy as np

# name: what it is, per turtle, in the last control step (all float; shape (copies, turtles)).
NAMES = {
    "distance": "distance driven (units; negative backwards; cut short at a contact)",
    "turned": "angle turned (radians, clockwise positive)",
    "touch": "1 if a touch sensor fired, else 0",
    "touches": "how many of the turtle's touch arcs fired",
    "near": "1 minus the shortest range reading over the turtle's rays (0: nothing within range; 0 without rays)",
    "range_min": "the shortest range reading, as a fraction of its sensor's range (1: nothing within range)",
    "v": "the action's linear part in [-1, 1] (velocity: v; wheels: (l + r) / 2; logo: 1 forward, -1 back)",
    "omega": "the action's turning part in [-1, 1] (velocity: omega; wheels: (l - r) / 2; logo: 1 right, -1 left)",
    "stroke": "the longest stroke of one control step (units): speed * dt / 2, or speed * dt for logo actions",
    "speed": "the turtle's top speed (units/s)",
    "x": "the turtle's x (world units; ground truth)",
    "y": "the turtle's y (world units; ground truth)",
    "heading": "the turtle's heading (degrees, Logo: 0 is +y, clockwise)",
    "contacts": "contacts in the turtle's copy during the step",
    "t": "the copy's time (seconds)",
    "steps": "control steps the copy has taken",
}
CONSTANTS = {"pi": np.pi}
# name: (function, number of arguments)
FUNCTIONS = {
    "abs": (np.abs, 1), "sqrt": (np.sqrt, 1), "exp": (np.exp, 1), "log": (np.log, 1),
    "sin": (np.sin, 1), "cos": (np.cos, 1), "tanh": (np.tanh, 1),
    "min": (np.minimum, 2), "max": (np.maximum, 2), "hypot": (np.hypot, 2),
    "clip": (np.clip, 3), "where": (lambda c, a, b: np.where(c != 0, a, b), 3),
}
_BINARY = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide,
           ast.Pow: np.power, ast.Mod: np.mod}
_COMPARE = {ast.Lt: np.less, ast.LtE: np.less_equal, ast.Gt: np.greater, ast.GtE: np.greater_equal,
            ast.Eq: np.equal, ast.NotEq: np.not_equal}
_SYMBOL = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**", ast.Mod: "%"}


class RewardExpression:
    """A checked reward expression; ``where`` names it in errors (a JSON path or "reward=")."""

    def __init__(self, text, where="/learn/reward"):
        if not isinstance(text, str) or not text.strip():
            raise ValueError(f"{where}: a reward expression, e.g. \"distance / stroke - touch\", not {text!r}")
        self.text = text
        self.where = where
        try:
            self._tree = ast.parse(text.strip(), mode="eval").body
        except SyntaxError as e:
            col = f" at column {e.offset}" if e.offset else ""
            raise ValueError(f"{where}: {text!r} is not an expression{col}: {e.msg}") from None
        self.names = set()
        self._check(self._tree)

    def _fail(self, node, what):
        raise ValueError(f"{self.where}: {self.text!r}, column {getattr(node, 'col_offset', 0) + 1}: {what}")

    def _check(self, node):
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                self._fail(node, f"{node.value!r} is not a number")
        elif isinstance(node, ast.Name):
            if node.id in NAMES:
                self.names.add(node.id)
            elif node.id not in CONSTANTS:
                what = " (a function: call it)" if node.id in FUNCTIONS else ""
                self._fail(node, f"unknown name {node.id!r}{what}; the names are {', '.join(sorted(NAMES))} and pi")
        elif isinstance(node, ast.BinOp):
            if type(node.op) not in _BINARY:
                self._fail(node, "only + - * / ** % between numbers")
            self._check(node.left)
            self._check(node.right)
        elif isinstance(node, ast.UnaryOp):
            if not isinstance(node.op, (ast.USub, ast.UAdd, ast.Not)):
                self._fail(node, "only -x, +x and not x")
            self._check(node.operand)
        elif isinstance(node, ast.Compare):
            if not all(type(op) in _COMPARE for op in node.ops):
                self._fail(node, "only < <= > >= == != compare")
            for n in [node.left, *node.comparators]:
                self._check(n)
        elif isinstance(node, ast.BoolOp):
            for n in node.values:
                self._check(n)
        elif isinstance(node, ast.IfExp):
            for n in (node.test, node.body, node.orelse):
                self._check(n)
        elif isinstance(node, ast.Call):
            name = node.func.id if isinstance(node.func, ast.Name) else None
            if name not in FUNCTIONS:
                self._fail(node, f"only the functions {', '.join(sorted(FUNCTIONS))} can be called")
            if node.keywords or len(node.args) != FUNCTIONS[name][1]:
                self._fail(node, f"{name} takes {FUNCTIONS[name][1]} argument(s), by position")
            for n in node.args:
                self._check(n)
        else:
            self._fail(node, f"{type(node).__name__.lower()} is not part of a reward expression "
                             "(numbers, names, arithmetic, comparisons, and/or/not, x if c else y, functions)")

    def _eval(self, node, env):
        if isinstance(node, ast.Constant):
            return np.float64(node.value)
        if isinstance(node, ast.Name):
            return env[node.id] if node.id in NAMES else np.float64(CONSTANTS[node.id])
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](self._eval(node.left, env), self._eval(node.right, env))
        if isinstance(node, ast.UnaryOp):
            x = self._eval(node.operand, env)
            if isinstance(node.op, ast.Not):
                return (x == 0).astype(np.float64)
            return -x if isinstance(node.op, ast.USub) else x
        if isinstance(node, ast.Compare):
            left, out = self._eval(node.left, env), None
            for op, n in zip(node.ops, node.comparators):
                right = self._eval(n, env)
                r = _COMPARE[type(op)](left, right)
                out = r if out is None else np.logical_and(out, r)
                left = right
            return out.astype(np.float64)
        if isinstance(node, ast.BoolOp):
            values = [self._eval(n, env) != 0 for n in node.values]
            join = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
            out = values[0]
            for v in values[1:]:
                out = join(out, v)
            return out.astype(np.float64)
        if isinstance(node, ast.IfExp):
            return np.where(self._eval(node.test, env) != 0, self._eval(node.body, env), self._eval(node.orelse, env))
        fn = FUNCTIONS[node.func.id][0]
        return fn(*[self._eval(n, env) for n in node.args])

    def evaluate(self, env, shape, alive=None):
        """The reward, float32 of `shape`, from `env` (name -> array broadcastable to shape).

        alive: bool array of `shape`, False for turtles gone from their copy (their reward is 0).
        A value that is not finite where a turtle is alive is an error naming the copy, turtle and
        figures, not a NaN handed to the learner.
        """
        with np.errstate(all="ignore"):
            r = np.broadcast_to(np.asarray(self._eval(self._tree, env), dtype=np.float64), shape)
        if alive is not None:
            r = np.where(alive, r, 0.0)
        bad = ~np.isfinite(r)
        if bad.any():
            i, k = (int(v) for v in np.argwhere(bad)[0])
            figures = ", ".join(f"{n}={np.broadcast_to(env[n], shape)[i, k]:.6g}" for n in sorted(self.names))
            raise FloatingPointError(f"{self.where}: {self.text!r} is {r[i, k]} for copy {i}, turtle {k}"
                                     + (f" ({figures})" if figures else ""))
        return r.astype(np.float32)

    def __repr__(self):
        return f"RewardExpression({self.text!r})"
