"""Objective and constraint expressions typed as text (``"U1^2 + U2^2"``, ``"motor1.i"``),
turned into CasADi SX in the compiled model's ``(t, x, z, p)``.

Names are the model's variables (aliases and ``der(x)`` included), parameters, inputs and
``time``; operators ``+ - * / ^ **``; functions ``sin cos tan exp log sqrt abs tanh atan2
min max``. The text is parsed by Python's ``ast`` and walked node by node: nothing is
evaluated as Python.
"""

from __future__ import annotations

import ast
from collections.abc import Callable

import casadi as ca

from ..errors import ParameterError

_FUNCTIONS: dict[str, Callable[..., ca.SX]] = {
    "sin": ca.sin, "cos": ca.cos, "tan": ca.tan, "exp": ca.exp, "log": ca.log,
    "sqrt": ca.sqrt, "abs": ca.fabs, "tanh": ca.tanh, "atan2": ca.atan2,
    "min": ca.fmin, "max": ca.fmax,
}
_BINARY = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
           ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
           ast.Pow: lambda a, b: a ** b}


def parse_expression(text: str, lookup: Callable[[str], ca.SX], option: str) -> ca.SX:
    """The SX of ``text``; ``lookup(name)`` gives the SX of a dotted name (raising
    :class:`ParameterError` for an unknown one). ``option`` names the expression in errors."""
    source = text.strip().replace("^", "**")
    if not source:
        raise ParameterError(f"{option}: empty expression")
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError:
        raise ParameterError(f"{option}: cannot read expression {text!r}") from None
    return _walk(tree.body, lookup, option, text)


def _name(node: ast.AST) -> str | None:
    """The dotted name (``a.b[2].c``) a node spells, or None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        base = _name(node.value)
        return None if base is None else f"{base}.{node.attr}"
    if isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant):
        base = _name(node.value)
        return None if base is None else f"{base}[{node.slice.value}]"
    return None


def _walk(node: ast.AST, lookup: Callable[[str], ca.SX], option: str, text: str) -> ca.SX:
    def walk(n: ast.AST) -> ca.SX:
        return _walk(n, lookup, option, text)

    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) \
            and not isinstance(node.value, bool):
        return ca.SX(float(node.value))
    name = _name(node)
    if name is not None:
        return lookup(name)
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return _BINARY[type(node.op)](walk(node.left), walk(node.right))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = walk(node.operand)
        return -inner if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
        fname = node.func.id
        if fname == "der" and len(node.args) == 1 and _name(node.args[0]) is not None:
            return lookup(f"der({_name(node.args[0])})")
        if fname in _FUNCTIONS:
            return _FUNCTIONS[fname](*[walk(a) for a in node.args])
        raise ParameterError(f"{option}: unknown function {fname!r} in {text!r} (known: "
                             f"{', '.join(sorted(_FUNCTIONS))}, der)")
    raise ParameterError(f"{option}: cannot use {ast.unparse(node)!r} in {text!r}")


def split_items(text: str) -> list[str]:
    """``"a=1,b=f(x,y)"`` -> ``["a=1", "b=f(x,y)"]``: commas outside parentheses separate."""
    items, depth, cur = [], 0, []
    for ch in text:
        depth += ch == "("
        depth -= ch == ")"
        if ch == "," and depth == 0:
            items.append("".join(cur).strip())
            cur = []
        else:
            cur.append(ch)
    items.append("".join(cur).strip())
    return [s for s in items if s]
