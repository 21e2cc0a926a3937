"""Set-up entry point for a fresh machine: `python3 tasks.py demo` or `python3 tasks.py test`.

Creates `.venv` with the project installed (editable, with the test extra) the first time, then runs the
job inside it. Only needs Python 3.11+ and pip, so it works where `make` is not installed.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
PY = VENV / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
STAMP = VENV / ".gripper-twin-installed"


def ensure_venv() -> None:
    """Create the virtual environment and install the project when missing or when pyproject changed."""
    pyproject = ROOT / "pyproject.toml"
    if STAMP.exists() and STAMP.stat().st_mtime >= pyproject.stat().st_mtime and PY.exists():
        return
    if not PY.exists():
        subprocess.check_call([sys.executable, "-m", "venv", str(VENV)])
    subprocess.check_call([str(PY), "-m", "pip", "install", "-q", "-e", f"{ROOT}[test]"])
    STAMP.touch()


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in {"demo", "test", "bench"}:
        print("usage: python3 tasks.py demo|test|bench [ARGS...]", file=sys.stderr)
        return 2
    ensure_venv()
    job, rest = argv[0], argv[1:]
    if job == "demo":
        cmd = [str(PY), "-m", "plc_client", "demo", *rest]
    elif job == "test":
        cmd = [str(PY), "-m", "pytest", "-q", *rest]
    else:
        cmd = [str(PY), "-m", "bench", *rest]
    return subprocess.call(cmd, cwd=ROOT)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
