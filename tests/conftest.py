"""Shared test helpers: paths of the shipped stations and of pybullet's own models."""
from pathlib import Path

import pybullet_data
import pytest

ROOT = Path(__file__).resolve().parent.parent
STATIONS = ROOT / "stations"
PYBULLET_DATA = Path(pybullet_data.getDataPath())


@pytest.fixture
def stations() -> Path:
    return STATIONS
