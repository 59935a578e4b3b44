"""The checks' language: expressions over a run's names, its signals and numbers with units,
read safely (Python's own parser, only the nodes listed here) and evaluated with the comparisons'
sides and margins kept for the evidence. Requirements' checks (system_ssp.tools.requirements)
and scenario events' conditions (events.py) are written in it.

    reentered and lifetime_with_burn_years < 5
    max(tracking.pointing_error) <= 0.5 deg and 1 < x * 2 <= 10 km

Names are looked up by the caller; `max(comp.var)`, `min`, `mean`, `rms`, `initial`, `final`
read a signal (a bare comp.var is its final, or current, value); a number with a unit is turned
into SI (`0.5 deg` is 0.008727 rad, `5 y` 157788000 s, `100 kB` 100000 B, `20 %` 0.2)."""
import ast
from dataclasses import dataclass
import math
import re
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from ..errors import SSPError

SIGNAL_FUNCTIONS = ("max", "min", "mean", "rms", "initial", "final")
NUMBER_FUNCTIONS = ("abs",)
# a number's unit -> its factor to SI
UNITS = {"rad": 1.0, "mrad": 1e-3, "deg": math.pi / 180.0, "arcsec": math.pi / 648000.0,
         "s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0, "d": 86400.0, "days": 86400.0,
         "y": 365.25 * 86400.0, "yr": 365.25 * 86400.0, "years": 365.25 * 86400.0,
         "m": 1.0, "mm": 1e-3, "km": 1e3, "kg": 1.0, "g": 1e-3, "mg": 1e-6,
         "N": 1.0, "mN": 1e-3, "Nm": 1.0, "mNm": 1e-3, "W": 1.0, "mW": 1e-3, "J": 1.0, "Wh": 3600.0,
         "B": 1.0, "kB": 1e3, "MB": 1e6, "percent": 1e-2, "rpm": 2.0 * math.pi / 60.0}
_NUMBER_UNIT = re.compile(r"(?<![\w.\]])((?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(" +
                          "|".join(sorted(map(re.escape, UNITS), key=len, reverse=True)) + r")(?![\w\[.])")
_COMPARE = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
_BINARY = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b,
           ast.Div: lambda a, b: a / b}
class Missing(Exception):
    """A value the check needs is not there (None or NaN)."""


@dataclass(frozen=True)
class Check:
    """A parsed check: its text, its tree, the plain names and the signals it reads."""
    text: str
    tree: ast.Expression
    names: Tuple[str, ...]
    signals: Tuple[Tuple[str, str], ...]  # (function, 'comp.var'); a bare comp.var is ('final', name)


def parse_check(text: str) -> Check:
    """A check's text as a Check; SSPError says what is not allowed."""
    source = _NUMBER_UNIT.sub(lambda m: f"({m.group(1)} * {UNITS[m.group(2)]!r})", text.replace("%", " percent"))
    source = source.replace("\n", " ").strip()
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError:
        raise SSPError(f"{text!r} is not an expression (names, comp.var signals, numbers with units, and, or, not, "
                       "comparisons, + - * /)") from None
    names: List[str] = []
    signals: List[Tuple[str, str]] = []

    def walk(node: ast.AST) -> None:
        if isinstance(node, ast.Expression):
            walk(node.body)
        elif isinstance(node, ast.BoolOp):
            for v in node.values:
                walk(v)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.Not, ast.USub, ast.UAdd)):
            walk(node.operand)
        elif isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            walk(node.left)
            walk(node.right)
        elif isinstance(node, ast.Compare) and all(type(op) in _COMPARE for op in node.ops):
            walk(node.left)
            for c in node.comparators:
                walk(c)
        elif isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            pass
        elif isinstance(node, ast.Name):
            if node.id not in ("true", "false", "True", "False") and node.id not in names:
                names.append(node.id)
        elif isinstance(node, (ast.Attribute, ast.Subscript)):
            signals.append(("final", _signal_name(node, text)))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords \
                and len(node.args) == 1:
            fn = node.func.id
            if fn in SIGNAL_FUNCTIONS:
                arg = node.args[0]
                if not isinstance(arg, (ast.Attribute, ast.Subscript)):
                    raise SSPError(f"{text!r}: {fn}() takes a signal, component.variable")
                signals.append((fn, _signal_name(arg, text)))
            elif fn in NUMBER_FUNCTIONS:
                walk(node.args[0])
            else:
                raise SSPError(f"{text!r}: unknown function {fn}() (signals: {', '.join(SIGNAL_FUNCTIONS)}; numbers: "
                               f"{', '.join(NUMBER_FUNCTIONS)})")
        else:
            shown = ast.unparse(node) if isinstance(node, ast.expr) else type(node).__name__
            raise SSPError(f"{text!r}: {shown!r} is not allowed (names, comp.var signals, numbers with units, "
                           "and, or, not, comparisons, + - * /)")

    walk(tree)
    return Check(text.strip(), tree, tuple(names), tuple(dict.fromkeys(signals)))


def _signal_name(node: ast.expr, text: str) -> str:
    name = ast.unparse(node).replace(" ", "")
    if not re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)+(\[\d+(,\d+)*\])?", name):
        raise SSPError(f"{text!r}: {name!r} is not a signal (component.variable, an element as comp.var[1])")
    return name


class _Evaluator:
    """Evaluates a check against `lookup(name)` and `signal(function, name)`; records each
    comparison's sides and margin for the evidence."""

    def __init__(self, lookup: Callable[[str], Any], signal: Callable[[str, str], Any]):
        self.lookup, self.signal = lookup, signal
        self.compared: List[Dict[str, Any]] = []

    def value(self, node: ast.AST) -> Any:
        if isinstance(node, ast.Expression):
            return self.value(node.body)
        if isinstance(node, ast.BoolOp):
            is_and = isinstance(node.op, ast.And)
            for v in node.values:  # short-circuit: `reentered and lifetime < 5` needs no lifetime if not reentered
                if bool(self.truth(v)) != is_and:
                    return not is_and
            return is_and
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.Not):
                return not self.truth(node.operand)
            x = self.number(node.operand)
            return -x if isinstance(node.op, ast.USub) else x
        if isinstance(node, ast.BinOp):
            a, b = self.number(node.left), self.number(node.right)
            if isinstance(node.op, ast.Div) and b == 0:
                raise Missing(f"{ast.unparse(node.right)} is 0 in a division")
            return _BINARY[type(node.op)](a, b)
        if isinstance(node, ast.Compare):
            left, left_node = self.number(node.left), node.left
            ok = True
            for op, right_node in zip(node.ops, node.comparators):
                right = self.number(right_node)
                sym = _COMPARE[type(op)]
                holds = {"<": left < right, "<=": left <= right, ">": left > right, ">=": left >= right,
                         "==": left == right, "!=": left != right}[sym]
                margin = (right - left if sym in ("<", "<=") else left - right if sym in (">", ">=")
                          else -abs(left - right) if sym == "==" else abs(left - right))
                self.compared.append({"left": ast.unparse(left_node), "op": sym, "right": ast.unparse(right_node),
                                      "left_value": left, "right_value": right, "margin": margin, "holds": holds})
                ok = ok and holds
                left, left_node = right, right_node  # a < b < c: b is the next comparison's left side
            return ok
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in ("true", "True"):
                return True
            if node.id in ("false", "False"):
                return False
            return self._present(node.id, self.lookup(node.id))
        if isinstance(node, (ast.Attribute, ast.Subscript)):
            name = ast.unparse(node).replace(" ", "")
            return self._present(name, self.signal("final", name))
        if isinstance(node, ast.Call):
            fn = node.func.id  # type: ignore[attr-defined]
            if fn in NUMBER_FUNCTIONS:
                return abs(self.number(node.args[0]))
            name = ast.unparse(node.args[0]).replace(" ", "")
            return self._present(f"{fn}({name})", self.signal(fn, name))
        raise SSPError(f"cannot evaluate {ast.dump(node)}")  # parse_check let it through: a bug

    @staticmethod
    def _present(name: str, value: Any) -> Any:
        if value is None or (isinstance(value, float) and math.isnan(value)):
            raise Missing(name)
        return value

    def number(self, node: ast.AST) -> float:
        v = self.value(node)
        if isinstance(v, str):
            raise Missing(f"{ast.unparse(node)} is a text ({v!r}), not a number")  # type: ignore[arg-type]
        return float(v)

    def truth(self, node: ast.AST) -> bool:
        return bool(self.value(node))


def evaluate(check: Check, lookup: Callable[[str], Any], signal: Callable[[str, str], Any]):
    """(holds: bool, comparisons) of `check`; raises Missing naming what it lacked."""
    ev = _Evaluator(lookup, signal)
    holds = bool(ev.value(check.tree))
    return holds, ev.compared


def signal_statistic(fn: str, values: Sequence[float]) -> Optional[float]:
    """max, min, mean, rms, initial or final of a recorded column (None: no rows)."""
    if not len(values):
        return None
    if fn == "max":
        return max(values)
    if fn == "min":
        return min(values)
    if fn == "mean":
        return math.fsum(values) / len(values)
    if fn == "rms":
        return math.sqrt(math.fsum(v * v for v in values) / len(values))
    return values[0] if fn == "initial" else values[-1]


