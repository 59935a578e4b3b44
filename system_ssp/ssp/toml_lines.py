"""Where a key of a TOML document is: tomllib gives values, not lines, and a message about a spec
should name the line a user edits. `KeyLines(text)` maps every dotted key path (the tables'
headers, the keys under them, inline tables' keys on their line) to its line number."""
import re
from typing import Dict, Optional, Tuple

_HEADER = re.compile(r"^\s*(\[\[?)\s*(.+?)\s*\]\]?\s*(#.*)?$")
_KEY = re.compile(r"""^\s*((?:"[^"]*"|'[^']*'|[A-Za-z0-9_\-]+)(?:\s*\.\s*(?:"[^"]*"|'[^']*'|[A-Za-z0-9_\-]+))*)\s*=""")
_PART = re.compile(r"""\s*("[^"]*"|'[^']*'|[A-Za-z0-9_\-]+)\s*(?:\.|$)""")


def split_key(dotted: str) -> Tuple[str, ...]:
    """'a."b.c".d' -> ('a', 'b.c', 'd')."""
    parts = []
    for m in _PART.finditer(dotted):
        part = m.group(1)
        parts.append(part[1:-1] if part[:1] in "\"'" else part)
    return tuple(parts)


class KeyLines:
    def __init__(self, text: str) -> None:
        self.lines: Dict[Tuple[str, ...], int] = {}
        self.text = text.splitlines()
        table: Tuple[str, ...] = ()
        counts: Dict[Tuple[str, ...], int] = {}
        in_string = False
        for number, line in enumerate(self.text, 1):
            if line.count('"""') % 2 or line.count("'''") % 2:
                in_string = not in_string
                continue
            if in_string:
                continue
            header = _HEADER.match(line)
            if header and not _KEY.match(line):
                table = split_key(header.group(2))
                if header.group(1) == "[[":
                    index = counts.get(table, 0)
                    counts[table] = index + 1
                    self.lines.setdefault(table, number)
                    table = table + (str(index),)
                self.lines.setdefault(table, number)
                continue
            key = _KEY.match(line)
            if key:
                self.lines.setdefault(table + split_key(key.group(1)), number)
                # keys of an inline table on the same line: `links = [{ from = "a.x", ... }]`
                for inner in re.finditer(r"[{,]\s*([A-Za-z0-9_\-]+|\"[^\"]*\")\s*=", line[key.end():]):
                    self.lines.setdefault(table + split_key(key.group(1)) + split_key(inner.group(1)), number)

    def line(self, *path: str) -> Optional[int]:
        """The line of the longest prefix of `path` that the document spells (None: not at all)."""
        for n in range(len(path), 0, -1):
            if tuple(path[:n]) in self.lines:
                return self.lines[tuple(path[:n])]
        return None

    def line_of_text(self, needle: str, after: Optional[int] = None) -> Optional[int]:
        """The first line at or after `after` holding `needle` (a value inside a list)."""
        start = (after or 1) - 1
        for number, line in enumerate(self.text[start:], start + 1):
            if needle in line:
                return number
        return None
