"""Requirements with verdicts: a requirements file (TOML) states what a run or a campaign must
show, and `run`, `mission` and `campaign` judge each requirement PASS, FAIL, INCONCLUSIVE or
ERROR (the ECSS-E-ST-10-02 vocabulary of verification) with its evidence, in their printed
table, summary JSON, HTML report and a JUnit XML file that CI systems read.

    [values]                       # named constants the checks may use
    tank_kg = 0.5871

    [[requirement]]
    id = "NBR-DEO-1"
    text = "The host re-enters within five years of the de-orbit burn."
    source = "thesis section 2.4 (requirement 3) and 3.2"
    check = "reentered and lifetime_with_burn_years < 5"          # one run (run, mission)
    probability = "P(reentered and end_s - burn_start_s < 5 y) >= 0.99 at 95 %"   # campaigns

A check is an expression over the run's names (a mission's summary figures, a campaign's metrics,
`stop_time`, the `[values]`), its signals (`max(comp.var)`, `min`, `mean`, `rms`, `initial`,
`final`; a bare `comp.var` is its final value) and numbers, with `and`, `or`, `not`,
comparisons and `+ - * /`; a number may carry a unit (`0.5 deg`, `5 y`, `100 kB`), which turns it
into SI (rad, s, B...), so write one where the other side is in SI. A name the command does not
have is refused before the run, in one line naming the file, the line and the names it has.

Verdicts. One run: PASS or FAIL as the check is true or false; INCONCLUSIVE when a value it needs
is missing (a phase the run never reached); ERROR when the run failed. A campaign: the runs
that meet the check (a run that failed, timed out or lacks a value does not) give k of n, and the
one-sided Clopper-Pearson bound at the confidence decides: PASS when the lower bound meets the
required probability, FAIL when the upper bound is below it, else INCONCLUSIVE with the number of
further runs like these that would decide it."""
from dataclasses import dataclass, field
import math
from pathlib import Path
import re
import sys
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple
import xml.etree.ElementTree as ET

from ..errors import SSPError
from ..limits import read_text_input
from ..master.expressions import (NUMBER_FUNCTIONS, SIGNAL_FUNCTIONS, UNITS, Check, Missing, evaluate,  # noqa: F401
                                  parse_check, signal_statistic)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

VERDICTS = ("PASS", "FAIL", "INCONCLUSIVE", "ERROR")
_PROBABILITY = re.compile(r"^\s*P\s*\((?P<check>.+)\)\s*(?P<op>>=|>|<=|<)\s*(?P<level>[0-9.eE+-]+)"
                          r"\s*(?:at\s+(?P<confidence>[0-9.]+)\s*%)?\s*$", re.S)
REQUIREMENT_KEYS = {"id", "text", "source", "check", "probability"}
DEFAULT_CONFIDENCE = 0.95


@dataclass(frozen=True)
class Probability:
    check: Check
    op: str
    level: float
    confidence: float

    @property
    def text(self) -> str:
        return f"P({self.check.text}) {self.op} {self.level:g} at {100 * self.confidence:g} %"


@dataclass(frozen=True)
class Requirement:
    id: str
    text: str
    source: str
    check: Optional[Check] = None
    probability: Optional[Probability] = None
    line: int = 0  # of its [[requirement]] header


@dataclass
class Requirements:
    path: Path
    requirements: List[Requirement]
    values: Dict[str, float] = field(default_factory=dict)
    lines: Dict[Tuple[int, str], int] = field(default_factory=dict)  # (requirement index, key) -> line

    def where(self, index: int, key: str) -> str:
        line = self.lines.get((index, key)) or self.requirements[index].line
        return f"{self.path}:{line}" if line else str(self.path)

    def for_runs(self) -> List[Tuple[int, Requirement, Check]]:
        """The requirements a single run judges (those with a check), with their index."""
        return [(i, r, r.check) for i, r in enumerate(self.requirements) if r.check is not None]

    def for_campaigns(self) -> List[Tuple[int, Requirement, Probability]]:
        return [(i, r, r.probability) for i, r in enumerate(self.requirements) if r.probability is not None]

    def uncovered(self, campaign: bool) -> List[Requirement]:
        """The requirements this kind of command cannot judge (a campaign judges probabilities)."""
        judged = {id(r) for _, r, _ in (self.for_campaigns() if campaign else self.for_runs())}
        return [r for r in self.requirements if id(r) not in judged]


# ---- reading ------------------------------------------------------------------------------
def load(path: Any) -> Requirements:
    """The requirements file at `path`, checked: each requirement has an id, a text, a source and
    a check or a probability that parse; ids are unique. SSPError names the file, line and key."""
    path = Path(path)
    text = read_text_input(path, str(path), "the requirements file",
                           "expected a requirements file (TOML, docs/requirements.md)")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SSPError(f"{path}: not valid TOML: {exc}") from None
    unknown = sorted(set(doc) - {"requirement", "values"})
    if unknown:
        raise SSPError(f"{path}: unknown table(s) {', '.join(unknown)} (expected [values] and [[requirement]])")
    headers = [n + 1 for n, line in enumerate(text.splitlines()) if line.strip().startswith("[[requirement]]")]
    lines = _key_lines(text, headers)
    values: Dict[str, float] = {}
    for name, value in (doc.get("values") or {}).items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SSPError(f"{path}: values.{name} = {value!r}: expected a finite number")
        if not name.isidentifier():
            raise SSPError(f"{path}: values.{name}: a value's name is a plain name (letters, digits, _)")
        values[name] = float(value)
    entries = doc.get("requirement")
    if not isinstance(entries, list) or not entries:
        raise SSPError(f"{path}: no [[requirement]] (each needs id, text, source and check or probability)")
    reqs = []
    seen: Dict[str, int] = {}
    for i, entry in enumerate(entries):
        line = headers[i] if i < len(headers) else 0
        where = f"{path}:{line}" if line else str(path)
        extra = sorted(set(entry) - REQUIREMENT_KEYS)
        if extra:
            raise SSPError(f"{where}: requirement key(s) {', '.join(extra)} unknown (expected "
                           f"{', '.join(sorted(REQUIREMENT_KEYS))})")
        for key in ("id", "text", "source"):
            if not isinstance(entry.get(key), str) or not entry[key].strip():
                raise SSPError(f"{where}: requirement {entry.get('id', i + 1)!r}: {key} must be a non-empty text")
        rid = entry["id"].strip()
        if rid in seen:
            raise SSPError(f"{where}: requirement id {rid!r} is also the id at line {seen[rid]}")
        seen[rid] = line
        if "check" not in entry and "probability" not in entry:
            raise SSPError(f"{where}: requirement {rid!r} has neither a check (one run) nor a probability (campaigns)")
        check = probability = None
        for key in ("check", "probability"):
            if key in entry and not isinstance(entry[key], str):
                raise SSPError(f"{path}:{lines.get((i, key), line)}: requirement {rid!r}: {key} must be a text")
        try:
            if "check" in entry:
                check = parse_check(entry["check"])
        except SSPError as exc:
            raise SSPError(f"{path}:{lines.get((i, 'check'), line)}: requirement {rid!r}: check: {exc}") from None
        try:
            if "probability" in entry:
                probability = parse_probability(entry["probability"])
        except SSPError as exc:
            raise SSPError(f"{path}:{lines.get((i, 'probability'), line)}: requirement {rid!r}: probability: "
                           f"{exc}") from None
        reqs.append(Requirement(rid, entry["text"].strip(), entry["source"].strip(), check, probability, line))
    return Requirements(path, reqs, values, lines)


def _key_lines(text: str, headers: Sequence[int]) -> Dict[Tuple[int, str], int]:
    out: Dict[Tuple[int, str], int] = {}
    rows = text.splitlines()
    for i, start in enumerate(headers):
        end = headers[i + 1] - 1 if i + 1 < len(headers) else len(rows)
        for n in range(start, end):
            m = re.match(r"\s*([A-Za-z_]+)\s*=", rows[n])
            if m:
                out.setdefault((i, m.group(1)), n + 1)
    return out


def parse_probability(text: str) -> Probability:
    m = _PROBABILITY.match(text)
    if not m:
        raise SSPError(f"{text!r}: expected 'P(<check>) >= <probability> [at <confidence> %]'")
    try:
        level = float(m.group("level"))
    except ValueError:
        raise SSPError(f"{text!r}: {m.group('level')!r} is not a probability") from None
    confidence = float(m.group("confidence")) / 100.0 if m.group("confidence") else DEFAULT_CONFIDENCE
    if not 0.0 < level < 1.0:
        raise SSPError(f"{text!r}: the probability {level:g} must be between 0 and 1 (exclusive)")
    if not 0.5 <= confidence < 1.0:
        raise SSPError(f"{text!r}: the confidence {100 * confidence:g} % must be at least 50 % and below 100 %")
    return Probability(parse_check(m.group("check")), m.group("op"), level, confidence)


def check_names(reqs: Requirements, campaign: bool, names: Sequence[str],
                signal_known: Optional[Callable[[str, str], Optional[str]]] = None) -> None:
    """Refuse (SSPError, file:line) a check that reads a name the command does not have, or a
    signal (`signal_known(function, name)` returns why not, or None; None: no signals here)."""
    known = set(names) | set(reqs.values)
    judged = [(i, r, p.check, "probability") for i, r, p in reqs.for_campaigns()] if campaign else \
        [(i, r, c, "check") for i, r, c in reqs.for_runs()]
    for i, r, check, key in judged:
        where = reqs.where(i, key)
        for name in check.names:
            if name not in known:
                near = sorted(known, key=lambda k: _distance(k, name))[:3]
                raise SSPError(f"{where}: requirement {r.id!r}: {key}: unknown name {name!r} (the closest of the "
                               f"{len(known)} names: {', '.join(near)})")
        for fn, signal in check.signals:
            if signal_known is None:
                raise SSPError(f"{where}: requirement {r.id!r}: {key}: {fn}({signal}): a campaign's checks read its "
                               "metrics, not signals (add a metric such as max:comp.var)")
            why = signal_known(fn, signal)
            if why:
                raise SSPError(f"{where}: requirement {r.id!r}: {key}: {signal}: {why}")


def _distance(a: str, b: str) -> int:
    import difflib
    return -int(1000 * difflib.SequenceMatcher(None, a, b).ratio())


def _number(x: Any) -> str:
    return f"{x:.6g}" if isinstance(x, float) else repr(x)


def _evidence(compared: Sequence[Mapping[str, Any]]) -> Tuple[str, Optional[float]]:
    parts = []
    for c in compared:
        left = c["left"] if c["left"] == _number(c["left_value"]) else f"{c['left']} = {_number(c['left_value'])}"
        op = c["op"] if c["holds"] else f"is not {c['op']}"
        parts.append(f"{left} {op} {_number(c['right_value'])} (margin {_number(c['margin'])})")
    margin = min((c["margin"] for c in compared), default=None) if compared and all(c["holds"] for c in compared) \
        else min((c["margin"] for c in compared if not c["holds"]), default=None)
    return "; ".join(parts), margin


def judge_run(reqs: Requirements, names: Mapping[str, Any], signal: Callable[[str, str], Any],
              error: Optional[str] = None) -> List[Dict[str, Any]]:
    """The verdicts of one run: `names` its figures, `signal(fn, name)` its signals; `error`: why
    the run failed (every requirement ERROR)."""
    values = {**reqs.values, **names}
    out = []
    for _, r, check in reqs.for_runs():
        v: Dict[str, Any] = {"id": r.id, "text": r.text, "source": r.source, "check": check.text}
        if error is not None:
            v.update(verdict="ERROR", evidence=f"the run failed: {error}")
        else:
            try:
                holds, compared = evaluate(check, values.get, signal)
            except Missing as exc:
                v.update(verdict="INCONCLUSIVE", evidence=f"no value of {exc} in this run")
            else:
                evidence, margin = _evidence(compared)
                v.update(verdict="PASS" if holds else "FAIL", evidence=evidence or ("true" if holds else "false"),
                         margin=margin, comparisons=compared)
        out.append(v)
    return out


def judge_result(reqs: Requirements, result: Any, error: Optional[str] = None) -> List[Dict[str, Any]]:
    """The verdicts of one run of a system (`neighbor-cosim run`): its names are stop_time, steps
    and incomplete; its signals the recorded columns (a bare comp.var: the final value of any input
    or output)."""
    if result is None:
        return judge_run(reqs, {}, _no_signals, error or "no result")
    names = {"stop_time": float(result.stop_time), "steps": int(result.steps), "incomplete": bool(result.incomplete)}

    def signal(fn: str, name: str) -> Any:
        if fn == "final" and name in result.final:
            value = result.final[name]
            return value if isinstance(value, (bool, int, float)) else None
        if name not in (result.data.dtype.names or ()):
            return None
        return signal_statistic(fn, [float(x) for x in result.data[name]])

    return judge_run(reqs, names, signal, error)


RUN_NAMES = ("stop_time", "steps", "incomplete")


def signals_read(reqs: Requirements) -> List[str]:
    """The signals the single-run checks read through a function (they must be recorded)."""
    return list(dict.fromkeys(name for _, _, c in reqs.for_runs() for fn, name in c.signals if fn != "final"))


def judge_campaign(reqs: Requirements, rows: Sequence[Mapping[str, Any]],
                   finished: Sequence[str] = ("ok", "incomplete")) -> List[Dict[str, Any]]:
    """The verdicts of a campaign's probabilities over its rows (one per run)."""
    out = []
    for _, r, p in reqs.for_campaigns():
        v: Dict[str, Any] = {"id": r.id, "text": r.text, "source": r.source, "check": p.text}
        n = len(rows)
        if n == 0:
            v.update(verdict="ERROR", evidence="no runs")
            out.append(v)
            continue
        k = failed = missing = 0
        for row in rows:
            if row.get("status") not in finished:
                failed += 1
                continue
            values = {**reqs.values, **row}
            try:
                holds, _ = evaluate(p.check, values.get, _no_signals)
            except Missing:
                missing += 1
                continue
            k += holds
        lo, hi = clopper_pearson(k, n, p.confidence)
        if p.op in (">=", ">"):
            passed = lo >= p.level if p.op == ">=" else lo > p.level
            failed_verdict = hi < p.level if p.op == ">=" else hi <= p.level
        else:
            passed = hi <= p.level if p.op == "<=" else hi < p.level
            failed_verdict = lo > p.level if p.op == "<=" else lo >= p.level
        verdict = "PASS" if passed else "FAIL" if failed_verdict else "INCONCLUSIVE"
        c = f"{100 * p.confidence:g} %"
        evidence = (f"{k} of {n} runs meet it: p = {k / n:.4g}, one-sided {c} bounds [{lo:.4g}, {hi:.4g}] against "
                    f"{p.op} {p.level:g}")
        notes = []
        if failed:
            notes.append(f"{failed} failed or timed out")
        if missing:
            notes.append(f"{missing} without a value it needs")
        if notes:
            evidence += f" ({' and '.join(notes)}: counted as not meeting it)"
        v.update(verdict=verdict, evidence=evidence, k=k, n=n, p=k / n, bounds=[lo, hi], confidence=p.confidence,
                 level=p.level)
        if verdict == "INCONCLUSIVE":
            more = runs_to_decide(k, n, p.op, p.level, p.confidence)
            v["more_runs"] = more
            v["evidence"] += (f"; about {more} more runs like these would decide it" if more is not None else
                              "; no number of runs like these decides it (their rate is at the required one)")
        out.append(v)
    return out


def _no_signals(fn: str, name: str) -> Any:
    raise Missing(f"{fn}({name})")  # check_names refuses signals in campaigns before the run


# ---- statistics (no scipy at run time: the regularized incomplete beta by its continued fraction)
def _betacf(a: float, b: float, x: float) -> float:
    tiny, eps = 1e-300, 1e-15
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 10000):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < eps:
            break
    return h


def betainc(a: float, b: float, x: float) -> float:
    """The regularized incomplete beta function I_x(a, b), a, b > 0."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    front = math.exp(math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x))
    if x < (a + 1.0) / (a + b + 2.0):
        return front * _betacf(a, b, x) / a
    return 1.0 - front * _betacf(b, a, 1.0 - x) / b


def _beta_ppf(q: float, a: float, b: float) -> float:
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if betainc(a, b, mid) < q:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-15:
            break
    return 0.5 * (lo + hi)


def clopper_pearson(k: int, n: int, confidence: float) -> Tuple[float, float]:
    """One-sided exact (Clopper-Pearson) bounds of a proportion k/n at `confidence`: the lower
    bound that the true proportion exceeds with that confidence, and the upper one."""
    lo = 0.0 if k == 0 else _beta_ppf(1.0 - confidence, k, n - k + 1)
    hi = 1.0 if k == n else _beta_ppf(confidence, k + 1, n - k)
    return lo, hi


def runs_to_decide(k: int, n: int, op: str, level: float, confidence: float, limit: int = 10 ** 7) -> Optional[int]:
    """How many more runs at the observed rate k/n would decide P op level at `confidence`
    (None: never, the rate is the required one, or more than `limit`)."""
    rate = k / n
    upward = op in (">=", ">")

    def decided(m: int) -> bool:
        kk = min(n + m, max(0, int(round(rate * (n + m)))))
        lo, hi = clopper_pearson(kk, n + m, confidence)
        return lo >= level or hi < level if upward else hi <= level or lo > level

    if rate == level:
        return None
    m = 1
    while not decided(m):
        m *= 2
        if m > limit:
            return None
    low, high = m // 2, m
    while high - low > 1:
        mid = (low + high) // 2
        if decided(mid):
            high = mid
        else:
            low = mid
    return high


# ---- reporting ----------------------------------------------------------------------------
def all_passed(verdicts: Sequence[Mapping[str, Any]]) -> bool:
    return all(v["verdict"] == "PASS" for v in verdicts)


def counts(verdicts: Sequence[Mapping[str, Any]]) -> Dict[str, int]:
    return {name: sum(v["verdict"] == name for v in verdicts) for name in VERDICTS}


def summary(reqs: Requirements, verdicts: List[Dict[str, Any]], campaign: bool) -> Dict[str, Any]:
    """What the summary JSON keeps: the file, each verdict, the counts and the requirements this
    command could not judge."""
    return {"file": str(reqs.path), "verdicts": verdicts, "counts": counts(verdicts),
            "all_passed": all_passed(verdicts),
            "uncovered": [{"id": r.id, "why": "no probability: judged by single runs" if campaign else
                           "no check: judged by campaigns"} for r in reqs.uncovered(campaign)]}


def table(s: Mapping[str, Any]) -> str:
    """The verdicts as printed lines."""
    c = s["counts"]
    lines = [f"requirements ({s['file']}): " + ", ".join(f"{c[name]} {name}" for name in VERDICTS if c[name])]
    width = max((len(v["id"]) for v in s["verdicts"]), default=2)
    for v in s["verdicts"]:
        lines.append(f"  {v['id']:<{width}}  {v['verdict']:<12}  {v['check']}")
        lines.append(f"  {'':<{width}}  {'':<12}  {v['evidence']}")
    for u in s["uncovered"]:
        lines.append(f"  {u['id']:<{width}}  {'not judged':<12}  {u['why']}")
    return "\n".join(lines)


COLOURS = {"PASS": "#d9f2d9", "FAIL": "#f8d0d0", "INCONCLUSIVE": "#fff0c0", "ERROR": "#e0d0f0"}


def html(s: Mapping[str, Any]) -> str:
    """The verdicts as an HTML table (for report.page)."""
    from html import escape

    c = s["counts"]
    head = ", ".join(f"{c[name]} {name}" for name in VERDICTS if c[name])
    rows = "".join(
        f'<tr><td>{escape(v["id"])}</td><td class="verdict" style="background:{COLOURS[v["verdict"]]}">'
        f'{v["verdict"]}</td><td>{escape(v["text"])}</td><td><code>{escape(v["check"])}</code></td>'
        f'<td>{escape(v["evidence"])}</td><td>{escape(v["source"])}</td></tr>' for v in s["verdicts"])
    rows += "".join(f'<tr><td>{escape(u["id"])}</td><td>not judged</td><td colspan="4">{escape(u["why"])}</td></tr>'
                    for u in s["uncovered"])
    return (f'<p>{escape(str(s["file"]))}: {escape(head)}</p><table class="requirements"><tr><th>id</th>'
            f"<th>verdict</th><th>requirement</th><th>check</th><th>evidence</th><th>source</th></tr>{rows}</table>")


def junit(s: Mapping[str, Any], suite: str) -> str:
    """The verdicts as JUnit XML: a test case per requirement; FAIL a failure, ERROR an error,
    INCONCLUSIVE skipped (with its evidence)."""
    c = s["counts"]
    root = ET.Element("testsuites")
    ts = ET.SubElement(root, "testsuite", name=suite, tests=str(len(s["verdicts"])), failures=str(c["FAIL"]),
                       errors=str(c["ERROR"]), skipped=str(c["INCONCLUSIVE"]))
    for v in s["verdicts"]:
        case = ET.SubElement(ts, "testcase", classname=suite, name=f"{v['id']}: {v['text']}")
        ET.SubElement(case, "properties").extend([
            ET.Element("property", name="source", value=v["source"]),
            ET.Element("property", name="check", value=v["check"]),
            ET.Element("property", name="verdict", value=v["verdict"])])
        tag = {"FAIL": "failure", "ERROR": "error", "INCONCLUSIVE": "skipped"}.get(v["verdict"])
        if tag:
            ET.SubElement(case, tag, message=f"{v['verdict']}: {v['evidence']}", type=v["verdict"])
        ET.SubElement(case, "system-out").text = v["evidence"]
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
