"""The Modelica parser's rules for equations and expressions: lark callbacks that build the
syntax tree of :mod:`.ast` (see :mod:`.parser`), and the helpers shared with its class and
element rules."""

from __future__ import annotations

from typing import Any

from lark import Token, Transformer, v_args

from . import ast as A
from .errors import ModelicaSyntaxError


def node_pos(meta: Any) -> A.Pos:
    """``(line, column)`` of a parse-tree node, ``(0, 0)`` when it has none."""
    if getattr(meta, "empty", True):
        return (0, 0)
    return (meta.line, meta.column)


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


@v_args(meta=True)
class ExpressionRules(Transformer):
    """Equations (simple, if, for, when), expressions, calls, arrays and comments. ``file``
    (set by the subclass) names the source in syntax errors."""

    file: str

    def _syntax_error(self, meta: Any, message: str) -> ModelicaSyntaxError:
        """A syntax error at the parse-tree node ``meta`` of this file."""
        line, col = node_pos(meta)
        return ModelicaSyntaxError(self.file, line, col, message)

    # -- equations ---------------------------------------------------------------------------
    def equation(self, meta, ch):
        return ch[0]

    def simple_equation(self, meta, ch):
        if len(ch) == 2:
            return A.EqSimple(ch[0], ch[1], node_pos(meta))
        if isinstance(ch[0], A.Call):
            return A.EqCall(ch[0], node_pos(meta))
        raise self._syntax_error(meta, "an equation must be 'expression = expression' or a "
                                      "call such as connect(a, b)")

    def if_equation(self, meta, ch):
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
        return A.EqIf(((cond, tuple(body)), *branches), otherwise, node_pos(meta))

    def elseif_equation(self, meta, ch):
        return ("__elseif__", ch[0], tuple(ch[1:]))

    def else_equation(self, meta, ch):
        return ("__else__", tuple(ch))

    def for_equation(self, meta, ch):
        return A.EqFor(ch[0], tuple(ch[1:]), node_pos(meta))

    def when_equation(self, meta, ch):
        cond = ch[0]
        body = []
        branches = []
        for c in ch[1:]:
            if isinstance(c, tuple) and c and c[0] == "__elsewhen__":
                branches.append((c[1], c[2]))
            else:
                body.append(c)
        return A.EqWhen(((cond, tuple(body)), *branches), node_pos(meta))

    def elsewhen_equation(self, meta, ch):
        return ("__elsewhen__", ch[0], tuple(ch[1:]))

    def for_indices(self, meta, ch):
        return tuple(ch)

    def for_index(self, meta, ch):
        return (ident_text(ch[0]), ch[1] if len(ch) > 1 else None)

    # -- expressions -------------------------------------------------------------------------
    def if_expression(self, meta, ch):
        branches = [(ch[0], ch[1])]
        for c in ch[2:-1]:
            branches.append(c)
        return A.IfExpr(tuple(branches), ch[-1], node_pos(meta))

    def elseif_expression(self, meta, ch):
        return (ch[0], ch[1])

    def range(self, meta, ch):
        items = [c for c in ch if not (isinstance(c, Token) and c.type == "COLON")]
        if len(items) == 2:
            return A.Range(items[0], None, items[1], node_pos(meta))
        return A.Range(items[0], items[1], items[2], node_pos(meta))

    def or_expr(self, meta, ch):
        return A.BinOp("or", ch[0], ch[1], node_pos(meta))

    def and_expr(self, meta, ch):
        return A.BinOp("and", ch[0], ch[1], node_pos(meta))

    def not_expr(self, meta, ch):
        return A.Unary("not", ch[0], node_pos(meta))

    def relation(self, meta, ch):
        return A.BinOp(str(ch[1]), ch[0], ch[2], node_pos(meta))

    def unary(self, meta, ch):
        return A.Unary(str(ch[0]).lstrip("."), ch[1], node_pos(meta))

    def binary(self, meta, ch):
        return A.BinOp(str(ch[1]), ch[0], ch[2], node_pos(meta))

    def number(self, meta, ch):
        text = str(ch[0])
        if any(c in text for c in ".eE"):
            return A.Num(float(text), token_pos(ch[0]))
        return A.Num(int(text), token_pos(ch[0]))

    def string(self, meta, ch):
        return A.Str(unescape(str(ch[0])[1:-1]), token_pos(ch[0]))

    def true(self, meta, ch):
        return A.Bool(True, node_pos(meta))

    def false(self, meta, ch):
        return A.Bool(False, node_pos(meta))

    def component_reference(self, meta, ch):
        glob = bool(ch) and isinstance(ch[0], Token) and ch[0].type == "DOT"
        parts = tuple(c for c in ch if not isinstance(c, Token))
        return A.Ref(parts, node_pos(meta), glob)

    def ref_part(self, meta, ch):
        return (ident_text(ch[0]), tuple(ch[1]) if len(ch) > 1 else None)

    def call(self, meta, ch):
        ref, (args, kwargs, iterator) = ch
        return A.Call(ref, args, kwargs, node_pos(meta), iterator)

    def function_call_args(self, meta, ch):
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

    def function_arguments(self, meta, ch):
        return list(ch)

    def comprehension_arguments(self, meta, ch):
        return _Comprehension((ch[0], ch[1]))

    def named_argument(self, meta, ch):
        return _Named((ident_text(ch[0]), ch[1]))

    def function_partial_application(self, meta, ch):
        kwargs = ch[1] if len(ch) > 1 else {}
        return A.PartialFunction(ch[0], kwargs, node_pos(meta))

    def named_argument_list(self, meta, ch):
        return {ident_text(ch[i]): ch[i + 1] for i in range(0, len(ch), 2)}

    def paren(self, meta, ch):
        return ch[0]

    def output_expression_list(self, meta, ch):
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
        return A.TupleExpr(tuple(items), node_pos(meta))

    def array(self, meta, ch):
        c = ch[0]
        if isinstance(c, _Comprehension):
            return A.ArrayComp(c[0], c[1], node_pos(meta))
        return A.ArrayLit(tuple(c), node_pos(meta))

    def array_arguments(self, meta, ch):
        return list(ch)

    def matrix(self, meta, ch):
        return A.Matrix(tuple(tuple(r) for r in ch), node_pos(meta))

    def expression_list(self, meta, ch):
        return list(ch)

    def array_subscripts(self, meta, ch):
        return list(ch)

    def colon_subscript(self, meta, ch):
        return A.Colon(node_pos(meta))

    def comment(self, meta, ch):
        desc = ch[0] if ch and isinstance(ch[0], str) else ""
        ann = next((c for c in ch if isinstance(c, A.Modification)), None)
        return (desc, ann)

    def string_comment(self, meta, ch):
        return "".join(unescape(str(t)[1:-1]) for t in ch if t.type == "STRING")

    def annotation(self, meta, ch):
        return A.Modification(tuple(ch[0]), None, node_pos(meta))
