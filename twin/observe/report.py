"""A run's report from its recording: one folder with `index.html`, the signal plot and a picture of the
cell at each grip and release.

    from twin.observe.report import write_report
    write_report("run.parquet", "report/", threshold=200.0, narration=lines)

Grips and releases are read from the recording itself (`doGripped` rising and falling), so the report
shows what the twin did, whoever drove it. Each picture is the recorded moment rendered headless
(`twin.observe.picture`), the held part in a highlight colour; its caption gives the time, the part and each
finger's position and force. Needs matplotlib (the [view] extra).
"""
from __future__ import annotations

import html
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .recording import Recording


@dataclass
class Event:
    kind: str  # "grip" or "release"
    index: int  # the recording's row
    time: float
    part: str


def grip_events(rec: Recording) -> list[Event]:
    """Every grip (doGripped rising) and release (falling), in time order."""
    if "doGripped" not in rec.signal_names:
        return []
    held = np.asarray(rec.column("doGripped"), dtype=bool)
    parts = rec.column("GrippedPart") if "GrippedPart" in rec.signal_names else None
    events = []
    for i in range(1, len(held)):
        if held[i] != held[i - 1]:
            kind = "grip" if held[i] else "release"
            part = str(parts[i] if held[i] else parts[i - 1]) if parts is not None else ""
            events.append(Event(kind, i, float(rec.time[i]), part))
    return events


def _caption(rec: Recording, ev: Event, n: int, events: list[Event]) -> str:
    """What happened: time, part, each finger's axis positions; for a grip, each finger's peak force while held."""
    frame = rec.frame(ev.index).as_signals(rec.scene)
    spec = {s["name"]: s for s in rec.scene.signals}
    later = [e.index for e in events if e.index > ev.index]
    held = slice(ev.index, later[0] if later else len(rec))
    fingers = []
    for f in rec.scene.fingers:
        axes = []
        for cj in reversed(f.chain):  # from the base out: a carriage, then the finger's own axis
            v = frame.get(f"{cj.input}.actual")
            if v is not None:
                unit = spec[f"{cj.input}.actual"].get("unit")
                axes.append(f"{cj.input} {v * 1000:.1f} mm" if unit == "m" else f"{cj.input} {np.degrees(v):.1f} deg")
        text = f"{f.name}: " + " + ".join(axes) if axes else f.name
        if ev.kind == "grip" and f"{f.name}.force" in spec:
            peak = float(np.max(np.asarray(rec.column(f"{f.name}.force")[held], dtype=float)))
            text += f", up to {peak:.0f} {spec[f'{f.name}.force'].get('unit') or 'N'} while held"
        fingers.append(text)
    what = f"{ev.kind} {n}" + (f" of {ev.part}" if ev.part else "")
    return f"{what} at t = {ev.time:.3f} s (step {int(rec.steps[ev.index])}). " + "; ".join(fingers)


def write_report(recording: str | Path, out_dir: str | Path, *, threshold: float | None = None,
                 narration: list[str] | tuple[str, ...] = (), title: str | None = None,
                 width: int = 800, height: int = 600) -> Path:
    """Write the report of `recording` into `out_dir`; returns the path of its index.html."""
    from .picture import RecordingCamera, save_png
    from .plot import plot_recording

    rec = Recording.open(recording)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    plot = plot_recording(rec, None, out / "signals.png", threshold=threshold,
                          title=f"{rec.scene.station}: the cycle's signals")
    events = grip_events(rec)
    pictures = []
    counts = {"grip": 0, "release": 0}
    with RecordingCamera(rec) as cam:
        save_png(cam.picture(float(rec.time[0]), width=width, height=height), out / "cell_start.png")
        for ev in events:
            counts[ev.kind] += 1
            n = counts[ev.kind]
            name = f"{ev.kind}_{n}.png"
            focus = ev.part if ev.part in rec.scene.bodies else None
            img = cam.picture(ev.time, width=width, height=height, focus=focus)
            save_png(img, out / name)
            pictures.append((name, _caption(rec, ev, n, events)))
    title = title or f"gripper-twin report: {rec.scene.station}"
    figs = "\n".join(f"<figure><img src='{html.escape(n)}' width='{width // 2}'><figcaption>{html.escape(c)}</figcaption></figure>"
                     for n, c in pictures) or "<p>No grip or release in this recording.</p>"
    story = ("<h2>What happened</h2><pre>" + html.escape("\n".join(narration)) + "</pre>") if narration else ""
    page = f"""<!doctype html>
<html><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body{{font-family:sans-serif;max-width:1200px;margin:1em auto;padding:0 1em}}
figure{{display:inline-block;margin:0.5em;vertical-align:top;max-width:{width // 2 + 10}px}}
figcaption{{font-size:0.8em}} pre{{background:#f4f4f4;padding:0.6em;font-size:0.8em;overflow-x:auto}}</style></head>
<body><h1>{html.escape(title)}</h1>
<p>Recording <code>{html.escape(str(Path(recording)))}</code>: {len(rec)} steps of {rec.scene.dt * 1000:g} ms,
{rec.time[-1]:.3f} s simulated; {counts['grip']} grip(s), {counts['release']} release(s).
Replay it with <code>twin view --replay {html.escape(str(Path(recording)))}</code>.</p>
<h2>Signals</h2><img src="{plot.name}" style="max-width:100%">
<h2>The cell at each grip and release</h2>
<figure><img src='cell_start.png' width='{width // 2}'><figcaption>the cell at the start</figcaption></figure>
{figs}
{story}
</body></html>
"""
    index = out / "index.html"
    index.write_text(page, encoding="utf-8")
    return index
