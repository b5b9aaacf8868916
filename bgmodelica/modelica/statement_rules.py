"""The Modelica parser's rules for algorithm statements and external clauses (lark callbacks
building :mod:`.ast` nodes; see :mod:`.parser`)."""

from __future__ import annotations

from lark import Token

from . import ast as A
from .expression_rules import ExpressionRules, first_pos, token_pos, unescape


class _Branch(tuple):
    """``(condition, statements)`` of an elseif/elsewhen part."""


class _Else(tuple):
    """The statements of an else part."""


def _statements(ch) -> tuple:
    return tuple(c for c in ch if not isinstance(c, (_Branch, _Else)))


class StatementRules(ExpressionRules):
    """Statements (assignments, calls, if, for, while, when, break, return) and the
    ``external`` clause of a function."""

    def statement(self, ch):
        return ch[0]

    def assign_statement(self, ch):
        return A.Assign(ch[0], ch[1], first_pos(ch))

    def call_statement(self, ch):
        args, kwargs, iterator = ch[1]
        call = A.Call(ch[0], args, kwargs, first_pos(ch), iterator)
        return A.StmtCall(call, first_pos(ch))

    def tuple_assign_statement(self, ch):
        target = ch[0]
        if not isinstance(target, A.TupleExpr):
            target = A.TupleExpr((target,), first_pos(ch))
        args, kwargs, iterator = ch[2]
        call = A.Call(ch[1], args, kwargs, ch[1].pos, iterator)
        return A.Assign(target, call, first_pos(ch))

    def break_statement(self, ch):
        return A.Break(first_pos(ch))

    def return_statement(self, ch):
        return A.Return(first_pos(ch))

    def if_statement(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        branches = [(ch[0], _statements(ch[1:]))]
        branches += [tuple(c) for c in ch if isinstance(c, _Branch)]
        otherwise = next((tuple(c) for c in ch if isinstance(c, _Else)), ())
        return A.StmtIf(tuple(branches), otherwise, pos)

    def elseif_statement(self, ch):
        return _Branch((ch[0], tuple(ch[1:])))

    elsewhen_statement = elseif_statement

    def else_statement(self, ch):
        return _Else(ch)

    def for_statement(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        return A.StmtFor(ch[0], tuple(ch[1:]), pos)

    def while_statement(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        return A.StmtWhile(ch[0], tuple(ch[1:]), pos)

    def when_statement(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        branches = [(ch[0], _statements(ch[1:]))]
        branches += [tuple(c) for c in ch if isinstance(c, _Branch)]
        return A.StmtWhen(tuple(branches), pos)

    # -- external clause ---------------------------------------------------------------------
    def external_clause(self, ch):
        ext = A.External(pos=token_pos(ch[0]))
        for c in ch[1:]:
            if isinstance(c, Token) and c.type == "STRING":
                ext.language = unescape(str(c)[1:-1])
            elif isinstance(c, A.Modification):
                ext.annotation = c
            elif isinstance(c, tuple):
                ext.output, ext.function, ext.args = c
        return ext

    def external_function_call(self, ch):
        output = ch[0] if isinstance(ch[0], A.Ref) else None
        rest = ch[1:] if output is not None else ch
        name = str(rest[0])
        args = tuple(rest[1]) if len(rest) > 1 else ()
        return (output, name, args)
