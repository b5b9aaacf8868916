"""The Modelica parser's rules for equations and expressions: lark callbacks that build the
syntax tree of :mod:`.ast` while parsing (see :mod:`.parser`), and the helpers shared with its
class and element rules.

The callbacks receive a rule's children only (no lark metadata): a node's position is that of
its first child with one, so keywords that begin a construct (``if``, ``for``, ``{``...) are
named terminals in the grammar and kept as children.
"""

from __future__ import annotations

from typing import Any

from lark import Token, Transformer

from . import ast as A
from .errors import ModelicaSyntaxError


def first_pos(ch: Any) -> A.Pos:
    """``(line, column)`` of the first of the children ``ch`` that has a position (a token,
    a node, a name, or a list/tuple holding one); ``(0, 0)`` when none has."""
    for c in ch:
        if isinstance(c, Token):
            return (c.line, c.column)
        p = getattr(c, "pos", None)
        if p is not None:
            return p
        if isinstance(c, (list, tuple)) and not isinstance(c, str):
            p = first_pos(c)
            if p != (0, 0):
                return p
    return (0, 0)


def token_pos(tok: Token) -> A.Pos:
    """``(line, column)`` of a token."""
    return (tok.line or 0, tok.column or 0)


def ident_text(tok: Token | str) -> str:
    """The name an identifier token stands for (a quoted identifier unquoted)."""
    s = str(tok)
    if s.startswith("'"):
        return unescape(s[1:-1])
    return s


def unescape(s: str) -> str:
    """A string literal's text with its escape sequences resolved."""
    if "\\" not in s:
        return s
    out = []
    i = 0
    while i < len(s):
        c = s[i]
        if c == "\\" and i + 1 < len(s):
            n = s[i + 1]
            out.append({"n": "\n", "t": "\t", "r": "\r", "\\": "\\", '"': '"', "'": "'",
                        "a": "\a", "b": "\b", "f": "\f", "v": "\v", "?": "?"}.get(n, n))
            i += 2
            continue
        out.append(c)
        i += 1
    return "".join(out)


class _Named(tuple):
    """``name = expression`` inside a function call."""


class _Comprehension(tuple):
    """``expression for indices``."""


class ExpressionRules(Transformer):
    """Equations (simple, if, for, when), expressions, calls, arrays and comments. ``file``
    (set by the subclass) names the source in syntax errors."""

    file: str

    def _syntax_error(self, pos: A.Pos, message: str) -> ModelicaSyntaxError:
        """A syntax error at ``pos`` of this file."""
        return ModelicaSyntaxError(self.file, pos[0], pos[1], message)

    # -- equations ---------------------------------------------------------------------------
    def equation(self, ch):
        return ch[0]

    def simple_equation(self, ch):
        if len(ch) == 2:
            return A.EqSimple(ch[0], ch[1], first_pos(ch))
        if isinstance(ch[0], A.Call):
            return A.EqCall(ch[0], first_pos(ch))
        raise self._syntax_error(first_pos(ch), "an equation must be 'expression = expression' "
                                 "or a call such as connect(a, b)")

    def if_equation(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        cond = ch[0]
        body = []
        branches = []
        otherwise: tuple = ()
        for c in ch[1:]:
            if isinstance(c, tuple) and c and c[0] == "__elseif__":
                branches.append((c[1], c[2]))
            elif isinstance(c, tuple) and c and c[0] == "__else__":
                otherwise = c[1]
            else:
                body.append(c)
        return A.EqIf(((cond, tuple(body)), *branches), otherwise, pos)

    def elseif_equation(self, ch):
        return ("__elseif__", ch[0], tuple(ch[1:]))

    def else_equation(self, ch):
        return ("__else__", tuple(ch))

    def for_equation(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        return A.EqFor(ch[0], tuple(ch[1:]), pos)

    def when_equation(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        cond = ch[0]
        body = []
        branches = []
        for c in ch[1:]:
            if isinstance(c, tuple) and c and c[0] == "__elsewhen__":
                branches.append((c[1], c[2]))
            else:
                body.append(c)
        return A.EqWhen(((cond, tuple(body)), *branches), pos)

    def elsewhen_equation(self, ch):
        return ("__elsewhen__", ch[0], tuple(ch[1:]))

    def for_indices(self, ch):
        return tuple(ch)

    def for_index(self, ch):
        return (ident_text(ch[0]), ch[1] if len(ch) > 1 else None)

    # -- expressions -------------------------------------------------------------------------
    def if_expression(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        branches = [(ch[0], ch[1])]
        for c in ch[2:-1]:
            branches.append(c)
        return A.IfExpr(tuple(branches), ch[-1], pos)

    def elseif_expression(self, ch):
        return (ch[0], ch[1])

    def range(self, ch):
        items = [c for c in ch if not (isinstance(c, Token) and c.type == "COLON")]
        if len(items) == 2:
            return A.Range(items[0], None, items[1], first_pos(ch))
        return A.Range(items[0], items[1], items[2], first_pos(ch))

    def or_expr(self, ch):
        return A.BinOp("or", ch[0], ch[1], first_pos(ch))

    def and_expr(self, ch):
        return A.BinOp("and", ch[0], ch[1], first_pos(ch))

    def not_expr(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        return A.Unary("not", ch[0], pos)

    def relation(self, ch):
        return A.BinOp(str(ch[1]), ch[0], ch[2], first_pos(ch))

    def unary(self, ch):
        return A.Unary(str(ch[0]).lstrip("."), ch[1], first_pos(ch))

    def binary(self, ch):
        return A.BinOp(str(ch[1]), ch[0], ch[2], first_pos(ch))

    def number(self, ch):
        text = str(ch[0])
        if any(c in text for c in ".eE"):
            return A.Num(float(text), token_pos(ch[0]))
        return A.Num(int(text), token_pos(ch[0]))

    def string(self, ch):
        return A.Str(unescape(str(ch[0])[1:-1]), token_pos(ch[0]))

    def true(self, ch):
        return A.Bool(True, first_pos(ch))

    def false(self, ch):
        return A.Bool(False, first_pos(ch))

    def component_reference(self, ch):
        parts: list = []
        for c in ch:
            if isinstance(c, Token):
                if c.type == "IDENT":
                    parts.append((ident_text(c), None))
            else:                               # the subscripts of the part before
                parts[-1] = (parts[-1][0], tuple(c))
        return A.Ref(tuple(parts), token_pos(ch[0]), ch[0].type == "DOT")

    def call(self, ch):
        ref, (args, kwargs, iterator) = ch
        return A.Call(ref, args, kwargs, first_pos(ch), iterator)

    def function_call_args(self, ch):
        if not ch:
            return ((), {}, None)
        c = ch[0]
        if isinstance(c, _Comprehension):
            return ((), {}, (c[0], c[1]))
        args, kwargs = [], {}
        for a in c:
            if isinstance(a, _Named):
                kwargs[a[0]] = a[1]
            else:
                args.append(a)
        return (tuple(args), kwargs, None)

    def function_arguments(self, ch):
        return list(ch)

    def comprehension_arguments(self, ch):
        return _Comprehension((ch[0], ch[1]))

    def named_argument(self, ch):
        return _Named((ident_text(ch[0]), ch[1]))

    def function_partial_application(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        kwargs = ch[1] if len(ch) > 1 else {}
        return A.PartialFunction(ch[0], kwargs, pos)

    def named_argument_list(self, ch):
        return {ident_text(ch[i]): ch[i + 1] for i in range(0, len(ch), 2)}

    def paren(self, ch):
        return ch[0]

    def output_expression_list(self, ch):
        """``(e)`` is ``e``; ``(a, , b)`` a :class:`TupleExpr` (None for an omitted item)."""
        items: list = [None]
        commas = 0
        for c in ch:
            if isinstance(c, Token) and c.type == "COMMA":
                items.append(None)
                commas += 1
            else:
                items[-1] = c
        if commas == 0 and items[0] is not None:
            return items[0]
        if commas == 0:
            items = []
        return A.TupleExpr(tuple(items), first_pos(ch))

    def array(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        c = ch[0]
        if isinstance(c, _Comprehension):
            return A.ArrayComp(c[0], c[1], pos)
        return A.ArrayLit(tuple(c), pos)

    def array_arguments(self, ch):
        return list(ch)

    def matrix(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        return A.Matrix(tuple(tuple(r) for r in ch), pos)

    def expression_list(self, ch):
        return list(ch)

    def array_subscripts(self, ch):
        return list(ch)

    def colon_subscript(self, ch):
        return A.Colon(first_pos(ch))

    def comment(self, ch):
        desc = ch[0] if ch and isinstance(ch[0], str) else ""
        ann = next((c for c in ch if isinstance(c, A.Modification)), None)
        return (desc, ann)

    def string_comment(self, ch):
        return "".join(unescape(str(t)[1:-1]) for t in ch if t.type == "STRING")

    def annotation(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        return A.Modification(tuple(ch[0]), None, pos)
