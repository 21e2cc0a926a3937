"""`twin plot FILE [SIGNAL ...] [-o plot.png|.svg]`: a recording's signals against simulated time.

One panel per unit, in the units the PLC sees (mm, deg, N; SI units otherwise), and one panel for the
on/off signals, each on its own labelled row. Every line is named at its right end, so the picture
reads without a legend hunt; a setpoint is drawn dashed in the colour of its axis's actual position.

With no SIGNAL the grip's story: the finger axes' positions and setpoints, the finger forces (with the
PLC's force threshold as a dotted line when it is known: `threshold`), `doGripped`, any slip signal,
`robot.busy`. A SIGNAL may be a glob (`L*.force`).
"""
from __future__ import annotations

import fnmatch
from pathlib import Path

import numpy as np

from twin.core.errors import TwinError
from twin.core.signals import ENGINEERING_UNITS as ENGINEERING
from .recording import Recording

FORMATS = (".png", ".svg")


def default_signals(rec: Recording) -> list[str]:
    """The grip's signals present in `rec` (see the module docstring)."""
    sig = {s["name"]: s for s in rec.scene.signals}
    chosen = []
    fingers_axes = [s["name"] for s in rec.scene.signals
                    if s["direction"] == "input" and s["type"] == "float" and s.get("group", "gripper") == "gripper"]
    for axis in fingers_axes:
        chosen += [axis, f"{axis}.actual"] if f"{axis}.actual" in sig else [axis]
    chosen += [n for n in sig if n.endswith(".force") or n.endswith(".measured_force")]
    chosen += [n for n in ("doGripped",) if n in sig]
    chosen += [n for n in sig if n == "slip" or n.endswith(".slip")]
    chosen += [n for n in ("robot.busy",) if n in sig]
    return chosen


def resolve(rec: Recording, wanted: list[str]) -> list[str]:
    names = rec.signal_names
    out = []
    for w in wanted:
        hits = [n for n in names if fnmatch.fnmatchcase(n, w)] if any(c in w for c in "*?[") else ([w] if w in names else [])
        if not hits:
            close = [n for n in names if w.lower() in n.lower()][:6]
            raise TwinError(f"{rec.path}: no signal {w!r} in this recording"
                            + (f" (did you mean {', '.join(close)}?)" if close else f" (signals: {', '.join(names)})"))
        out += [h for h in hits if h not in out]
    return out


def plot_recording(rec: Recording, signals: list[str] | None = None, output: str | Path = "plot.png", *,
                   threshold: float | None = None, title: str | None = None, size=(11.0, None)) -> Path:
    """Write the plot of `signals` (default: `default_signals`) to `output` (.png or .svg); returns its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    output = Path(output)
    if output.suffix.lower() not in FORMATS:
        raise TwinError(f"{output}: twin plot writes .png or .svg, not {output.suffix or 'a file without suffix'}")
    names = resolve(rec, signals) if signals else default_signals(rec)
    if not names:
        raise TwinError(f"{rec.path}: nothing to plot (name the signals: {', '.join(rec.signal_names)})")
    spec = {s["name"]: s for s in rec.scene.signals}
    t = rec.time
    panels: dict[str, list[str]] = {}
    for n in names:
        s = spec[n]
        key = "on/off" if s["type"] in ("bool",) else ("text" if s["type"] == "enum" else
                                                      ENGINEERING.get(s["unit"], (s["unit"] or "value", 1.0))[0])
        panels.setdefault(key, []).append(n)
    order = sorted(panels, key=lambda k: (k in ("on/off", "text"), k == "N", list(panels).index(k)))
    heights = [max(1.2, 0.45 * len(panels[k])) if k in ("on/off", "text") else 2.6 for k in order]
    fig_h = size[1] or (sum(heights) + 1.2)
    fig, axes = plt.subplots(len(order), 1, sharex=True, figsize=(size[0], fig_h), squeeze=False,
                             gridspec_kw={"height_ratios": heights})
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, key in zip(axes[:, 0], order):
        if key in ("on/off", "text"):
            _on_off_panel(ax, t, [(n, rec.column(n), spec[n]) for n in panels[key]])
            continue
        colour_of: dict[str, str] = {}
        ends: list[tuple[float, str, str]] = []  # (last value, label, colour): named at the right end
        for n in panels[key]:
            s = spec[n]
            factor = ENGINEERING.get(s["unit"], (None, 1.0))[1]
            y = np.asarray(rec.column(n), dtype=float) * factor
            base = n[:-len(".actual")] if n.endswith(".actual") else n
            is_setpoint = s["direction"] == "input" and f"{n}.actual" in spec
            colour = colour_of.setdefault(base, colours[len(colour_of) % len(colours)])
            ax.plot(t, y, color=colour, lw=1.0 if is_setpoint else 1.6, ls="--" if is_setpoint else "-",
                    label=f"{n} (setpoint)" if is_setpoint else n, drawstyle="steps-post" if is_setpoint else "default")
            if len(y) and not is_setpoint and np.isfinite(y[-1]):
                ends.append((float(y[-1]), n, colour))
        _name_line_ends(ax, t, ends)
        if key == "N" and threshold is not None:
            ax.axhline(threshold, color="k", ls=":", lw=1.0)
            ax.annotate(f"PLC threshold {threshold:g} N", (t[0] if len(t) else 0, threshold), xytext=(2, 3),
                        textcoords="offset points", fontsize=7)
        ax.set_ylabel(key)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", ncol=min(4, len(panels[key])), framealpha=0.7)
    axes[-1, 0].set_xlabel("simulated time [s]")
    fig.suptitle(title or f"{rec.scene.station}: {Path(rec.path).name}", fontsize=10)
    fig.tight_layout(rect=(0, 0, 0.93, 1))
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=110)
    plt.close(fig)
    return output


def _name_line_ends(ax, t, ends) -> None:
    """Name each line at its right end; lines ending together share one label (no overlapping text)."""
    if not ends or not len(t):
        return
    values = [v for v, _, _ in ends]
    span = (max(values) - min(values)) or 1.0
    groups: list[list] = []
    for v, name, colour in sorted(ends):
        if groups and abs(v - groups[-1][-1][0]) < 0.04 * span:
            groups[-1].append((v, name, colour))
        else:
            groups.append([(v, name, colour)])
    for g in groups:
        ax.annotate(", ".join(n for _, n, _ in g), (t[-1], g[0][0]), xytext=(4, 0), textcoords="offset points",
                    fontsize=7, color=g[0][2] if len(g) == 1 else "0.3", va="center", annotation_clip=False)


def _on_off_panel(ax, t, rows) -> None:
    """Each on/off (or text) signal on its own row, its name as the row's tick label."""
    ticks = []
    for k, (name, col, s) in enumerate(reversed(rows)):
        base = 1.5 * k
        if s["type"] == "enum":
            values = [str(v) for v in col]
            y = np.array([0.0 if not v else 1.0 for v in values])
            changes = [i for i in range(len(values)) if i == 0 or values[i] != values[i - 1]]
            for i in changes:
                if values[i]:
                    ax.annotate(values[i], (t[i], base + 1.0), fontsize=7, va="bottom")
        else:
            y = np.asarray(col, dtype=float)
        ax.fill_between(t, base, base + y, step="post", alpha=0.35)
        ax.plot(t, base + y, drawstyle="steps-post", lw=1.2)
        ticks.append((base + 0.5, name))
    ax.set_yticks([p for p, _ in ticks], [n for _, n in ticks], fontsize=8)
    ax.set_ylim(-0.3, 1.5 * len(rows))
    ax.grid(True, axis="x", alpha=0.3)


def cmd_plot(args) -> int:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise TwinError("twin plot needs matplotlib: pip install 'gripper-twin[view]'") from None
    rec = Recording.open(args.file)
    out = plot_recording(rec, args.signals or None, args.output, threshold=args.threshold)
    print(out)
    return 0
