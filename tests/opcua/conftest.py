"""Fixtures: `twin serve --opcua 0` subprocesses and asyncua clients to them (real sockets on loopback)."""
from __future__ import annotations

import pytest

pytest.importorskip("asyncua", reason="OPC UA tests need asyncua (the test extra installs it)")
