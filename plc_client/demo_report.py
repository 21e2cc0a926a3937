"""A demo's report (`plc demo`): the run is recorded by the twin server, and the report is drawn from that recording
(`twin.observe.report`: the signal plot and a picture of the cell at each grip and release, in one folder).

Without the [view] extra (matplotlib, pyarrow) the demo still runs: it records to CSV, and says in one
line why there is no report.
"""
from __future__ import annotations

from pathlib import Path


def recording_for(record: str | None, report_dir: str | None) -> str | None:
    """The file the server records into: the one asked for, else (for a report) one in the report's folder."""
    if record is not None or report_dir is None:
        return record
    Path(report_dir).mkdir(parents=True, exist_ok=True)
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return str(Path(report_dir) / "recording.csv")
    return str(Path(report_dir) / "recording.parquet")


def report(record: str, report_dir: str, *, threshold: float | None, narration: list[str],
           title: str = "gripper-twin demo") -> Path | None:
    try:
        import matplotlib  # noqa: F401
        import PIL  # noqa: F401
    except ImportError:
        print("report: not written: it needs matplotlib (pip install 'gripper-twin[view]')", flush=True)
        return None
    from twin.observe.report import write_report

    index = write_report(record, report_dir, threshold=threshold, narration=narration,
                         title=title)
    print(f"report: {index.resolve()}", flush=True)
    return index
