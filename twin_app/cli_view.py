"""The `twin view`, `twin plot` and `twin snapshot` commands (added to `twin` by `add_commands`).

    twin view STATION [--host 127.0.0.1] [--port 8080] [--lockstep | --realtime [--speed X]] [--paused] [--record FILE]
    twin view --replay FILE [--at T] [--host 127.0.0.1] [--port 8080]
    twin plot FILE [SIGNAL ...] [-o plot.png|.svg]
    twin snapshot STATION|FILE [--at T] [-o cell.png] [--width W] [--height H]

Heavy libraries (viser, matplotlib, pyarrow) are imported when a command runs, never at start-up.
"""
from __future__ import annotations

import argparse

from twin_app.cli_args import positive_float, tcp_port


def _pixels(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"needs a whole number of pixels, not {text!r}") from None
    if not 16 <= v <= 8192:
        raise argparse.ArgumentTypeError(f"must be 16..8192 pixels, not {text}")
    return v


def add_commands(sub, open_cell) -> None:
    """`twin view`, `twin plot`, `twin snapshot`; `open_cell(station)` is the application's (it assembles a cell)."""
    p = sub.add_parser("view", help="the cell in 3D in a web browser: live signals, settable inputs, run controls",
                       description="Run a station and serve a live 3D page of it (or replay a recording).")
    p.add_argument("station", nargs="?", help="a station folder or station.toml (or --replay FILE)")
    p.add_argument("--host", default="127.0.0.1", help="address the page binds (default loopback only)")
    p.add_argument("--port", type=tcp_port, default=8080, help="HTTP port (default 8080; the next free one if taken; 0 = any)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--realtime", dest="lockstep", action="store_false", help="run against the wall clock (default)")
    mode.add_argument("--lockstep", action="store_true", help="step only from the page's Step / Advance buttons")
    p.add_argument("--speed", type=positive_float, default=1.0, help="real time: X times real time (default 1)")
    p.add_argument("--paused", action="store_true", help="real time: start paused (Run on the page starts it)")
    p.add_argument("--record", metavar="FILE", default=None, help="also record every step into FILE (.parquet or .csv)")
    p.add_argument("--replay", metavar="FILE", default=None, help="play a recording back, with a timeline")
    p.add_argument("--at", type=float, default=None, metavar="T", help="--replay: start at simulated time T (s)")
    p.add_argument("--events", metavar="FILE|-", default=None,
                   help="write what happens as JSON lines (ready with the page's address, ..., stopped): docs/events.md")
    p.set_defaults(func=lambda args: _view(args, open_cell), lockstep=False)

    p = sub.add_parser("plot", help="plot signals of a recording against simulated time (PNG or SVG)",
                       description="Plot a recording's signals, one panel per unit. Default: finger positions and "
                                   "setpoints, finger forces (with the PLC's threshold when known), doGripped, slip, "
                                   "robot busy.")
    p.add_argument("file", help="a recording (.parquet or .csv)")
    p.add_argument("signals", nargs="*", metavar="SIGNAL", help="signals to plot (default: the grip's signals)")
    p.add_argument("-o", "--output", default="plot.png", help="the picture to write, .png or .svg (default plot.png)")
    p.add_argument("--threshold", type=float, default=None, metavar="N",
                   help="draw the PLC's force threshold at N newtons (default: the one the station's PLC uses, if known)")
    p.set_defaults(func=_plot)

    p = sub.add_parser("snapshot", help="a picture of the cell (a station at its start, or a recording at a time), headless",
                       description="Render the cell with pybullet's software renderer: no GPU, no display.")
    p.add_argument("source", metavar="STATION|FILE", help="a station folder or station.toml, or a recording")
    p.add_argument("--at", type=float, default=None, metavar="T",
                   help="recording: the simulated time in s (default: the end); station: run T seconds first")
    p.add_argument("-o", "--output", default="cell.png", help="the PNG to write (default cell.png)")
    p.add_argument("--width", type=_pixels, default=960, help="pixels (default 960)")
    p.add_argument("--height", type=_pixels, default=720, help="pixels (default 720)")
    p.set_defaults(func=lambda args: _snapshot(args, open_cell))


def _view(args, open_cell) -> int:
    from twin.frontends.view.live import cmd_view

    return cmd_view(args, open_cell)


def _plot(args) -> int:
    from twin.observe.plot import cmd_plot

    return cmd_plot(args)


def _snapshot(args, open_cell) -> int:
    from twin.observe.picture import cmd_snapshot

    return cmd_snapshot(args, open_cell)


def add_serve_options(p) -> None:
    """The `twin serve` options of this package: --view [PORT], --view-host, --record FILE."""
    p.add_argument("--view", nargs="?", type=int, const=8080, default=None, metavar="PORT",
                   help="also serve the live 3D page (default port 8080; needs the [view] extra)")
    p.add_argument("--view-host", default="127.0.0.1", help="address the page binds (default loopback)")
    p.add_argument("--record", metavar="FILE", default=None,
                   help="record every signal and body pose at every step into FILE (.parquet, or .csv)")
