"""Expectations: what a scenario must show, checked against what it measured.

The campaign's `[expect]` applies to every scenario; each `[[expect.when]]` whose `if` holds for the
scenario's parameters overrides it (in order), and a listed scenario's own `expect` comes last. The
verdict is `pass`, `fail` (an expectation not met: each failure says what was expected and what was
measured) or `error` (the scenario could not run: it crashed, hung, or raised).
"""
from __future__ import annotations

import math

from .spec import Campaign, Scenario, scenario_values

PASS, FAIL, ERROR = "pass", "fail", "error"


def expectations(campaign: Campaign, scenario: Scenario) -> dict:
    exp = dict(campaign.expect)
    values = scenario_values(scenario)
    for cond, override in campaign.when:
        if cond.evaluate(values):
            exp.update(override)
    exp.update(scenario.expect)
    return exp


def judge(campaign: Campaign, scenario: Scenario, measured: dict) -> tuple[str, list[str]]:
    """(status, failures): each failure names the expectation, what it wanted and what was measured."""
    exp = expectations(campaign, scenario)
    outcome = measured.get("outcome")
    if outcome in ("crashed", "hung"):
        return ERROR, [f"{outcome}: {measured.get('message', '')}"]
    failures: list[str] = []
    want = exp.get("outcome", "completed")
    wanted = want if isinstance(want, list) else [want]
    if outcome not in wanted:
        detail = f" ({measured['fault']}" + (f": {measured['message']}" if measured.get("message") else "") + ")" \
            if measured.get("fault") not in (None, "none") else (f" ({measured['message']})" if measured.get("message") else "")
        failures.append(f"outcome: expected {' or '.join(wanted)}, measured {outcome}{detail}")
    if outcome == "error" and "error" not in wanted:
        return ERROR, failures
    if "fault" in exp and measured.get("fault", "none") != exp["fault"]:
        failures.append(f"fault: expected {exp['fault']}, measured {measured.get('fault', 'none')}")
    if "plc_fault" in exp:
        seen = measured.get("plc_faults", "none")
        if exp["plc_fault"] == "none" and seen != "none" or exp["plc_fault"] != "none" and exp["plc_fault"] not in seen.split("+"):
            failures.append(f"plc_fault: expected {exp['plc_fault']}, measured {seen}")
    if "grip" in exp and measured.get("grip") != exp["grip"]:
        failures.append(f"grip: expected {exp['grip']}, measured {measured.get('grip')} "
                        f"({measured.get('grips', 0)} confirmed, {measured.get('misses', 0)} missed)")
    for key in ("grips", "misses"):
        if key in exp and measured.get(key) != exp[key]:
            failures.append(f"{key}: expected {exp[key]}, measured {measured.get(key)}")
    if "cycle_time_max" in exp:
        t = measured.get("time")
        if t is None or t > exp["cycle_time_max"]:
            failures.append(f"cycle_time_max: expected at most {exp['cycle_time_max']:g} s, measured {_num(t)} s")
    if "max_finger_force" in exp:
        f = measured.get("max_finger_force")
        if f is None or f > exp["max_finger_force"]:
            failures.append(f"max_finger_force: expected at most {exp['max_finger_force']:g} N, measured {_num(f)} N")
    if "slip" in exp:
        s = measured.get("slip")
        if s is not None and bool(s) != exp["slip"]:
            failures.append(f"slip: expected {str(exp['slip']).lower()}, measured {str(bool(s)).lower()}")
    if "part_present" in exp and bool(measured.get("part_present")) != exp["part_present"]:
        failures.append(f"part_present: expected {str(exp['part_present']).lower()}, measured "
                        f"{str(bool(measured.get('part_present'))).lower()}")
    if ("part_tolerance_mm" in exp or "part_at_mm" in exp) and exp.get("part_present", True):
        failures += _part(exp, measured)
    for name, want_value in exp.get("values", {}).items():
        failures += _value(name, want_value, measured)
    return (FAIL if failures else PASS), failures


def _part(exp: dict, measured: dict) -> list[str]:
    tol = exp.get("part_tolerance_mm", 5.0)
    if "part_end_mm" not in measured:
        return ["part: the station has no target to measure"]
    end = measured.get("part_end_mm")
    target = exp.get("part_at_mm", measured.get("part_start_mm"))
    where = "its start" if "part_at_mm" not in exp else f"({', '.join(f'{v:g}' for v in target)}) mm"
    if end is None:
        return [f"part: expected {measured.get('part')} within {tol:g} mm of {where}, measured: not in the cell"]
    error = math.dist(end, target)
    if error > tol:
        return [f"part: expected {measured.get('part')} within {tol:g} mm of {where}, measured {error:.1f} mm away "
                f"(at {', '.join(f'{v:.1f}' for v in end)} mm)"]
    return []


def _value(name: str, want, measured: dict) -> list[str]:
    if name not in measured:
        return [f"values.{name}: expected a measured value, none was measured"]
    got = measured[name]
    if isinstance(want, dict):
        out = []
        if "equal" in want and got != want["equal"]:
            out.append(f"values.{name}: expected {want['equal']!r}, measured {got!r}")
        if "min" in want and not (isinstance(got, (int, float)) and got >= want["min"]):
            out.append(f"values.{name}: expected at least {want['min']:g}, measured {_num(got)}")
        if "max" in want and not (isinstance(got, (int, float)) and got <= want["max"]):
            out.append(f"values.{name}: expected at most {want['max']:g}, measured {_num(got)}")
        return out
    return [] if got == want else [f"values.{name}: expected {want!r}, measured {got!r}"]


def _num(v) -> str:
    return f"{v:.4g}" if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v)
