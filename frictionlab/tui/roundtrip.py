"""Write an edited preset back into its YAML text, keeping the comments.

The file is read twice: with ruamel.yaml's round-trip loader (the nodes that
carry comments, quoting and layout) and with frictionlab's own reader (the values
frictionlab sees). A key whose value equals that reading is left alone, so its
spelling (``1e4``, quotes, a folded description) stays byte for byte; changed
values are replaced, new keys go after the key that precedes them in the edited
data, and a removed key hands its comments to the key before it (a comment
line above the next key is stored with the removed one). New scalars are
spelled so frictionlab reads them back as the same value (``1.0e-05``, ``'yes'``).
"""

from __future__ import annotations

import io
import math
import re

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import CommentMark
from ruamel.yaml.representer import RoundTripRepresenter
from ruamel.yaml.scalarstring import DoubleQuotedScalarString
from ruamel.yaml.tokens import CommentToken

from ..io.safe_yaml import YamlProblem, load_yaml
from ..runs.sweep import yaml_scalar


class _ReadsBackRepresenter(RoundTripRepresenter):
    """Plain floats and strings in spellings frictionlab's reader reads back unchanged."""


def _represent_float(representer, value: float):
    if math.isnan(value):
        text = ".nan"
    elif math.isinf(value):
        text = ".inf" if value > 0 else "-.inf"
    else:
        text = yaml_scalar(value)
    return representer.represent_scalar("tag:yaml.org,2002:float", text)


def _represent_str(representer, value: str):
    node = RoundTripRepresenter.represent_str(representer, value)
    try:
        reads_back = load_yaml(value) == value
    except YamlProblem:
        reads_back = False
    if node.style is None and not reads_back and "\n" not in value:
        node.style = "'"  # e.g. "yes", "1e4", "0o17": plain text the reader would take for another type
    return node


_ReadsBackRepresenter.add_representer(float, _represent_float)
_ReadsBackRepresenter.add_representer(str, _represent_str)


def _same(a, b) -> bool:
    """Equal and of the same types all the way down (True is not 1, 1 is not 1.0)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


# ------------------------------------------------------------------ comments of removed nodes


def _token_lines(token, indent: int | None) -> str:
    """A comment token's text; ``indent`` set when its first line is an end-of-line
    comment, which becomes a comment line of its own at that column."""
    text = token.value if token.value.endswith("\n") else token.value + "\n"
    first, _, rest = text.partition("\n")
    if indent is not None:
        first = " " * indent + first.strip() if first.strip() else ""
        return (first + "\n" if first else "") + rest
    return text


def _comments_of(node, seen: set[int]) -> str:
    """Every comment inside ``node`` (a map or list about to be dropped), in order."""
    out = []
    if isinstance(node, CommentedMap | CommentedSeq):
        ca = node.ca
        for token in _tokens(ca.comment):
            if id(token) not in seen:
                seen.add(id(token))
                out.append(_token_lines(token, None))
        items = list(node.items()) if isinstance(node, CommentedMap) else list(enumerate(node))
        for key, value in items:
            out.append(_item_comments(node, key, seen))
            out.append(_comments_of(value, seen))
    return "".join(out)


def _tokens(slot) -> list:
    if slot is None:
        return []
    if isinstance(slot, CommentToken):
        return [slot]
    return [t for part in slot for t in _tokens(part)]


def _item_comments(node, key, seen: set[int]) -> str:
    slots = node.ca.items.get(key) or []
    eol_slot = 0 if isinstance(node, CommentedSeq) else 2
    try:
        column = node.lc.item(key)[1] if isinstance(node, CommentedSeq) else node.lc.key(key)[1]
    except (KeyError, IndexError, TypeError):
        column = 0
    out = []
    for index, slot in enumerate(slots):
        for token in _tokens(slot):
            if id(token) not in seen:
                seen.add(id(token))
                out.append(_token_lines(token, column if index == eol_slot else None))
    return "".join(out)


def _append_after(node: CommentedMap, key, text: str) -> None:
    """Put comment lines right after ``node[key]`` (after its last nested line)."""
    value = node[key]
    if isinstance(value, CommentedMap) and len(value) and not value.fa.flow_style():
        _append_after(value, list(value)[-1], text)
        return
    if isinstance(value, CommentedSeq) and len(value) and not value.fa.flow_style():
        slots, index = value.ca.items.setdefault(len(value) - 1, [None, None, None, None]), 0
    else:
        slots, index = node.ca.items.setdefault(key, [None, None, None, None]), 2
    token = slots[index]
    if token is None:
        slots[index] = CommentToken("\n" + text, CommentMark(0), None)
    else:
        token.value = (token.value if token.value.endswith("\n") else token.value + "\n") + text


# ------------------------------------------------------------------ merging


# what only a double-quoted scalar carries, escaped: YAML's non-printable characters, and line
# breaks but \n (a folded or quoted value reads them back as \n)
_ESCAPED_ONLY = re.compile("[^\t\n\x20-\x7e\xa0-\u2027\u202a-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _to_node(value):
    """Plain dicts and lists as ruamel containers, so comments can be hung on them; text
    that needs escapes double-quoted (ruamel keeps a key's folded or quoted style for its new value,
    and wrote the characters raw: a file no reader takes)."""
    if isinstance(value, str) and _ESCAPED_ONLY.search(value):
        return DoubleQuotedScalarString(value)
    if isinstance(value, dict) and not isinstance(value, CommentedMap):
        return CommentedMap((k, _to_node(v)) for k, v in value.items())
    if isinstance(value, list) and not isinstance(value, CommentedSeq):
        return CommentedSeq(_to_node(v) for v in value)
    return value


def _dedent(text: str, column: int) -> str:
    """Comment lines no deeper than ``column`` (the removed key's): they now sit among its siblings."""
    lines = []
    for line in text.splitlines(keepends=True):
        body = line.lstrip(" ")
        lines.append(" " * min(len(line) - len(body), column) + body if body.strip() else line)
    return "".join(lines)


def _removed_comments(node: CommentedMap, key) -> str:
    seen: set[int] = set()
    text = _item_comments(node, key, seen) + _comments_of(node[key], seen)
    return _dedent(text, _key_column(node, key))


def _key_column(node: CommentedMap, key) -> int:
    try:
        return node.lc.key(key)[1]
    except (KeyError, IndexError, TypeError):
        return 0


def _put_above(node: CommentedMap, key, text: str) -> None:
    slots = node.ca.items.setdefault(key, [None, None, None, None])
    slots[1] = (slots[1] or []) + [CommentToken(text, CommentMark(0), None)]


def _merge(node: CommentedMap, old: dict, new: dict) -> str:
    """Make ``node`` hold ``new``; returns comment text that found no place in it
    (all its keys went)."""
    keys = list(node)
    removed = []  # (the surviving key before it or None, the first surviving key after it or None, comments)
    for position, key in enumerate(keys):
        if key in new:
            continue
        text = _removed_comments(node, key)
        if text:
            before = next((k for k in reversed(keys[:position]) if k in new), None)
            after = next((k for k in keys[position + 1 :] if k in new), None)
            removed.append((before, after, text))
        del node[key]
    placed: list[tuple[object, str]] = []  # (key to put the comments after, comments)
    previous = None
    for key, value in new.items():
        if key not in node:
            position = 0 if previous is None else list(node).index(previous) + 1
            node.insert(position, key, _to_node(value))
        elif key in old and _same(value, old[key]):
            pass
        elif isinstance(value, dict) and isinstance(node[key], CommentedMap) and isinstance(old.get(key), dict):
            left = _merge(node[key], old[key], value)
            if left:  # the section is now empty ({}): its comments go above it
                _put_above(node, key, _dedent(left, _key_column(node, key)))
        else:
            text = _comments_of(node[key], set())
            node[key] = _to_node(value)
            if text:
                placed.append((key, text))
        previous = key
    lost = ""
    order = list(node)
    for before, after, text in removed:
        if before is None:
            # keys added in front of the first survivor now stand where the removed key stood
            front = order[: order.index(after)] if after is not None else order
            before = front[-1] if front else None
        if before is not None:
            placed.append((before, text))
        elif after is not None:
            _put_above(node, after, text)
        else:
            lost += text
    for key, text in placed:
        _append_after(node, key, text)
    return lost


def _guess_indents(text: str) -> tuple[int, int]:
    """(mapping indent, dash offset) of a block-style file; (2, 0) when it shows none."""
    mapping = offset = None
    parent_indent = None  # indent of the previous line when it was a key with nothing after the colon
    for line in text.splitlines():
        body = line.lstrip(" ")
        if not body or body.startswith("#"):
            continue
        indent = len(line) - len(body)
        if parent_indent is not None and indent > parent_indent:
            if body.startswith("- ") and offset is None:
                offset = indent - parent_indent
            elif not body.startswith("-") and mapping is None:
                mapping = indent - parent_indent
        if mapping is not None and offset is not None:
            break
        key_only = body.split(" #")[0].rstrip().endswith(":") and not body.startswith("-")
        parent_indent = indent if key_only else None
    return mapping or 2, offset or 0


def _explicit_start(text: str) -> bool:
    """Whether the document starts with ``---`` (after any comment lines)."""
    for line in text.splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            return line.rstrip() == "---" or line.startswith("--- ")
    return False


def dump_preserving(original: str, data: dict) -> str | None:
    """``data`` as YAML laid out like ``original``, or None when ``original``
    cannot be read as a mapping by both loaders (the caller writes it plainly)."""
    rt = YAML(typ="rt")
    rt.Representer = _ReadsBackRepresenter
    rt.preserve_quotes = True
    rt.width = 4096  # never re-wrap a long line the file had on one line
    try:
        old = load_yaml(original)
        node = rt.load(original)
    except Exception:  # ruamel and the reader raise several types for text one of them refuses
        return None
    if not isinstance(old, dict) or not isinstance(node, CommentedMap):
        return None
    mapping, offset = _guess_indents(original)
    rt.indent(mapping=mapping, sequence=offset + 2, offset=offset)
    rt.explicit_start = _explicit_start(original)
    lost = _merge(node, old, data)
    out = io.StringIO()
    rt.dump(node, out)
    return out.getvalue() + lost
