"""Parse Modelica text (``grammar.lark``: the specification's concrete syntax) into the
syntax tree of :mod:`.ast`.

The grammar is compiled once per process by lark's LALR(1) parser generator, with the rules
applied while parsing (no intermediate parse tree). Syntax errors become
:class:`ModelicaSyntaxError` with ``file:line:column`` and what was expected. The rules for
classes and elements are here, those for statements in :mod:`.statement_rules`, for equations
and expressions in :mod:`.expression_rules`. :func:`parse_file` caches parsed files in the
process and on disk (:mod:`.ast_cache`).
"""

from __future__ import annotations

import os
import threading
import time
from functools import lru_cache
from pathlib import Path
from typing import Any

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput

from . import ast as A
from . import ast_cache
from .errors import ModelicaError, ModelicaSyntaxError
from .expression_rules import first_pos, ident_text, token_pos
from .parse_values import ClassMod as _ClassMod
from .parse_values import Name as _Name
from .parse_values import Prefixes as _Prefixes
from .parse_values import Section as _Section
from .statement_rules import StatementRules

_GRAMMAR = Path(__file__).with_name("grammar.lark")

#: words that start a construct the grammar does not read, with what they start
UNSUPPORTED_WORDS = {
    "Clock": "synchronous (clocked) language elements",
    "subSample": "synchronous (clocked) language elements",
}


_PURITY = {"PURE": "pure", "IMPURE": "impure"}


class _ToAst(StatementRules):
    """The rules for classes and elements; ``file`` names the text being parsed and
    ``classes`` collects every class definition made."""

    def __init__(self) -> None:
        super().__init__()
        self.file = "<string>"
        self.classes: list[A.ClassDef] = []

    # -- stored definition -------------------------------------------------------------------
    def start(self, ch):
        within = None
        classes = []
        for c in ch:
            if isinstance(c, A.ClassDef):
                classes.append(c)
            elif isinstance(c, str) and not isinstance(c, Token):
                within = c
        return A.StoredDefinition(self.file, within, classes)

    def within_clause(self, ch):
        return ch[0] if ch else ""      # a _Name: its position names the clause in messages

    def name(self, ch):
        out = _Name(".".join(ident_text(t) for t in ch))
        out.pos = token_pos(ch[0])
        return out

    def type_specifier(self, ch):
        return str(ch[-1])

    # -- classes -----------------------------------------------------------------------------
    def class_prefixes(self, ch):
        partial = bool(ch) and ch[0].type == "PARTIAL"
        purity = next((_PURITY[t.type] for t in ch if t.type in _PURITY), "")
        kind = " ".join(str(t) for t in ch if t.type != "PARTIAL" and t.type not in _PURITY)
        out = _Prefixes((partial, purity, kind))
        out.pos = token_pos(ch[0])
        return out

    def class_definition(self, ch):
        cdef: A.ClassDef = ch[-1]
        cdef.partial, cdef.purity, cdef.kind = ch[-2]
        cdef.encapsulated = isinstance(ch[0], Token) and ch[0].type == "ENCAPSULATED"
        cdef.pos = first_pos(ch)
        cdef.file = self.file
        self.classes.append(cdef)
        return cdef

    short_class_definition = class_definition

    def long_class_specifier(self, ch):
        name, desc, comp, end = ident_text(ch[0]), ch[1], ch[2], ident_text(ch[3])
        if name != end:
            raise ModelicaSyntaxError(self.file, ch[3].line, ch[3].column,
                                      f"class {name} is closed by 'end {end}' (expected "
                                      f"'end {name}')")
        cdef = A.ClassDef(name, "", token_pos(ch[0]), description=desc, file=self.file, **comp)
        for el in cdef.elements:
            if isinstance(el, A.ClassDef):
                el.parent = cdef
        return cdef

    def extends_class_specifier(self, ch):
        pos, ch = token_pos(ch[0]), ch[1:]
        mod = A.Modification((), None, pos)
        if isinstance(ch[1], _ClassMod):
            mod = A.Modification(tuple(ch[1]), None, pos)
            ch = [ch[0], *ch[2:]]
        cdef = self.long_class_specifier(ch)
        cdef.class_extends = mod
        return cdef

    def short_class_specifier(self, ch):
        name = ident_text(ch[0])
        prefix = ch[1]
        type_name = ch[2]
        dims: tuple = ()
        mod = None
        desc, ann = "", None
        for c in ch[3:]:
            if isinstance(c, list):
                dims = tuple(c)
            elif isinstance(c, _ClassMod):
                mod = A.Modification(tuple(c), None, token_pos(ch[0]))
            elif isinstance(c, tuple) and len(c) == 2:
                desc, ann = c
        return A.ClassDef(name, "", token_pos(ch[0]), description=desc, annotation=ann,
                          short=(prefix, type_name, dims, mod), file=self.file)

    def enum_class_specifier(self, ch):
        name = ident_text(ch[0])
        literals: tuple = ()
        desc = ""
        for c in ch[1:]:
            if isinstance(c, list):
                literals = tuple(c)
            elif isinstance(c, tuple) and len(c) == 2:
                desc = c[0]
        return A.ClassDef(name, "type", token_pos(ch[0]), description=desc, enum=literals,
                          file=self.file)

    def base_prefix(self, ch):
        return str(ch[0]) if ch else ""

    def enum_list(self, ch):
        return list(ch)

    def enumeration_literal(self, ch):
        return ident_text(ch[0])

    def composition(self, ch):
        out: dict[str, Any] = {"elements": [], "equations": [], "initial_equations": [],
                               "algorithms": [], "initial_algorithms": [], "annotation": None,
                               "external": None}
        out["elements"].extend(ch[0])
        protected: set[str] = set()
        for c in ch[1:]:
            if isinstance(c, _Section):
                kind, items = c
                if kind == "protected":
                    protected.update(e.name for e in items
                                     if isinstance(e, (A.Component, A.ClassDef)))
                    kind = "elements"
                if kind in ("algorithms", "initial_algorithms"):
                    out[kind].append(items)
                else:
                    out[kind].extend(items)
            elif isinstance(c, A.External):
                out["external"] = c
            elif isinstance(c, A.Modification):
                out["annotation"] = c
        out["protected"] = frozenset(protected)
        return out

    def public_section(self, ch):
        return _Section(("elements", ch[0]))

    def protected_section(self, ch):
        return _Section(("protected", ch[0]))

    def equation_section(self, ch):
        return _Section(("equations", list(ch)))

    def initial_equation_section(self, ch):
        return _Section(("initial_equations", list(ch[1:])))

    def algorithm_section(self, ch):
        return _Section(("algorithms", A.Statements(ch[1:], token_pos(ch[0]))))

    def initial_algorithm_section(self, ch):
        return _Section(("initial_algorithms", A.Statements(ch[1:], token_pos(ch[0]))))

    def element_list(self, ch):
        out = []
        for c in ch:
            if isinstance(c, list):
                out.extend(c)
            else:
                out.append(c)
        return out

    def element_prefix(self, ch):
        return str(ch[0])

    def declaration_element(self, ch):
        prefixes = frozenset(c for c in ch if isinstance(c, str) and not isinstance(c, Token)
                             and c in ("redeclare", "final", "inner", "outer", "replaceable"))
        k = next(i for i, c in enumerate(ch) if isinstance(c, (A.ClassDef, list)))
        body = ch[k]
        _constrain(body, ch[k + 1:])
        if isinstance(body, A.ClassDef):
            body.element_prefixes = prefixes
            return body
        for comp in body:
            comp.element_prefixes = prefixes
        return body

    def constraining_clause(self, ch):
        return ("constrainedby", ch[0], ch[1] if len(ch) > 1 else None)

    def import_alias(self, ch):
        return A.Import(ident_text(ch[1]), str(ch[2]), False, token_pos(ch[0]))

    def import_all(self, ch):
        return A.Import(None, str(ch[1]), True, token_pos(ch[0]))

    def import_name(self, ch):
        return A.Import(None, str(ch[1]), False, token_pos(ch[0]))

    def import_some(self, ch):
        """``import A.B.{c, d}``: one import a name."""
        return [A.Import(None, f"{ch[1]}.{name}", False, token_pos(ch[0])) for name in ch[3]]

    def import_list(self, ch):
        return [ident_text(t) for t in ch]

    def extends_clause(self, ch):
        mod = None
        for c in ch[2:]:
            if isinstance(c, _ClassMod):
                mod = A.Modification(tuple(c), None, token_pos(ch[0]))
        return A.Extends(ch[1], mod, token_pos(ch[0]))

    def type_prefix(self, ch):
        return str(ch[0])

    def component_clause(self, ch):
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

    def component_clause1(self, ch):
        comps = self.component_clause([*ch[:-1], _CompList([ch[-1]])])
        return comps[0]

    def component_list(self, ch):
        return _CompList(ch)

    def component_declaration(self, ch):
        name, dims, mod, pos = ch[0]
        cond = None
        desc, ann = "", None
        for c in ch[1:]:
            if isinstance(c, tuple) and len(c) == 2 and c and c[0] == "__cond__":
                cond = c[1]
            elif isinstance(c, tuple) and len(c) == 2:
                desc, ann = c
        return (name, dims, mod, cond, desc, ann, pos)

    def component_declaration1(self, ch):
        return self.component_declaration(ch)

    def condition_attribute(self, ch):
        return ("__cond__", ch[0])

    def declaration(self, ch):
        name = ident_text(ch[0])
        dims: tuple = ()
        mod = None
        for c in ch[1:]:
            if isinstance(c, A.Modification):
                mod = c
            elif isinstance(c, list):
                dims = tuple(c)
        return (name, dims, mod, token_pos(ch[0]))

    # -- modifications -----------------------------------------------------------------------
    def modification(self, ch):
        if isinstance(ch[0], Token):                # = expression, := expression
            return A.Modification((), ch[1], token_pos(ch[0]))
        return A.Modification(tuple(ch[0]), ch[1] if len(ch) > 1 else None, ch[0].pos)

    def class_modification(self, ch):
        out = _ClassMod(ch[1:])
        out.pos = token_pos(ch[0])
        return out

    def element_modification_or_replaceable(self, ch):
        target = ch[-1]
        flags = {str(t) for t in ch[:-1]}
        if isinstance(target, A.ElementMod):
            target.each = "each" in flags
            target.final = "final" in flags
            return target
        return A.Redeclare(target, "each" in flags, first_pos(ch))

    def element_modification(self, ch):
        name = ch[0]
        mod = next((c for c in ch[1:] if isinstance(c, A.Modification)), None)
        return A.ElementMod(str(name), mod, pos=name.pos)

    def element_redeclaration(self, ch):
        flags = {str(t) for t in ch[:-1]}
        return A.Redeclare(ch[-1], "each" in flags, first_pos(ch))

    def element_replaceable(self, ch):
        _constrain(ch[1], ch[2:])
        return ch[1]


class _CompList(list):
    """The component list of a component clause."""


def _constrain(body: Any, rest: list) -> None:
    """Apply ``constrainedby T(mod) "description" annotation(...)`` (``rest``: the parsed
    constraining clause and comment, when given) to a component list, a component or a
    class; the description and annotation count when the element has none of its own."""
    if not rest:
        return
    (_, type_name, _mod), (desc, ann) = rest[0], rest[1]
    items = body if isinstance(body, list) else [body]
    for item in items:
        if isinstance(item, A.Component):
            item.constrainedby = type_name
        item.description = item.description or desc
        item.annotation = item.annotation or ann


#: the largest Modelica text read (bytes), about 15 times the largest file of the Modelica
#: Standard Library; a larger file is refused at once rather than parsed for minutes
MAX_TEXT_BYTES = 10 * 2**20


def _check_size(size: int, file: str) -> None:
    if size > MAX_TEXT_BYTES:
        raise ModelicaSyntaxError(file, 1, 1, f"file too large: {size / 2**20:.1f} MB of "
                                  f"Modelica text (the limit is {MAX_TEXT_BYTES // 2**20} MB; "
                                  "split it into packages)")


def parse_text(text: str, file: str = "<string>") -> A.StoredDefinition:
    """Parse Modelica ``text``; ``file`` names it in error messages."""
    _check_size(len(text), file)
    return _parse(text, file)[0]


@lru_cache(maxsize=1)
def _lark() -> tuple[Lark, _ToAst]:
    """The parser, with the rules of :class:`_ToAst` applied while parsing (no parse tree is
    built, and lark's position tracking is not needed: nodes take their first token's)."""
    rules = _ToAst()
    options = dict(parser="lalr", transformer=rules, maybe_placeholders=False)
    # cache=True keeps the generated LALR tables in the temporary directory (keyed by the
    # grammar's hash): building them takes ~0.4 s, loading them ~0.03 s
    try:
        return Lark(_GRAMMAR.read_text(), cache=True, **options), rules
    except OSError:                       # read-only temporary directory
        return Lark(_GRAMMAR.read_text(), **options), rules


_LOCK = threading.Lock()


def _parse(text: str, file: str) -> tuple[A.StoredDefinition, list[A.ClassDef]]:
    """The syntax tree of ``text`` and every class definition in it."""
    lark, rules = _lark()
    with _LOCK, ast_cache.paused_gc():    # the rules hold the file being parsed
        rules.file, rules.classes = file, []
        try:
            return lark.parse(text), rules.classes
        except UnexpectedInput as err:
            raise _syntax_error(err, text, file) from None


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
    if len(value) > 40:                   # a long string: its start is enough
        value = value[:36] + " ..." + value[0]
    return ModelicaSyntaxError(file, line, col, f"unexpected {value!r}"
                               + (f"; expected {shown}{more}" if shown else ""))


_TERMINAL_TEXT = {"SEMICOLON": "';'", "LPAR": "'('", "RPAR": "')'", "COMMA": "','",
                  "EQUAL": "'='", "IDENT": "a name", "NUMBER": "a number", "STRING": "a string",
                  "LSQB": "'['", "RSQB": "']'", "LBRACE": "'{'", "RBRACE": "'}'",
                  "REL_OP": "a relation", "ADD_OP": "'+'/'-'", "MUL_OP": "'*'/'/'",
                  "POW_OP": "'^'", "COLON": "':'", "DOT": "'.'", "$END": "end of file",
                  "ASSIGN": "':='", "DOTSTAR": "'.*'", "DOTBRACE": "'.{'",
                  "INITIAL_EQUATION": "'initial equation'",
                  "INITIAL_ALGORITHM": "'initial algorithm'"}


def _terminal_text(name: str) -> str:
    if name in _TERMINAL_TEXT:
        return _TERMINAL_TEXT[name]
    return repr(name.lower())


_CACHE: dict[str, tuple[tuple, A.StoredDefinition]] = {}


def parse_file(path: str | os.PathLike, disk_cache: bool = True) -> A.StoredDefinition:
    """Parse a ``.mo`` file: cached in this process while the file is unchanged, and on disk
    by content (:mod:`.ast_cache`) unless ``disk_cache`` is false."""
    p = Path(path)
    try:
        st = p.stat()
        _check_size(st.st_size, str(path))
        data = p.read_bytes()
        text = data.decode("utf-8")
    except OSError as err:
        raise ModelicaError(f"cannot read Modelica file {p}: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        col = err.start - data.rfind(b"\n", 0, err.start)
        raise ModelicaSyntaxError(str(path), line, col, f"the file is not UTF-8 text "
                                  f"({err.reason}: byte 0x{data[err.start]:02x})") from None
    key = str(p.resolve())
    stamp = (st.st_mtime_ns, st.st_size, hash(data), str(path))
    hit = _CACHE.get(key)
    if hit is not None and hit[0] == stamp:
        return hit[1]
    started = time.perf_counter()
    tree = ast_cache.load(data, str(path)) if disk_cache else None
    if tree is None:
        if "\r" in text:                  # newlines as read_text would give them
            text = text.replace("\r\n", "\n").replace("\r", "\n")
        tree, classes = _parse(text, str(path))
        if disk_cache:
            ast_cache.store(data, tree, classes)
    _SECONDS[0] += time.perf_counter() - started
    _CACHE[key] = (stamp, tree)
    return tree


_SECONDS = [0.0]


def parse_seconds() -> float:
    """Seconds this process spent parsing files or loading them from the disk cache."""
    return _SECONDS[0]
