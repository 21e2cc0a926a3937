"""Fixtures: `twin serve --opcua 0` subprocesses and asyncua clients to them (real sockets on loopback)."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "modbus"))  # modbus_helpers: the server process

pytest.importorskip("asyncua", reason="OPC UA tests need asyncua (the test extra installs it)")
