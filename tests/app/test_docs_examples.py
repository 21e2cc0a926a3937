"""Docs that are true because they are tested: every shell and Python example in README.md, docs/*.md and
twin/frontends/modbus/README.md runs here, as a reader would run it (from the project's folder).

An example that cannot run here says so visibly, in its first line: a comment starting `# illustrative:`
and why (it starts a server on a fixed port, needs a cluster or a real PLC, runs the whole suite, takes
minutes, or shows a command's synopsis). The README's opening block is the exception: it holds exactly the two
set-up commands (`python3 tasks.py demo`, `python3 tasks.py test`), checked below for what they are; CI runs the
second and tests/plc/test_demo_cli.py the first. Everything else runs:

- a Python example with `def test_...` functions is a pytest file (as the reader would save it), run by
  pytest with `plc_client.testing`'s fixtures; a comment `# plc_station: PATH` in it names the station its
  fixtures serve (else the example defines `plc_station` itself);
- any other Python example runs as a script;
- a shell example runs line by line with bash (`set -e`), the project's commands on its PATH, in a scratch
  folder that sees the project's `stations/` and `tests/`.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "twin" / "frontends" / "modbus" / "README.md"]
RUN = ("sh", "python")
ILLUSTRATIVE = "# illustrative:"


FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
SETUP = ["python3 tasks.py demo", "python3 tasks.py test"]


def examples():
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for i, m in enumerate(FENCE.finditer(text)):
            if path.name == "README.md" and path.parent == ROOT and i == 0:
                continue  # the two set-up commands (test_the_readme_opens_with_the_two_setup_commands)
            if m.group(1) in RUN:
                line = text[:m.start()].count("\n") + 2
                yield pytest.param(m.group(1), m.group(2), id=f"{path.relative_to(ROOT)}:{line}")


ALL = list(examples())


def test_the_examples_are_found_and_most_python_ones_run():
    assert len(ALL) >= 20
    python = [p for p in ALL if p.values[0] == "python"]
    assert sum(not p.values[1].startswith(ILLUSTRATIVE) for p in python) >= len(python) - 2


def test_the_readme_opens_with_the_two_setup_commands():
    """The README's first code block: the demo, then the tests, and nothing else (comments aside)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    first = FENCE.search(text)
    assert text[:first.start()].strip().startswith("# ") and text[:first.start()].count("\n") <= 3
    commands = [ln.split("#")[0].strip() for ln in first.group(2).splitlines()]
    assert [c for c in commands if c] == SETUP


def env() -> dict:
    bin_dir = str(Path(sys.executable).parent)
    return {**os.environ, "PATH": bin_dir + os.pathsep + os.environ.get("PATH", ""),
            "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""), "MPLBACKEND": "Agg"}


@pytest.mark.parametrize("lang, code", ALL)
def test_example_runs(lang, code, tmp_path):
    if code.startswith(ILLUSTRATIVE):
        pytest.skip(code.splitlines()[0])
    for name in ("stations", "tests"):
        (tmp_path / name).symlink_to(ROOT / name)
    if lang == "sh":
        cmd = ["bash", "-e", "-c", code]
    elif "def test_" in code:
        station = re.search(r"#\s*plc_station:\s*(\S+)", code)
        head = "import pytest\n\npytest_plugins = ['plc_client.testing']\n"
        if station and "def plc_station" not in code:
            head += f"\n\n@pytest.fixture\ndef plc_station():\n    return {station.group(1)!r}\n"
        (tmp_path / "test_example.py").write_text(head + "\n\n" + code, encoding="utf-8")
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_example.py"]
    else:
        cmd = [sys.executable, "-c", code]
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)  # its own process group: whatever it starts ends with it
    try:
        out, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        out, err = "", "timed out after 60 s"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()
    assert proc.returncode == 0, f"exit {proc.returncode}\n{out[-1500:]}\n{err[-1500:]}"
