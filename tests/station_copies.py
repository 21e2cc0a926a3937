"""Copies of shipped stations with one edit to their station.toml, for tests of what a changed file does."""
from __future__ import annotations

import shutil
from pathlib import Path

STATIONS = Path(__file__).resolve().parent.parent / "stations"


def edited_station(source: Path, folder: Path, old: str | None = None, new: str | None = None) -> Path:
    """`source` copied to `folder`, its station.toml with the text `old` (which must be there) replaced by `new`.
    A station that refers to the shared robot models (`../robots`) gets them beside its copy."""
    shutil.copytree(source, folder)
    if (source.parent / "robots").is_dir() and not (folder.parent / "robots").exists():
        shutil.copytree(source.parent / "robots", folder.parent / "robots")
    if old is not None:
        toml = folder / "station.toml"
        text = toml.read_text()
        assert old in text, f"{old!r} is not in {source / 'station.toml'}"
        toml.write_text(text.replace(old, new))
    return folder
