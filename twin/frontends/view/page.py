"""The page: a viser server drawing a `Scene` and showing `Frame`s, with a signal panel and run controls.

What it draws, from the scene: every visual of every body (boxes, cylinders, spheres, capsules, meshes
loaded with trimesh; the station's colours), the floor as a grid, the robot's named targets as small
axes, the targets (parts) and fixtures. Per frame: every body where the frame puts it, the gripped part
in a highlight colour, per finger a marker at its tip (red while it touches a part) and an arrow along its
joint axis whose length is the finger's force (the direction the servo pushes in), and a translucent
ghost of each finger where its setpoints would put it.

The panel: the simulation's state (time, step, mode, speed; the buttons the `Controls` allow), the
inputs (a checkbox per bool; a number per analogue input, in engineering units, set with Enter; a value
the twin refuses is not sent and the twin's own message is shown), and a table of every signal's live
value (element id `signal-table`, one row per signal with `data-signal="NAME"` on its value cell).
The page knows the twin only through `Controls`: it never steps the twin or calls pybullet.
"""
from __future__ import annotations

import html
import math
import threading
import time
from typing import Protocol

import numpy as np

from twin.core.signals import ENGINEERING_UNITS as ENGINEERING  # as the Modbus map and the PLC see them
from twin.observe.scene import Frame, Scene, matrix_to_quat, pose_matrix, setpoint_motion

HIGHLIGHT = (40, 220, 90)  # the gripped part
CONTACT, NO_CONTACT = (230, 30, 30), (120, 120, 120)
FORCE_COLOUR = (250, 200, 0)
GHOST_OPACITY = 0.3
TABLE_HZ = 10.0  # the signal table's refresh rate (the 3D scene and the state line follow every frame)


def engineering(signal: dict) -> tuple[str, float]:
    """(unit, factor): SI value * factor = the value in the unit shown (mm, deg; others as they are)."""
    return ENGINEERING.get(signal.get("unit") or "", (signal.get("unit") or "", 1.0))


def format_value(signal: dict, value) -> str:
    if signal["type"] == "bool":
        return "1" if value else "0"
    if signal["type"] == "enum":
        return str(value) if value else "(none)"
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    unit, factor = engineering(signal)
    if signal["type"] == "int":
        return f"{int(value)}"
    v = float(value) * factor
    return f"{v:.2f} {unit}".rstrip() if unit else f"{v:.4g}"


class Controls(Protocol):
    """What the page may ask of whatever runs the twin (live) or plays the recording (replay)."""

    mode: str  # "realtime", "lockstep" or "replay"

    def state(self) -> dict: ...  # time, step, speed, paused, late_steps (as known)

    def write(self, name: str, value) -> str | None: ...  # SI value; None when accepted, else the refusal

    def buttons(self) -> tuple[str, ...]: ...  # which of "pause", "run", "step", "advance" apply now

    def press(self, button: str) -> None: ...


def _rgb(rgba) -> tuple[int, int, int]:
    return tuple(int(round(max(0.0, min(1.0, c)) * 255)) for c in rgba[:3])  # type: ignore[return-value]


def _wxyz(q) -> tuple[float, float, float, float]:
    return (float(q[3]), float(q[0]), float(q[1]), float(q[2]))


def _node(key: str) -> str:
    return key.replace("/", "__").replace(" ", "_")


class CellPage:
    """A viser server showing one cell. `show(frame)` from any thread; `close()` stops the server."""

    def __init__(self, scene: Scene, controls: Controls, *, host: str = "127.0.0.1", port: int = 8080,
                 title: str | None = None, fps: float = 25.0):
        import viser

        self.scene, self.controls, self.fps = scene, controls, fps
        self.server = viser.ViserServer(host=host, port=port, label=title or f"gripper-twin: {scene.station}", verbose=False)
        self.port = self.server.get_port()
        self.host = host
        self._lock = threading.Lock()
        self._signals = {s["name"]: s for s in scene.signals}
        self._shown_inputs: dict[str, object] = {}
        self._last_step: int | None = None
        self._last_table = ""
        self._last_state = ""
        self._last_buttons: tuple[str, ...] = ()
        self._body_index = {b: k for k, b in enumerate(scene.bodies)}
        self._setting = False
        self.frames_shown = 0
        self._sent: dict = {}  # what each scene node last got (no message for what did not change)
        self._table_due = 0.0  # the signal table and the inputs: at most TABLE_HZ times a second
        self._unseen: Frame | None = None
        self._build_scene()
        self._build_panel()

        @self.server.on_client_connect
        def _(client) -> None:
            frame, self._unseen = self._unseen, None
            if frame is not None:
                self._table_due = 0.0
                self.show(frame, force=True)

    # -- the 3D scene ---------------------------------------------------------------------------------------
    def _build_scene(self) -> None:
        sc, scene = self.server.scene, self.scene
        sc.set_up_direction("+z")
        # plain lights, no environment map, fog or shadows: cheap enough for software WebGL (no GPU)
        sc.configure_environment_map(None)
        sc.configure_default_lights(True, cast_shadow=False)
        sc.configure_fog(0.0, 1.0, enabled=False)
        self._frames = {}
        self._meshes: dict[str, list] = {}
        for key in scene.bodies:
            self._frames[key] = sc.add_frame(f"/cell/{_node(key)}", show_axes=False)
        for k, v in enumerate(scene.visuals):
            h = self._add_visual(f"/cell/{_node(v.body)}/v{k}", v)
            if h is not None:
                self._meshes.setdefault(v.body, []).append((h, _rgb(v.rgba)))
        # ghosts: the finger's visuals again, translucent, placed where the setpoints would put them
        self._ghosts = {}
        for f in scene.fingers:
            parts = []
            for link in f.links:
                if link not in self._body_index:
                    continue
                frame = sc.add_frame(f"/ghost/{_node(f.name)}/{_node(link)}", show_axes=False)
                for k, v in enumerate(x for x in scene.visuals if x.body == link):
                    self._add_visual(f"/ghost/{_node(f.name)}/{_node(link)}/v{k}", v, opacity=GHOST_OPACITY,
                                     colour=(120, 170, 255))
                parts.append((link, frame))
            self._ghosts[f.name] = parts
        self._markers, self._arrows = {}, {}
        finger_links = {link for f in scene.fingers for link in f.links}
        sizes = [max(v.size) if v.shape != "mesh" else 0.1 for v in scene.visuals if v.body in finger_links and v.size]
        self.arrow_length = 1.5 * max(sizes + [0.015])  # the strongest finger's force arrow: 1.5 finger lengths
        a = self.arrow_length
        for f in scene.fingers:
            self._markers[f.name] = sc.add_icosphere(f"/fingers/{_node(f.name)}/contact", radius=0.06 * a,
                                                     color=NO_CONTACT, cast_shadow=False, receive_shadow=False)
            self._arrows[f.name] = sc.add_arrows(f"/fingers/{_node(f.name)}/force", np.zeros((1, 2, 3), np.float32),
                                                 FORCE_COLOUR, shaft_radius=0.02 * a, head_radius=0.05 * a,
                                                 head_length=0.12 * a, visible=False)
        for name, pose in scene.robot_targets.items():
            sc.add_frame(f"/robot_targets/{_node(name)}", axes_length=0.08, axes_radius=0.004,
                         position=tuple(pose[:3]), wxyz=_wxyz(pose[3:7]))
            sc.add_label(f"/robot_targets/{_node(name)}/label", name, position=(0.0, 0.0, 0.03), font_screen_scale=0.7)
        # a camera that sees the whole cell
        lo, hi = self._extent()
        centre = (lo + hi) / 2
        span = float(max(np.max(hi - lo), 0.3))
        self.server.initial_camera.look_at = tuple(float(c) for c in centre)
        self.server.initial_camera.position = (float(centre[0] + 1.3 * span), float(centre[1] - 1.3 * span),
                                               float(centre[2] + 0.9 * span))
        self.server.initial_camera.up = (0.0, 0.0, 1.0)
        self._finger_tips = self._tip_offsets()

    def _extent(self):
        pts = []
        for v in self.scene.visuals:
            if v.shape != "plane":
                pts.append(v.position)
        pts += [p[:3] for p in self.scene.robot_targets.values()]
        if not pts:
            return np.zeros(3) - 0.5, np.zeros(3) + 0.5
        a = np.array(pts, dtype=float)
        return a.min(axis=0) - 0.2, a.max(axis=0) + 0.2

    def _add_visual(self, name: str, v, *, opacity: float | None = None, colour=None):
        sc = self.server.scene
        colour = colour or _rgb(v.rgba)
        if opacity is None and v.rgba[3] < 0.999:
            opacity = float(v.rgba[3])
        common = dict(position=tuple(v.position), wxyz=_wxyz(v.orientation), cast_shadow=False, receive_shadow=False)
        if opacity is not None:
            common["opacity"] = opacity
        if v.shape == "box":
            return sc.add_box(name, colour, tuple(v.size), **common)
        if v.shape == "cylinder":
            return sc.add_cylinder(name, radius=v.size[1], height=v.size[0], color=colour, **common)
        if v.shape == "sphere":
            return sc.add_icosphere(name, radius=v.size[0], color=colour, **common)
        if v.shape == "capsule":
            h = sc.add_cylinder(name, radius=v.size[1], height=v.size[0], color=colour, **common)
            for end, z in (("a", v.size[0] / 2), ("b", -v.size[0] / 2)):
                sc.add_icosphere(f"{name}/{end}", radius=v.size[1], color=colour, position=(0.0, 0.0, z),
                                 cast_shadow=False, receive_shadow=False,
                                 **({"opacity": opacity} if opacity is not None else {}))
            return h
        if v.shape == "plane":
            if opacity is not None:  # a ghost of a plane: nothing to show
                return None
            return sc.add_grid(name, width=20.0, height=20.0, cell_size=0.5, section_size=1.0, plane_color=colour,
                               plane_opacity=1.0, shadow_opacity=0.0, position=(0.0, 0.0, -0.001))
        if v.shape == "mesh":
            mesh = _load_mesh(v.mesh)
            if mesh is None:
                return None
            vertices, faces = mesh
            return sc.add_mesh_simple(name, vertices * np.asarray(v.size, dtype=np.float32), faces, color=colour, **common)
        return None

    def _tip_offsets(self) -> dict[str, tuple[str, np.ndarray]]:
        """Per finger: the link and the point in it (the middle of its visuals) where its marker and arrow go."""
        tips = {}
        for f in self.scene.fingers:
            link = f.links[0] if f.links else f.name
            pts = [v.position for v in self.scene.visuals if v.body == link]
            tips[f.name] = (link, np.mean(np.array(pts, dtype=float), axis=0) if pts else np.zeros(3))
        return tips

    # -- the panel ------------------------------------------------------------------------------------------
    def _build_panel(self) -> None:
        gui = self.server.gui
        self._state_md = gui.add_markdown("starting ...")
        with gui.add_folder("Run"):
            self._buttons = {
                "pause": gui.add_button("Pause", visible=False),
                "run": gui.add_button("Run", visible=False),
                "step": gui.add_button("Step", hint="one simulation step", visible=False),
                "advance": gui.add_button("Advance 1 s", hint="lockstep: run one simulated second", visible=False),
            }
        for name, b in self._buttons.items():
            b.on_click(lambda _e, n=name: self.controls.press(n))
        add_widgets = getattr(self.controls, "add_widgets", None)
        if add_widgets is not None:  # e.g. the replay's timeline
            with gui.add_folder("Timeline"):
                add_widgets(gui)
        self._message = gui.add_markdown("")
        self._inputs = {}
        inputs = [s for s in self.scene.signals if s["direction"] == "input"]
        if inputs and self.controls.mode != "replay":
            with gui.add_folder("Inputs"):
                for s in inputs:
                    self._inputs[s["name"]] = self._input_widget(gui, s)
        with gui.add_folder("Signals"):
            self._table = gui.add_html("")

    def _input_widget(self, gui, s: dict):
        name = s["name"]
        unit, factor = engineering(s)
        if s["type"] == "bool":
            h = gui.add_checkbox(name, False, hint=s.get("description") or None)

            @h.on_update
            def _(event, h=h, name=name):
                if not self._setting:
                    self._submit(event, name, bool(h.value))
            return h
        if s["type"] == "enum":
            choices = [c or "(none)" for c in s["choices"]] or ["(none)"]
            h = gui.add_dropdown(name, choices)

            @h.on_update
            def _(event, h=h, name=name):
                if not self._setting:
                    self._submit(event, name, "" if h.value == "(none)" else h.value)
            return h
        rng = ""
        if s.get("min") is not None and s.get("max") is not None:
            rng = f"{s['min'] * factor:g} to {s['max'] * factor:g} {unit}".rstrip()
        label = f"{name} [{unit}]" if unit else name
        with gui.add_form(None) as form:
            h = gui.add_number(label, 0.0, step=0.01 if s["type"] == "float" else 1,
                               hint=f"{s.get('description', '')} Range {rng}. Type a value and press Enter.".strip())

        @form.on_submit
        def _(event, h=h, name=name, factor=factor):
            try:
                value = float(h.value) / factor
            except (TypeError, ValueError):
                self._refuse(event, name, f"signal {name!r}: needs a number, not {h.value!r}")
                return
            if s["type"] == "int" and value == int(value):
                value = int(value)
            self._submit(event, name, value)
        return h

    def _submit(self, event, name: str, value) -> None:
        refusal = self.controls.write(name, value)
        if refusal is None:
            self._message.content = f"set **{name}** = {format_value(self._signals[name], value)}"
            self._shown_inputs[name] = value
        else:
            self._refuse(event, name, refusal)

    def _refuse(self, event, name: str, message: str) -> None:
        self._message.content = f"<span style='color:#c00' id='refusal'>refused: {html.escape(message)}</span>"
        client = getattr(event, "client", None)
        if client is not None:
            client.add_notification("Refused", message, color="red", auto_close_seconds=8.0)
        # put the widget back to the signal's present value
        self._shown_inputs.pop(name, None)
        self._last_step = None
        self._table_due = 0.0

    # -- showing a frame ---------------------------------------------------------------------------------------
    def show(self, frame: Frame, *, force: bool = False) -> None:
        """Bring the page up to `frame` (only what changed is sent)."""
        if not force and not self.server.get_clients():
            self._unseen = frame  # nobody looks: send nothing; a browser that connects gets this frame
            return
        with self._lock:
            state = self.controls.state()
            same = frame.step == self._last_step and not force
            with self.server.atomic():
                if not same:
                    self._show_bodies(frame)
                self._show_panel(frame, state, same)
            self.server.flush()
            self._last_step = frame.step
            self.frames_shown += 1

    def _show_bodies(self, frame: Frame) -> None:
        values = frame.as_signals(self.scene)
        for key, h in self._frames.items():
            p = frame.poses[self._body_index[key]]
            self._place(h, p[:3], p[3:7])
        gripped = values.get("GrippedPart") or ""
        for target in self.scene.targets:
            for h, rgb in self._meshes.get(target, []):
                want = HIGHLIGHT if target == gripped else rgb
                if getattr(h, "color", None) != want:
                    h.color = want
        setpoints = {s["name"]: values[s["name"]] for s in self.scene.signals
                     if s["direction"] == "input" and s["type"] == "float" and s["name"] in values}
        forces = [abs(float(values.get(f"{f.name}.force") or 0.0)) for f in self.scene.fingers]
        scale = self.arrow_length / max(forces + [1.0])  # the strongest finger's arrow is arrow_length long
        for f, force in zip(self.scene.fingers, forces):
            link, offset = self._finger_tips[f.name]
            if link not in self._body_index:
                continue
            T = pose_matrix(frame.poses[self._body_index[link]])
            tip = T[:3, :3] @ offset + T[:3, 3]
            contact = bool(values.get(f"{f.name}.contact"))
            self._place(self._markers[f.name], tip, None)
            colour = CONTACT if contact else NO_CONTACT
            if self._sent.get(("colour", f.name)) != colour:
                self._markers[f.name].color = colour
                self._sent[("colour", f.name)] = colour
            arrow = self._arrows[f.name]
            if force > 1e-6 and f.chain:
                cj = f.chain[0]
                axis = np.asarray(cj.axis, dtype=float)
                axis = T[:3, :3] @ (axis / (np.linalg.norm(axis) or 1.0))
                sign = self._push_sign(f, frame, setpoints)
                end = tip + sign * axis * force * scale
                points = np.array([[tip, end]], dtype=np.float32)
                last = self._sent.get(("arrow", f.name))
                if last is None or not np.array_equal(np.round(last, 4), np.round(points, 4)):
                    arrow.points = points
                    self._sent[("arrow", f.name)] = points
                if not arrow.visible:
                    arrow.visible = True
            elif arrow.visible:
                arrow.visible = False
            G = setpoint_motion(f, self.scene, frame, setpoints)
            for link_key, h in self._ghosts.get(f.name, ()):
                P = G @ pose_matrix(frame.poses[self._body_index[link_key]])
                self._place(h, P[:3, 3], matrix_to_quat(P[:3, :3]))

    def _place(self, handle, position, quat_xyzw) -> None:
        """Move a scene node, sending nothing when it has not moved (most of the cell stands still)."""
        key = id(handle)
        pos = tuple(round(float(c), 6) for c in position)
        rot = None if quat_xyzw is None else tuple(round(float(c), 6) for c in quat_xyzw)
        last = self._sent.get(key)
        if last is not None and last == (pos, rot):
            return
        self._sent[key] = (pos, rot)
        if last is None or last[0] != pos:
            handle.position = pos
        if rot is not None and (last is None or last[1] != rot):
            handle.wxyz = _wxyz(rot)

    def _push_sign(self, f, frame: Frame, setpoints: dict) -> float:
        """+1 when the finger's servo pushes along its joint axis (its setpoint lies ahead), -1 when against."""
        cj = f.chain[0]
        j = self.scene.joints.index(cj.name) if cj.name in self.scene.joints else None
        if j is None or cj.input not in setpoints:
            return 1.0
        want = cj.multiplier * float(setpoints[cj.input]) + cj.offset
        return 1.0 if want >= float(frame.joints[j]) else -1.0

    def _show_panel(self, frame: Frame, state: dict, same: bool) -> None:
        mode = {"realtime": f"real time x{state.get('speed', 1.0):g}", "lockstep": "lockstep",
                "replay": "replay"}.get(self.controls.mode, self.controls.mode)
        run = "paused" if state.get("paused") else ("running" if self.controls.mode == "realtime" else "")
        text = (f"<span id='sim-state'><b>t = {frame.time:.3f} s</b> &nbsp; step {frame.step} &nbsp; mode: {mode}"
                + (f" &nbsp; {run}" if run else "")
                + (f" &nbsp; late steps: {state['late_steps']}" if state.get("late_steps") else "")
                + (" &nbsp; <b>FAULT</b>" if state.get("fault") else "") + "</span>")
        if text != self._last_state:
            self._state_md.content = text
            self._last_state = text
        buttons = self.controls.buttons()
        if buttons != self._last_buttons:
            for name, b in self._buttons.items():
                b.visible = name in buttons
            self._last_buttons = buttons
        now = time.perf_counter()
        if same or now < self._table_due:
            return
        self._table_due = now + 1.0 / TABLE_HZ
        values = frame.as_signals(self.scene)
        rows = []
        for s in self.scene.signals:
            v = values.get(s["name"])
            unit, factor = engineering(s)
            rng = ""
            if s.get("min") is not None and s.get("max") is not None and s["type"] in ("float", "int"):
                rng = f"{s['min'] * factor:g}..{s['max'] * factor:g}"
            rows.append(f"<tr><td>{html.escape(s['name'])}</td>"
                        f"<td data-signal=\"{html.escape(s['name'])}\" style='text-align:right'>{html.escape(format_value(s, v))}</td>"
                        f"<td>{'in' if s['direction'] == 'input' else 'out'}</td><td>{rng}</td></tr>")
        table = ("<table id='signal-table' style='font-size:0.75em;width:100%;border-collapse:collapse'>"
                 "<tr><th align=left>signal</th><th align=right>value</th><th>dir</th><th>range</th></tr>"
                 + "".join(rows) + "</table>")
        if table != self._last_table:
            self._table.content = table
            self._last_table = table
        self._setting = True
        try:
            for name, h in self._inputs.items():
                v = values.get(name)
                if self._shown_inputs.get(name, object()) == v:
                    continue
                s = self._signals[name]
                if s["type"] == "bool":
                    h.value = bool(v)
                elif s["type"] == "enum":
                    h.value = v or "(none)"
                else:
                    unit, factor = engineering(s)
                    h.value = round(float(v) * factor, 6) if v is not None else 0.0
                self._shown_inputs[name] = v
        finally:
            self._setting = False

    def close(self) -> None:
        try:
            self.server.stop()
        except Exception:  # noqa: BLE001 - stopping a server that failed half-way
            pass


_MESHES: dict[str, tuple | None] = {}


def _load_mesh(path: str):
    """(vertices float32, faces uint32) of a mesh file, or None (with one warning) when it cannot be read."""
    if path in _MESHES:
        return _MESHES[path]
    result = None
    try:
        import trimesh

        loaded = trimesh.load(path, force="mesh")
        result = (np.asarray(loaded.vertices, dtype=np.float32), np.asarray(loaded.faces, dtype=np.uint32))
    except Exception as exc:  # noqa: BLE001 - any reader failure: draw the rest of the cell
        import sys

        print(f"twin view: warning: mesh {path} not drawn: {exc}", file=sys.stderr)
    _MESHES[path] = result
    return result


class FrameLoop:
    """Calls `page.show(source())` `fps` times a second in a thread, until stopped."""

    def __init__(self, page: CellPage, source, *, fps: float = 25.0, before=None):
        self.page, self.source, self.period, self.before = page, source, 1.0 / fps, before
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="view-frames", daemon=True)

    def start(self) -> "FrameLoop":
        self._thread.start()
        return self

    def _run(self) -> None:
        next_t = time.perf_counter()
        while not self._stop.is_set():
            if self.before is not None:
                self.before()
            try:
                self.page.show(self.source())
            except Exception as exc:  # noqa: BLE001 - a page error must not stop the simulation
                import sys

                print(f"twin view: page update failed: {type(exc).__name__}: {exc}", file=sys.stderr)
                self._stop.wait(1.0)
            next_t += self.period
            delay = next_t - time.perf_counter()
            if delay < 0:
                next_t = time.perf_counter()
                delay = 0
            self._stop.wait(delay)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
