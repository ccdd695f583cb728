"""YAML for presets, read with limits a hostile file cannot get past.

``yaml.safe_load`` builds no arbitrary objects, but it accepts an alias bomb
(a few lines whose aliases expand to billions of values), nesting deep enough
to exhaust the stack, recursive aliases, and it keeps the last of two equal
keys without a word. Here the document is composed into nodes first, with
its nesting bounded; the nodes are then measured with aliases expanded (in
time proportional to the file, not to the expansion), duplicate keys are
refused, and only then are Python objects built.
"""

from __future__ import annotations

import math
import re
from typing import Any

import yaml

MAX_DEPTH = 64  # presets nest four or five levels
MAX_VALUES = 20_000  # scalars, lists and mappings once aliases are expanded (a preset has ~50)


class YamlProblem(ValueError):
    """A document that is not valid YAML, or breaks a rule of presets
    (duplicate key). The message names a line, never the content."""


class YamlLimit(YamlProblem):
    """A document beyond the limits (nesting, expanded size, recursive aliases)."""


def _line(node_or_mark) -> int:
    mark = getattr(node_or_mark, "start_mark", node_or_mark)
    return mark.line + 1 if mark is not None else 0


class _Unconvertible(ValueError):
    """A scalar YAML parsed but Python cannot hold, with the line it is on."""

    def __init__(self, node, cause: Exception):
        super().__init__(str(cause))
        self.node, self.line, self.cause = node, _line(node), cause


class _BoundedLoader(yaml.SafeLoader):
    """SafeLoader that refuses nesting deeper than MAX_DEPTH while composing
    (the composer recurses once per level), and reads ``1e-6`` and ``1.5e3`` as numbers, as YAML 1.2
    and every other reader do (YAML 1.1 wants ``1.0e-6`` and ``1.5e+3``, and took the others for strings)."""

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0
        self._nodes = 0

    def construct_object(self, node, deep=False):
        try:
            return super().construct_object(node, deep)
        except (ValueError, OverflowError) as exc:  # a date like 2020-13-45, an int past Python's digit limit
            if isinstance(exc, _Unconvertible):
                raise
            raise _Unconvertible(node, exc) from None

    def construct_mapping(self, node, deep=False):
        """A plain key YAML 1.1 reads as a boolean or null (``yes:``, ``on:``, ``null:``) is kept as
        the text written: a preset's keys are names, and True would be said as 1 (and ``yes`` and
        ``on`` would collide without a word)."""
        node.value = [(_as_text(key), value) for key, value in node.value]
        return super().construct_mapping(node, deep)

    def compose_node(self, parent, index):
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise YamlLimit(
                    f"nested more than {MAX_DEPTH} levels deep at line {_line(self.peek_event())}"
                )
            self._nodes += 1  # aliases count too: composing stops early on a long file
            if self._nodes > MAX_VALUES:
                raise YamlLimit(f"more than {MAX_VALUES:,} values (at line {_line(self.peek_event())})")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_WORDS = ("tag:yaml.org,2002:bool", "tag:yaml.org,2002:null")


def _as_text(key):
    if isinstance(key, yaml.ScalarNode) and key.tag in _WORDS and key.style is None:
        return yaml.ScalarNode("tag:yaml.org,2002:str", key.value, key.start_mark, key.end_mark)  # a copy: an alias keeps its own
    return key


# Numbers are read as YAML 1.2 and Python read them, not as YAML 1.1: ``1e-6`` is a float
# (1.1 wants ``1.0e-6``), ``010`` is ten (1.1: octal eight), and ``1:30`` is text (1.1:
# ninety, base 60), which the field's check then names. Underscores between digits are
# kept (``1_000``), as Python allows them.
_INT, _FLOAT = "tag:yaml.org,2002:int", "tag:yaml.org,2002:float"
_DIGITS = r"[0-9](?:_?[0-9])*"
_BoundedLoader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers if tag not in (_INT, _FLOAT)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_BoundedLoader.add_implicit_resolver(
    _INT, re.compile(rf"^(?:[-+]?{_DIGITS}|0o[0-7]+|0x[0-9a-fA-F]+)$"), list("-+0123456789")
)
_BoundedLoader.add_implicit_resolver(
    _FLOAT,
    re.compile(
        rf"^(?:[-+]?(?:{_DIGITS}(?:\.(?:{_DIGITS})?)?|\.{_DIGITS})(?:[eE][-+]?[0-9]+)?"
        r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
    ),
    list("-+.0123456789"),
)


def _integer(loader, node):
    text = loader.construct_scalar(node)
    return int(text, 0) if text[:2] in ("0o", "0x") else int(text, 10)


def past_double_precision(text: str, number: float) -> bool:
    """Whether ``number``, read from ``text``, is a finite nonzero number double precision cannot
    hold: 1e400 read as infinity, 1e-400 as zero."""
    mantissa = text.lower().partition("e")[0]
    return (math.isinf(number) and "inf" not in mantissa) or (number == 0.0 and re.search("[1-9]", mantissa) is not None)


def _finite_or_text(loader, node):
    """A float, or its text when it is past double precision: not read as infinity or zero, so
    the field's check names the number as written."""
    number = loader.construct_yaml_float(node)
    return node.value if past_double_precision(node.value, number) else number


_BoundedLoader.add_constructor(_FLOAT, _finite_or_text)
_BoundedLoader.add_constructor(_INT, _integer)

def _children(node) -> list:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    return []


def _duplicate_key(node: yaml.MappingNode, path: str) -> str | None:
    seen: dict[tuple[str, str], int] = {}
    for key in (_as_text(key) for key, _ in node.value):  # as constructed: ``yes:`` and ``"yes":`` are one key
        if not isinstance(key, yaml.ScalarNode) or key.tag == "tag:yaml.org,2002:merge":
            continue
        ident = (key.tag, key.value)
        if ident in seen:
            where = f"{path}: " if path else ""
            name = key.value if len(key.value) <= 40 else key.value[:37] + "..."
            return f"{where}duplicate key {name!r} at lines {seen[ident]} and {_line(key)}"
        seen[ident] = _line(key)
    return None


def check_nodes(root) -> dict[int, str]:
    """Refuse recursive aliases, more than MAX_VALUES values once aliases are
    expanded, and duplicate keys. Each node is visited once (iterative
    depth-first walk: aliases can chain deeper than the stack). Returns the dotted
    path of each mapping's value, by its node's id."""
    size: dict[int, int] = {}  # expanded size of each finished node
    open_nodes: set[int] = set()  # the nodes on the current path
    paths: dict[int, str] = {id(root): ""}
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, leaving = stack.pop()
        key = id(node)
        if leaving:
            open_nodes.discard(key)
            total = 1 + sum(size[id(child)] for child in _children(node))
            if total > MAX_VALUES:
                raise YamlLimit(
                    f"the value at line {_line(node)} expands to more than {MAX_VALUES:,} values "
                    "(aliases repeat what they refer to)"
                )
            size[key] = total
            if isinstance(node, yaml.MappingNode):
                duplicate = _duplicate_key(node, paths.get(key, ""))
                if duplicate:
                    raise YamlProblem(duplicate)
            continue
        if key in size:
            continue
        if key in open_nodes:
            raise YamlLimit(f"an alias at line {_line(node)} refers to a value that contains it (a recursive value)")
        open_nodes.add(key)
        stack.append((node, True))
        if isinstance(node, yaml.MappingNode):
            base = paths.get(key, "")
            for name, value in node.value:
                if isinstance(name, yaml.ScalarNode):
                    paths.setdefault(id(value), f"{base}.{name.value}" if base else str(name.value))
        for child in reversed(_children(node)):
            if id(child) in open_nodes:
                raise YamlLimit(
                    f"an alias at line {_line(child)} refers to a value that contains it (a recursive value)"
                )
            if id(child) not in size:
                stack.append((child, False))
    return paths


_OPENED = {"a flow sequence": "a [ list", "a flow mapping": "a { mapping", "a quoted scalar": "a quoted string"}


# PyYAML's words for the commonest slips, said in a preset's terms (at the fault, not where it was found)
_NO_COLON = "a line that is neither 'key: value' nor part of a value (a key without its ':', as 'seed 1' for 'seed: 1')"
_STRAY_COLON = "a ': ' where YAML takes none: a key indented under a value, or a value holding ': ' (quote it)"
_TAB = "a tab, where YAML takes spaces only (to indent, say); replace it with spaces"
_INDENTED = ("a line indented under a value that is already whole (words after a closing quote, say, or a list item "
             "under 'key: value'); indent it as the keys beside it, or make it part of that value")


def _text_line(text: str, index: int) -> str:
    lines = text.splitlines()
    return lines[index] if index < len(lines) else ""


def _long_key(characters: int) -> str | None:
    """YAML's plain keys end within 1024 characters: a key longer than that is no key to it."""
    if characters <= 1024:
        return None
    return f"a key of {characters} characters, where YAML takes at most 1024; shorten it (no key of a preset is that long)"


def _syntax_problem(exc: yaml.MarkedYAMLError, text: str) -> str:
    """The parser's complaint, at the line where the fault is: a bracket or a quote left
    open is found only at the end of the file, so it is told where it was opened."""
    mark, context = exc.problem_mark or exc.context_mark, exc.context_mark
    at_end = mark is not None and not text[mark.index:].strip()
    what = (exc.context or "").removeprefix("while parsing ").removeprefix("while scanning ")[:60]
    if exc.problem == "could not find expected ':'" and context is not None:  # found at the next line, or the end
        key = _text_line(text, context.line).find(":", context.column) - context.column
        return f"not valid YAML at line {context.line + 1}, column {context.column + 1}: {_long_key(key) or _NO_COLON}"
    if at_end and context is not None and exc.context:  # "while parsing a flow sequence" ...
        return (f"not valid YAML at line {context.line + 1}, column {context.column + 1}: "
                f"{_OPENED.get(what, what)} opened here is not closed before the end of the file")  # fmt: skip
    if what in _OPENED and context is not None and mark is not None and mark.line > context.line:
        # found lines later (the next key): the fault is the bracket or quote left open
        return (f"not valid YAML at line {context.line + 1}, column {context.column + 1}: {_OPENED[what]} "
                f"opened here is not closed (at line {mark.line + 1}: {(exc.problem or 'syntax error')[:60]})")
    if (exc.context or "").startswith("expected a single document") and mark:  # "but found another document"
        return (f"a second YAML document (a --- line) starts at line {mark.line + 1}: a preset is one document; put "
                "the other in a file of its own")
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
    problem = exc.problem or exc.context or "syntax error"
    said = _TAB if "'\\t'" in problem else _STRAY_COLON if problem == "mapping values are not allowed here" else problem[:80]
    if said is _STRAY_COLON and mark is not None:  # a key past 1024 characters, its ':' then taken for a value's
        line = _text_line(text, mark.line)
        key = line[len(line) - len(line.lstrip()) : mark.column]
        said = (": " not in key and _long_key(len(key))) or said  # not a long value holding ': '
    if problem.startswith("expected <block end>, but found") and exc.context == "while parsing a block mapping":
        said = _INDENTED
    return f"not valid YAML{where}: {said}"


def load_yaml(text: str) -> Any:
    """The single YAML document in ``text`` as Python objects (None if empty).
    YamlLimit / YamlProblem name a line and never quote the text."""
    try:
        loader = _BoundedLoader(text)  # checks every character first
    except yaml.reader.ReaderError as exc:  # a control character such as NUL
        line = text.count("\n", 0, exc.position) + 1
        raise YamlProblem(f"not valid YAML at line {line}: character #x{exc.character:04x} is not allowed") from None
    try:
        try:
            root = loader.get_single_node()
        except yaml.MarkedYAMLError as exc:
            raise YamlProblem(_syntax_problem(exc, text)) from None
        except yaml.YAMLError:
            raise YamlProblem("not valid YAML") from None
        if root is None:
            return None
        paths = check_nodes(root)
        try:
            return loader.construct_document(root)
        except yaml.MarkedYAMLError as exc:
            mark = exc.problem_mark or exc.context_mark
            where = f" at line {mark.line + 1}" if mark else ""
            said = exc.problem or "bad value"
            if said.startswith("could not determine a constructor for the tag"):  # !!python/object:..., !Foo
                said = f"its tag {said.rsplit(' ', 1)[-1][:80]} is none a preset takes; write the value without it"
            raise YamlProblem(f"a value YAML cannot read{where}: {said}") from None
        except _Unconvertible as exc:  # the reason names limits and ranges, never the text
            reason = str(exc.cause).split(";")[0][:100]
            field = f"{paths[id(exc.node)]}: " if paths.get(id(exc.node)) else ""  # a list's item has no key of its own
            if digits := re.search(r"integer string conversion: value has (\d+) digits", str(exc.cause)):
                raise YamlProblem(f"{field}the whole number at line {exc.line} has {digits[1]} digits: a number must be "
                                  "0 or between 1e-100 and 1e+100 in magnitude") from None  # fmt: skip
            raise YamlProblem(f"{field}the value at line {exc.line} cannot be converted ({type(exc.cause).__name__}: "
                              f"{reason})") from None
        except (ValueError, OverflowError) as exc:
            raise YamlProblem(f"a value YAML cannot convert ({type(exc).__name__})") from None
    finally:
        loader.dispose()
