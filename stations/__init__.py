"""Ready-made stations (cells): each folder holds a station.toml and its models."""
from pathlib import Path

ROOT = Path(__file__).resolve().parent


def path(name: str) -> Path:
    """The folder of a shipped station, e.g. path("ring_rig")."""
    return ROOT / name
