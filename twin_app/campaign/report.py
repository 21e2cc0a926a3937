"""What a campaign leaves behind: the results table (CSV), JUnit XML, a summary, and the live progress line."""
from __future__ import annotations

import csv
import io
import math
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

MEASURED_COLUMNS = ("outcome", "fault", "time", "steps", "grips", "misses", "grip", "plc_faults",
                    "max_finger_force", "slip", "part", "part_present", "part_end_x_mm", "part_end_y_mm",
                    "part_end_z_mm", "part_moved_mm")
HIDDEN = {"trace", "faults_log", "part_start_mm", "part_end_mm", "message"}


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    if isinstance(v, (list, tuple)):
        return "+".join(_cell(x) for x in v)
    return str(v)


def _flat_measured(m: dict) -> dict:
    out = dict(m)
    end = m.get("part_end_mm")
    if "part" in m:
        for axis, k in zip("xyz", range(3)):
            out[f"part_end_{axis}_mm"] = None if end is None else end[k]
    return out


def table_rows(records: list[dict]) -> tuple[list[str], list[list[str]]]:
    """The results table: one row per scenario, in scenario order: parameters, measured values, verdict."""
    params: list[str] = []
    extra: list[str] = []
    for r in records:
        for k in r["params"]:
            if k not in params:
                params.append(k)
        for k in _flat_measured(r["measured"]):
            if k not in MEASURED_COLUMNS and k not in HIDDEN and k not in extra:
                extra.append(k)
    extra.sort()
    # the parameter `fault` (the faults injected) and the measured `fault` (what the run stopped with) differ
    header = ["index", "name", "status", *("injected" if k == "fault" else k for k in params), *MEASURED_COLUMNS,
              *extra, "failures", "message"]
    rows = []
    for r in sorted(records, key=lambda r: r["index"]):
        m = _flat_measured(r["measured"])
        rows.append([str(r["index"]), r["name"], r["status"], *(_cell(r["params"].get(k)) for k in params),
                     *(_cell(m.get(k)) for k in MEASURED_COLUMNS), *(_cell(m.get(k)) for k in extra),
                     "; ".join(r["failures"]), _cell(m.get("message"))])
    return header, rows


def write_csv(path: Path, records: list[dict]) -> None:
    header, rows = table_rows(records)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    path.write_text(buf.getvalue())


def write_junit(path: Path, campaign_name: str, records: list[dict]) -> None:
    """JUnit XML as CI tools read it (Jenkins, GitLab, GitHub actions): one test case per scenario."""
    records = sorted(records, key=lambda r: r["index"])
    fails = sum(r["status"] == "fail" for r in records)
    errors = sum(r["status"] == "error" for r in records)
    total = sum(r.get("wall", 0.0) for r in records)
    suites = ET.Element("testsuites", name=campaign_name, tests=str(len(records)), failures=str(fails),
                        errors=str(errors), time=f"{total:.3f}")
    suite = ET.SubElement(suites, "testsuite", name=campaign_name, tests=str(len(records)), failures=str(fails),
                          errors=str(errors), skipped="0", time=f"{total:.3f}",
                          timestamp=time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime()))
    for r in records:
        case = ET.SubElement(suite, "testcase", name=r["name"], classname=f"campaign.{_classname(campaign_name)}",
                             time=f"{r.get('wall', 0.0):.3f}")
        m = r["measured"]
        if r["status"] in ("fail", "error"):
            tag = "failure" if r["status"] == "fail" else "error"
            message = "; ".join(r["failures"]) or m.get("message", "")
            el = ET.SubElement(case, tag, message=message, type=m.get("fault", tag) if tag == "error" else "expectation")
            el.text = _details(r)
        out = ET.SubElement(case, "system-out")
        out.text = _details(r)
    ET.indent(suites)
    path.write_bytes(ET.tostring(suites, encoding="utf-8", xml_declaration=True))


def _classname(name: str) -> str:
    return "".join(c if c.isalnum() or c in "_-" else "_" for c in name) or "campaign"


def _details(r: dict) -> str:
    m = r["measured"]
    lines = [f"scenario {r['index']}: {r['name']}"]
    lines += [f"  {k} = {_cell(v)}" for k, v in r["params"].items()]
    lines.append("measured:")
    lines += [f"  {k} = {_cell(v)}" for k, v in _flat_measured(m).items() if k not in HIDDEN]
    if m.get("message"):
        lines.append(f"message: {m['message']}")
    for entry in m.get("faults_log", []):
        lines.append(f"fault: {entry}")
    for f in r["failures"]:
        lines.append(f"FAILED {f}")
    return "\n".join(lines)


def summary_text(campaign_name: str, records: list[dict], total: int, wall: float, backend: str) -> str:
    counts = {s: sum(r["status"] == s for r in records) for s in ("pass", "fail", "error")}
    outcomes: dict[str, int] = {}
    for r in records:
        o = r["measured"].get("outcome", "?")
        outcomes[o] = outcomes.get(o, 0) + 1
    lines = [f"campaign {campaign_name}: {len(records)} of {total} scenarios run: {counts['pass']} passed, "
             f"{counts['fail']} failed, {counts['error']} errors",
             "outcomes: " + ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items())),
             f"wall time {wall:.1f} s on {backend}" + (f" ({len(records) / wall * 60:.1f} scenarios/min)" if wall > 0 and records else "")]
    bad = [r for r in sorted(records, key=lambda r: r["index"]) if r["status"] != "pass"]
    for r in bad[:20]:
        why = "; ".join(r["failures"]) or r["measured"].get("message", "")
        lines.append(f"  {r['status'].upper():5} [{r['index']}] {r['name']}: {why}")
    if len(bad) > 20:
        lines.append(f"  ... and {len(bad) - 20} more (see the results table)")
    return "\n".join(lines) + "\n"


class Progress:
    """The live line: done/total, pass/fail/error, rate, time left. On a terminal it rewrites itself; else a
    line every `every` seconds and at the end."""

    def __init__(self, total: int, stream=None, every: float = 5.0, already: int = 0):
        self.total, self.stream, self.every = total, stream or sys.stderr, every
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.t0 = time.monotonic()
        self.done = self.already = already
        self.counts = {"pass": 0, "fail": 0, "error": 0}
        self._last = 0.0

    def update(self, status: str) -> None:
        self.done += 1
        self.counts[status] = self.counts.get(status, 0) + 1
        now = time.monotonic()
        if self.tty or now - self._last >= self.every or self.done == self.total:
            self._last = now
            self._print(self.line(now))

    def line(self, now: float | None = None) -> str:
        now = time.monotonic() if now is None else now
        elapsed = max(now - self.t0, 1e-9)
        ran = self.done - self.already
        rate = ran / elapsed * 60.0
        left = (self.total - self.done) / (ran / elapsed) if ran else float("nan")
        eta = "--" if not math.isfinite(left) else (f"{left / 60:.0f} min" if left >= 120 else f"{left:.0f} s")
        c = self.counts
        return (f"[{self.done}/{self.total}] pass {c['pass']} fail {c['fail']} error {c['error']} | "
                f"{rate:.1f} scenarios/min | {eta} left")

    def _print(self, text: str) -> None:
        if self.tty:
            self.stream.write("\r" + text + "\x1b[K")
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def close(self) -> None:
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
