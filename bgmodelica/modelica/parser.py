"""Parse Modelica text (the subset in ``grammar.lark``) into the syntax tree of :mod:`.ast`.

The grammar is compiled once per process by lark's LALR(1) parser generator. Syntax errors
become :class:`ModelicaSyntaxError` with ``file:line:column`` and what was expected.
"""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path
from typing import Any

from lark import Lark, Token, Transformer, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, VisitError

from . import ast as A
from .errors import ModelicaError, ModelicaSyntaxError

_GRAMMAR = Path(__file__).with_name("grammar.lark")

#: keywords and words of full Modelica that the subset does not read, with what they start
UNSUPPORTED_WORDS = {
    "algorithm": "algorithm sections",
    "while": "while loops (algorithm statements)",
    "external": "external functions",
    "pure": "pure/impure functions",
    "impure": "pure/impure functions",
    "operator": "operator records and overloaded operators",
    "Clock": "synchronous (clocked) language elements",
    "subSample": "synchronous (clocked) language elements",
}


@lru_cache(maxsize=1)
def _lark() -> Lark:
    # cache=True keeps the generated LALR tables in the temporary directory (keyed by the
    # grammar's hash): building them takes ~0.4 s, loading them ~0.03 s
    try:
        return Lark(_GRAMMAR.read_text(), parser="lalr", propagate_positions=True,
                    maybe_placeholders=False, cache=True)
    except OSError:                       # read-only temporary directory
        return Lark(_GRAMMAR.read_text(), parser="lalr", propagate_positions=True,
                    maybe_placeholders=False)


def _pos(meta: Any) -> A.Pos:
    if getattr(meta, "empty", True):
        return (0, 0)
    return (meta.line, meta.column)


def _tpos(tok: Token) -> A.Pos:
    return (tok.line or 0, tok.column or 0)


def _ident(tok: Token | str) -> str:
    s = str(tok)
    if s.startswith("'"):
        return _unescape(s[1:-1])
    return s


def _unescape(s: str) -> str:
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


class _ClassMod(tuple):
    """The argument list of a class modification (distinguished from other tuples)."""


class _Named(tuple):
    """``name = expression`` inside a function call."""


class _Comprehension(tuple):
    """``expression for indices``."""


class _Section(tuple):
    """``(kind, items)`` of a composition."""


@v_args(meta=True)
class _ToAst(Transformer):
    def __init__(self, file: str) -> None:
        super().__init__()
        self.file = file

    # -- stored definition -------------------------------------------------------------------
    def start(self, meta, ch):
        within = None
        classes = []
        for c in ch:
            if isinstance(c, A.ClassDef):
                classes.append(c)
            elif isinstance(c, str) and not isinstance(c, Token):
                within = c
        return A.StoredDefinition(self.file, within, classes)

    def within_clause(self, meta, ch):
        return ch[0] if ch else ""

    def name(self, meta, ch):
        return ".".join(_ident(t) for t in ch)

    def type_specifier(self, meta, ch):
        return ch[-1]

    # -- classes -----------------------------------------------------------------------------
    def class_kind(self, meta, ch):
        return " ".join(str(t) for t in ch)

    def class_definition(self, meta, ch):
        cdef: A.ClassDef = ch[-1]
        kind = ch[-2]
        cdef.kind = kind
        cdef.partial = any(isinstance(t, Token) and t.type == "PARTIAL" for t in ch)
        cdef.pos = _pos(meta)
        cdef.file = self.file
        return cdef

    short_class_definition = class_definition

    def long_class_specifier(self, meta, ch):
        name, desc, comp, end = _ident(ch[0]), ch[1], ch[2], _ident(ch[3])
        if name != end:
            raise ModelicaSyntaxError(self.file, ch[3].line, ch[3].column,
                                      f"class {name} is closed by 'end {end}' (expected "
                                      f"'end {name}')")
        cdef = A.ClassDef(name, "", _pos(meta), description=desc, file=self.file, **comp)
        for el in cdef.elements:
            if isinstance(el, A.ClassDef):
                el.parent = cdef
        return cdef

    def short_class_specifier(self, meta, ch):
        name = _ident(ch[0])
        prefix = ch[1]
        type_name = ch[2]
        dims: tuple = ()
        mod = None
        desc, ann = "", None
        for c in ch[3:]:
            if isinstance(c, list):
                dims = tuple(c)
            elif isinstance(c, _ClassMod):
                mod = A.Modification(tuple(c), None, _pos(meta))
            elif isinstance(c, tuple) and len(c) == 2:
                desc, ann = c
        return A.ClassDef(name, "", _pos(meta), description=desc, annotation=ann,
                          short=(prefix, type_name, dims, mod), file=self.file)

    def enum_class_specifier(self, meta, ch):
        name = _ident(ch[0])
        literals: tuple = ()
        desc = ""
        for c in ch[1:]:
            if isinstance(c, list):
                literals = tuple(c)
            elif isinstance(c, tuple) and len(c) == 2:
                desc = c[0]
        return A.ClassDef(name, "type", _pos(meta), description=desc, enum=literals,
                          file=self.file)

    def base_prefix(self, meta, ch):
        return str(ch[0]) if ch else ""

    def enum_list(self, meta, ch):
        return list(ch)

    def enumeration_literal(self, meta, ch):
        return _ident(ch[0])

    def composition(self, meta, ch):
        out: dict[str, Any] = {"elements": [], "equations": [], "initial_equations": [],
                               "annotation": None, "unsupported": []}
        out["elements"].extend(ch[0])
        for c in ch[1:]:
            if isinstance(c, _Section):
                kind, items = c
                if kind == "elements":
                    out["elements"].extend(items)
                elif kind == "equations":
                    out["equations"].extend(items)
                elif kind == "initial":
                    out["initial_equations"].extend(items)
                else:
                    out["unsupported"].append(items)
            elif isinstance(c, A.Modification):
                out["annotation"] = c
        return out

    def public_section(self, meta, ch):
        return _Section(("elements", ch[0]))

    protected_section = public_section

    def equation_section(self, meta, ch):
        return _Section(("equations", list(ch)))

    def initial_equation_section(self, meta, ch):
        return _Section(("initial", list(ch[1:])))

    def algorithm_section(self, meta, ch):
        return _Section(("unsupported", A.Unsupported("algorithm section", _pos(meta))))

    def initial_algorithm_section(self, meta, ch):
        return _Section(("unsupported", A.Unsupported("initial algorithm section",
                                                      _pos(meta))))

    def external_clause(self, meta, ch):
        return _Section(("unsupported", A.Unsupported("external function", _pos(meta))))

    def element_list(self, meta, ch):
        out = []
        for c in ch:
            if isinstance(c, list):
                out.extend(c)
            else:
                out.append(c)
        return out

    def element_prefix(self, meta, ch):
        return str(ch[0])

    def declaration_element(self, meta, ch):
        prefixes = frozenset(c for c in ch if isinstance(c, str) and not isinstance(c, Token)
                             and c in ("redeclare", "final", "inner", "outer", "replaceable"))
        body = next(c for c in ch if isinstance(c, (A.ClassDef, list)))
        constrained = next((c for c in ch if isinstance(c, tuple) and len(c) == 3
                            and c[0] == "constrainedby"), None)
        if isinstance(body, A.ClassDef):
            body.element_prefixes = prefixes
            return body
        for comp in body:
            comp.element_prefixes = prefixes
            if constrained is not None:
                comp.constrainedby = constrained[1]
        return body

    def constraining_clause(self, meta, ch):
        return ("constrainedby", ch[0], ch[1] if len(ch) > 1 else None)

    def import_alias(self, meta, ch):
        return A.Import(_ident(ch[0]), ch[1], False, _pos(meta))

    def import_all(self, meta, ch):
        return A.Import(None, ch[0], True, _pos(meta))

    def import_name(self, meta, ch):
        return A.Import(None, ch[0], False, _pos(meta))

    def extends_clause(self, meta, ch):
        mod = None
        for c in ch[1:]:
            if isinstance(c, _ClassMod):
                mod = A.Modification(tuple(c), None, _pos(meta))
        return A.Extends(ch[0], mod, _pos(meta))

    def type_prefix(self, meta, ch):
        return str(ch[0])

    def component_clause(self, meta, ch):
        prefixes = []
        k = 0
        while isinstance(ch[k], str) and not isinstance(ch[k], Token) and ch[k] in (
                "flow", "stream", "discrete", "parameter", "constant", "input", "output"):
            prefixes.append(ch[k])
            k += 1
        type_name = ch[k]
        rest = ch[k + 1:]
        type_dims: tuple = ()
        if rest and isinstance(rest[0], list) and not isinstance(rest[0], _CompList):
            type_dims = tuple(rest[0])
            rest = rest[1:]
        comps = []
        for (name, dims, mod, cond, desc, ann, pos) in rest[0]:
            comps.append(A.Component(name, type_name, frozenset(prefixes), type_dims + dims,
                                     mod, cond, desc, ann, pos))
        return comps

    def component_clause1(self, meta, ch):
        comps = self.component_clause(meta, [*ch[:-1], _CompList([ch[-1]])])
        return comps[0]

    def component_list(self, meta, ch):
        return _CompList(ch)

    def component_declaration(self, meta, ch):
        name, dims, mod, pos = ch[0]
        cond = None
        desc, ann = "", None
        for c in ch[1:]:
            if isinstance(c, tuple) and len(c) == 2 and c and c[0] == "__cond__":
                cond = c[1]
            elif isinstance(c, tuple) and len(c) == 2:
                desc, ann = c
        return (name, dims, mod, cond, desc, ann, pos)

    def component_declaration1(self, meta, ch):
        return self.component_declaration(meta, ch)

    def condition_attribute(self, meta, ch):
        return ("__cond__", ch[0])

    def declaration(self, meta, ch):
        name = _ident(ch[0])
        dims: tuple = ()
        mod = None
        for c in ch[1:]:
            if isinstance(c, A.Modification):
                mod = c
            elif isinstance(c, list):
                dims = tuple(c)
        return (name, dims, mod, _tpos(ch[0]))

    # -- modifications -----------------------------------------------------------------------
    def modification(self, meta, ch):
        args: tuple = ()
        binding = None
        for c in ch:
            if isinstance(c, _ClassMod):
                args = tuple(c)
            else:
                binding = c
        return A.Modification(args, binding, _pos(meta))

    def class_modification(self, meta, ch):
        return _ClassMod(ch)

    def element_modification_or_replaceable(self, meta, ch):
        target = ch[-1]
        flags = {str(t) for t in ch[:-1]}
        if isinstance(target, A.ElementMod):
            target.each = "each" in flags
            target.final = "final" in flags
            return target
        return A.Redeclare(target, "each" in flags, _pos(meta))

    def element_modification(self, meta, ch):
        name = ch[0]
        mod = next((c for c in ch[1:] if isinstance(c, A.Modification)), None)
        return A.ElementMod(name, mod, pos=_pos(meta))

    def element_redeclaration(self, meta, ch):
        flags = {str(t) for t in ch[:-1]}
        return A.Redeclare(ch[-1], "each" in flags, _pos(meta))

    def element_replaceable(self, meta, ch):
        return ch[1]

    # -- equations ---------------------------------------------------------------------------
    def equation(self, meta, ch):
        return ch[0]

    def simple_equation(self, meta, ch):
        if len(ch) == 2:
            return A.EqSimple(ch[0], ch[1], _pos(meta))
        if isinstance(ch[0], A.Call):
            return A.EqCall(ch[0], _pos(meta))
        line, col = _pos(meta)
        raise ModelicaSyntaxError(self.file, line, col,
                                  "an equation must be 'expression = expression' or a call "
                                  "such as connect(a, b)")

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
        return A.EqIf(((cond, tuple(body)), *branches), otherwise, _pos(meta))

    def elseif_equation(self, meta, ch):
        return ("__elseif__", ch[0], tuple(ch[1:]))

    def else_equation(self, meta, ch):
        return ("__else__", tuple(ch))

    def for_equation(self, meta, ch):
        return A.EqFor(ch[0], tuple(ch[1:]), _pos(meta))

    def when_equation(self, meta, ch):
        cond = ch[0]
        body = []
        branches = []
        for c in ch[1:]:
            if isinstance(c, tuple) and c and c[0] == "__elsewhen__":
                branches.append((c[1], c[2]))
            else:
                body.append(c)
        return A.EqWhen(((cond, tuple(body)), *branches), _pos(meta))

    def elsewhen_equation(self, meta, ch):
        return ("__elsewhen__", ch[0], tuple(ch[1:]))

    def for_indices(self, meta, ch):
        return tuple(ch)

    def for_index(self, meta, ch):
        return (_ident(ch[0]), ch[1] if len(ch) > 1 else None)

    def statement(self, meta, ch):
        return A.Unsupported("algorithm statement", _pos(meta))

    # -- expressions -------------------------------------------------------------------------
    def if_expression(self, meta, ch):
        branches = [(ch[0], ch[1])]
        for c in ch[2:-1]:
            branches.append(c)
        return A.IfExpr(tuple(branches), ch[-1], _pos(meta))

    def elseif_expression(self, meta, ch):
        return (ch[0], ch[1])

    def range(self, meta, ch):
        items = [c for c in ch if not (isinstance(c, Token) and c.type == "COLON")]
        if len(items) == 2:
            return A.Range(items[0], None, items[1], _pos(meta))
        return A.Range(items[0], items[1], items[2], _pos(meta))

    def or_expr(self, meta, ch):
        return A.BinOp("or", ch[0], ch[1], _pos(meta))

    def and_expr(self, meta, ch):
        return A.BinOp("and", ch[0], ch[1], _pos(meta))

    def not_expr(self, meta, ch):
        return A.Unary("not", ch[0], _pos(meta))

    def relation(self, meta, ch):
        return A.BinOp(str(ch[1]), ch[0], ch[2], _pos(meta))

    def unary(self, meta, ch):
        return A.Unary(str(ch[0]).lstrip("."), ch[1], _pos(meta))

    def binary(self, meta, ch):
        return A.BinOp(str(ch[1]), ch[0], ch[2], _pos(meta))

    def number(self, meta, ch):
        text = str(ch[0])
        if any(c in text for c in ".eE"):
            return A.Num(float(text), _tpos(ch[0]))
        return A.Num(int(text), _tpos(ch[0]))

    def string(self, meta, ch):
        return A.Str(_unescape(str(ch[0])[1:-1]), _tpos(ch[0]))

    def true(self, meta, ch):
        return A.Bool(True, _pos(meta))

    def false(self, meta, ch):
        return A.Bool(False, _pos(meta))

    def component_reference(self, meta, ch):
        glob = bool(ch) and isinstance(ch[0], Token) and ch[0].type == "DOT"
        parts = tuple(c for c in ch if not isinstance(c, Token))
        return A.Ref(parts, _pos(meta), glob)

    def ref_part(self, meta, ch):
        return (_ident(ch[0]), tuple(ch[1]) if len(ch) > 1 else None)

    def call(self, meta, ch):
        ref, (args, kwargs, iterator) = ch
        return A.Call(ref, args, kwargs, _pos(meta), iterator)

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
        return _Named((_ident(ch[0]), ch[1]))

    def function_argument_partial(self, meta, ch):
        line, col = _pos(meta)
        raise ModelicaSyntaxError(self.file, line, col,
                                  "unsupported Modelica construct: functional arguments "
                                  "('function f(...)' in a call)")

    def array(self, meta, ch):
        c = ch[0]
        if isinstance(c, _Comprehension):
            return A.ArrayComp(c[0], c[1], _pos(meta))
        return A.ArrayLit(tuple(c), _pos(meta))

    def array_arguments(self, meta, ch):
        return list(ch)

    def matrix(self, meta, ch):
        return A.Matrix(tuple(tuple(r) for r in ch), _pos(meta))

    def expression_list(self, meta, ch):
        return list(ch)

    def array_subscripts(self, meta, ch):
        return list(ch)

    def colon_subscript(self, meta, ch):
        return A.Colon(_pos(meta))

    def comment(self, meta, ch):
        desc = ch[0] if ch and isinstance(ch[0], str) else ""
        ann = next((c for c in ch if isinstance(c, A.Modification)), None)
        return (desc, ann)

    def string_comment(self, meta, ch):
        return "".join(_unescape(str(t)[1:-1]) for t in ch if t.type == "STRING")

    def annotation(self, meta, ch):
        return A.Modification(tuple(ch[0]), None, _pos(meta))


class _CompList(list):
    """The component list of a component clause."""


def parse_text(text: str, file: str = "<string>") -> A.StoredDefinition:
    """Parse Modelica ``text``; ``file`` names it in error messages."""
    try:
        tree = _lark().parse(text)
    except UnexpectedInput as err:
        raise _syntax_error(err, text, file) from None
    try:
        return _ToAst(file).transform(tree)
    except VisitError as err:
        if isinstance(err.orig_exc, ModelicaError):
            raise err.orig_exc from None
        raise


def _syntax_error(err: UnexpectedInput, text: str, file: str) -> ModelicaSyntaxError:
    line = getattr(err, "line", 0) or 0
    col = getattr(err, "column", 0) or 0
    tok = getattr(err, "token", None)
    if isinstance(err, UnexpectedEOF) or line <= 0 or getattr(tok, "type", "") == "$END":
        lines = text.splitlines() or [""]
        line, col = len(lines), len(lines[-1]) + 1
        return ModelicaSyntaxError(file, line, col, "unexpected end of file (a class or "
                                   "section is not closed: missing 'end NAME;'?)")
    if isinstance(err, UnexpectedCharacters):
        ch = text[err.pos_in_stream] if err.pos_in_stream < len(text) else "?"
        if ch == '"':
            return ModelicaSyntaxError(file, line, col, "unterminated string")
        if ch == "'":
            return ModelicaSyntaxError(file, line, col, "unterminated quoted identifier")
        return ModelicaSyntaxError(file, line, col, f"unexpected character {ch!r}")
    value = str(tok) if tok is not None else "?"
    construct = UNSUPPORTED_WORDS.get(value)
    if construct:
        return ModelicaSyntaxError(file, line, col,
                                   f"unsupported Modelica construct: {construct} "
                                   f"(at {value!r})")
    expected = sorted(getattr(err, "expected", None) or getattr(err, "accepts", None) or [])
    shown = ", ".join(_terminal_text(t) for t in expected[:8])
    more = ", ..." if len(expected) > 8 else ""
    return ModelicaSyntaxError(file, line, col, f"unexpected {value!r}"
                               + (f"; expected {shown}{more}" if shown else ""))


_TERMINAL_TEXT = {"SEMICOLON": "';'", "LPAR": "'('", "RPAR": "')'", "COMMA": "','",
                  "EQUAL": "'='", "IDENT": "a name", "NUMBER": "a number", "STRING": "a string",
                  "LSQB": "'['", "RSQB": "']'", "LBRACE": "'{'", "RBRACE": "'}'",
                  "REL_OP": "a relation", "ADD_OP": "'+'/'-'", "MUL_OP": "'*'/'/'",
                  "POW_OP": "'^'", "COLON": "':'", "DOT": "'.'", "$END": "end of file"}


def _terminal_text(name: str) -> str:
    if name in _TERMINAL_TEXT:
        return _TERMINAL_TEXT[name]
    return repr(name.lower())


_CACHE: dict[str, tuple[tuple, A.StoredDefinition]] = {}


def parse_file(path: str | os.PathLike) -> A.StoredDefinition:
    """Parse a ``.mo`` file (cached while the file is unchanged)."""
    p = Path(path)
    try:
        st = p.stat()
        text = p.read_text(encoding="utf-8")
    except OSError as err:
        raise ModelicaError(f"cannot read Modelica file {p}: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        raise ModelicaError(f"Modelica file {p} is not UTF-8 text ({err.reason} at byte "
                            f"{err.start})") from None
    key = str(p.resolve())
    stamp = (st.st_mtime_ns, st.st_size, hash(text))
    hit = _CACHE.get(key)
    if hit is not None and hit[0] == stamp:
        return hit[1]
    tree = parse_text(text, str(path))
    _CACHE[key] = (stamp, tree)
    return tree
