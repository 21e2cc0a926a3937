"""Loading the twin prints nothing: pybullet's import banner would land in a command's output."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_importing_the_twin_and_the_cell_prints_nothing_on_either_stream():
    out = subprocess.run([sys.executable, "-c", "import twin_app.cell, twin.core.world, twin.observe.picture"],
                         cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert (out.stdout, out.stderr) == ("", "")


def test_an_import_error_still_shows():
    # the banner is silenced, not Python's own errors
    out = subprocess.run([sys.executable, "-c", "import twin.core.world; import no_such_module_here"],
                         cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 1 and "No module named 'no_such_module_here'" in out.stderr
