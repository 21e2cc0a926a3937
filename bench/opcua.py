"""OPC UA benchmark: `twin serve --opcua` against Modbus on the same cell, in one run.

    python -m bench opcua [--station DIR] [--requests N] [--items 1000] [--seconds S]

One `twin serve STATION --opcua 0 --port 0` process runs the cell in real time (the station's step, 12 ms
on the ring rig), serving both protocols from the same runner. The bench process is the client of both
(asyncua's client and pymodbus's async client, one request at a time), so latencies include a Python
client library on each side. While measuring, the bench swings the finger setpoints between 330 and
350 mm every 0.6 s (no contact), so about a third of the signals change every step. Measured:

- read latency: one signal (L2.actual), and every signal (one OPC UA Read of all variables; Modbus: the
  input registers and discrete inputs, two requests): p50 and p99;
- write latency: one setpoint (L5), accepted: p50 and p99;
- delay from a write to the client seeing its effect one step later (`ring.present` written, the ring's
  `ring.z` observed): OPC UA by a subscription (12 ms publishing and sampling), Modbus by polling every
  12 ms like a PLC scan; and, OPC UA only, from a value's source timestamp to its notification's arrival;
- load: N monitored items (default 1000, spread over all variables, 12 ms sampling and publishing, in a
  second client process) for S seconds, against the same S seconds without them: steps run, steps late
  (finished after their wall-clock deadline, from the server's own sim.late_steps), the real-time factor
  (simulated time / wall time over the window), the CPU time per step of the simulation's process and of
  the OPC UA server's process, and the read latency of
  one signal on each protocol meanwhile (one read every 20 ms). The last line says whether the simulation
  kept real time with the items: a real-time factor of at least 0.99 and at most 1 % of the steps late.

The OPC UA server runs in a process of its own (`twin.frontends.opcua.cell_link`): its reads do not wait for steps.
"""
from __future__ import annotations

import argparse
import asyncio
import os
import re
import subprocess
import sys
import threading
import time
from datetime import datetime, timezone
from pathlib import Path

from bench.modbus_latency import Server

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_STATION = ROOT / "stations" / "ring_rig"
UNIT = 1


class TwinServer(Server):
    """`twin serve STATION --opcua 0 --port 0` in real time; its Modbus port and OPC UA endpoint from its events
    (started here; stopped as bench modbus stops its servers)."""

    def __init__(self, station: Path):
        cert_dir = ROOT / ".pytest_cache" / "bench-opcua-certs"
        super().__init__([sys.executable, "-m", "twin", "serve", str(station), "--port", "0", "--opcua", "0",
                          "--opcua-cert-dir", str(cert_dir)], port_from_events=True)
        self.url = self.events.endpoint("opcua")["url"]

    def cpu_seconds(self) -> float:
        """User + system CPU time of the server process so far (Linux /proc)."""
        return _cpu(self.proc.pid)

    def front_end_cpu_seconds(self) -> float:
        """The same, of the front ends' processes (`twin.frontends.process`: here the OPC UA server's)."""
        total = 0.0
        for task in Path(f"/proc/{self.proc.pid}/task").iterdir():
            for pid in (task / "children").read_text().split():
                try:
                    if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes():
                        total += _cpu(int(pid))
                except OSError:
                    pass
        return total


def _cpu(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")



def pct(values: list[float], q: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(round(q / 100 * (len(s) - 1))))]


async def timed(fn, n: int) -> list[float]:
    out = []
    for i in range(n):
        t0 = time.perf_counter()
        await fn(i)
        out.append((time.perf_counter() - t0) * 1000)
    return out


# -- the measurements -----------------------------------------------------------------------------------------
class Bench:
    def __init__(self, server: TwinServer, station: str, rmap):
        self.server, self.station, self.rmap = server, station, rmap

    async def connect(self):
        from asyncua import Client
        from pymodbus.client import AsyncModbusTcpClient

        # a keep-alive probe of 10 s, not asyncua's 1 s: on a loaded machine a late answer is measured (the read
        # latencies below), not turned into a reconnection
        self.ua = Client(self.server.url, timeout=30, watchdog_intervall=10)
        await self.ua.connect()
        self.ns = await self.ua.get_namespace_index(f"urn:gripper-twin:station:{self.station}")
        self.mb = AsyncModbusTcpClient("127.0.0.1", port=self.server.port, timeout=5, retries=0)
        await self.mb.connect()

    async def close(self):
        await self.ua.disconnect()
        self.mb.close()

    def node(self, name: str):
        from asyncua import ua

        return self.ua.get_node(ua.NodeId(name, self.ns))

    async def mb_read(self, name: str):
        e = self.rmap[name]
        read = {"coil": self.mb.read_coils, "discrete_input": self.mb.read_discrete_inputs,
                "holding_register": self.mb.read_holding_registers, "input_register": self.mb.read_input_registers}[e.table]
        r = await read(e.address, count=e.count, device_id=UNIT)
        assert not r.isError(), r
        return e.decode(r.bits[:1] if e.table in ("coil", "discrete_input") else r.registers)

    async def swing_fingers(self, stop: asyncio.Event):
        """Keep the cell busy: finger setpoints between 330 and 350 mm every 0.6 s (over OPC UA)."""
        from asyncua import ua

        nodes = [self.node(n) for n in ("L2", "L3", "L4") if n in self.rmap]
        k = 0
        while not stop.is_set():
            value = 0.33 if k % 2 == 0 else 0.35
            for n in nodes:
                await n.write_value(ua.DataValue(ua.Variant(value, ua.VariantType.Double)))
            k += 1
            try:
                await asyncio.wait_for(stop.wait(), 0.6)
            except asyncio.TimeoutError:
                pass

    async def latencies(self, n: int) -> dict[str, tuple[list[float], list[float]]]:
        from asyncua import ua

        out = {}
        actual = self.node("L2.actual")
        out["read one signal (L2.actual)"] = (await timed(lambda i: actual.read_value(), n),
                                              await timed(lambda i: self.mb_read("L2.actual"), n))
        names = [e.name for e in self.rmap if e.name not in ("sim.advance", "sim.map_crc")]
        nodes = [self.node(x) for x in names]
        di = [e for e in self.rmap if e.table == "discrete_input" and e.address >= 16]
        ir = [e for e in self.rmap if e.table == "input_register" and e.address >= 16]
        di_end, ir_end = max(e.end for e in di), max(e.end for e in ir)

        async def mb_all(i):
            a = await self.mb.read_discrete_inputs(16, count=di_end - 16, device_id=UNIT)  # the station's, after
            b = await self.mb.read_input_registers(16, count=min(ir_end - 16, 125), device_id=UNIT)  # the sim block
            assert not a.isError() and not b.isError()

        out[f"read every output ({len(names)} OPC UA / {len(di) + len(ir)} Modbus)"] = (
            await timed(lambda i: self.ua.read_values(nodes), n), await timed(mb_all, n))
        L5 = self.node("L5")
        lo, hi = self.rmap["L5"].min / 1000, self.rmap["L5"].max / 1000  # map range in mm -> m
        values = (lo + 0.25 * (hi - lo), lo + 0.75 * (hi - lo))
        e = self.rmap["L5"]

        async def ua_write(i):
            await L5.write_value(ua.DataValue(ua.Variant(values[i % 2], ua.VariantType.Double)))

        async def mb_write(i):
            r = await self.mb.write_registers(e.address, e.encode(values[i % 2]), device_id=UNIT)
            assert not r.isError(), r

        out["write one setpoint (L5)"] = (await timed(ua_write, n), await timed(mb_write, n))
        return out

    async def change_delays(self, n: int) -> tuple[list[float], list[float], list[float]]:
        """Write ring.present, see ring.z change: by subscription (OPC UA), by 12 ms polling (Modbus)."""
        from asyncua import ua

        seen = asyncio.Queue()
        source_delay: list[float] = []

        class Handler:
            def datachange_notification(self, node, val, data):
                now = datetime.now(timezone.utc)
                ts = data.monitored_item.Value.SourceTimestamp
                if ts is not None:
                    source_delay.append((now - ts.replace(tzinfo=timezone.utc)).total_seconds() * 1000)
                seen.put_nowait((time.perf_counter(), val))

        sub = await self.ua.create_subscription(12, Handler())
        z = self.node("ring.z")
        await sub.subscribe_data_change([z], sampling_interval=12)
        await asyncio.sleep(0.3)
        while not seen.empty():
            seen.get_nowait()
        source_delay.clear()
        present = self.node("ring.present")
        ua_delays = []
        for i in range(n):
            want_low = i % 2 == 0  # taken away: z far below the cell
            t0 = time.perf_counter()
            await present.write_value(ua.DataValue(ua.Variant(not want_low, ua.VariantType.Boolean)))
            while True:
                t, val = await asyncio.wait_for(seen.get(), 5)
                if (val < -1) == want_low:
                    ua_delays.append((t - t0) * 1000)
                    break
            await asyncio.sleep(0.05)
        await sub.delete()
        e = self.rmap["ring.present"]
        mb_delays = []
        for i in range(n):
            want_low = i % 2 == 0
            t0 = time.perf_counter()
            r = await self.mb.write_coil(e.address, not want_low, device_id=UNIT)
            assert not r.isError()
            while True:
                if ((await self.mb_read("ring.z")) < -1) == want_low:
                    mb_delays.append((time.perf_counter() - t0) * 1000)
                    break
                await asyncio.sleep(0.012)  # a PLC scan of 12 ms
            await asyncio.sleep(0.05)
        return ua_delays, mb_delays, source_delay

    async def step_counters(self) -> tuple[int, int, float, float]:
        """sim.step, sim.late_steps, simulated time (s) and the wall clock (s) when they were read."""
        t = time.perf_counter()
        step, late, ms = [int(await self.mb_read(n)) for n in ("sim.step", "sim.late_steps", "sim.time_ms")]
        return step, late, ms / 1000, t

    async def load_window(self, seconds: float) -> dict:
        """Over `seconds`: steps run and late, the real-time factor, server CPU seconds, and read latencies
        of one signal on each protocol (a read every 20 ms, taking turns)."""
        s0, l0, sim0, t0 = await self.step_counters()
        c0, f0 = self.server.cpu_seconds(), self.server.front_end_cpu_seconds()
        actual = self.node("L2.actual")
        ua_ms, mb_ms = [], []
        end = time.perf_counter() + seconds
        while time.perf_counter() < end:
            t = time.perf_counter()
            await actual.read_value()
            ua_ms.append((time.perf_counter() - t) * 1000)
            await asyncio.sleep(0.01)
            t = time.perf_counter()
            await self.mb_read("L2.actual")
            mb_ms.append((time.perf_counter() - t) * 1000)
            await asyncio.sleep(0.01)
        s1, l1, sim1, t1 = await self.step_counters()
        return {"steps": s1 - s0, "late": l1 - l0, "x": (sim1 - sim0) / (t1 - t0),
                "cpu": self.server.cpu_seconds() - c0, "ua_cpu": self.server.front_end_cpu_seconds() - f0,
                "ua": ua_ms, "mb": mb_ms}


async def subscriber(url: str, station: str, items: int, seconds: float) -> None:
    """A second client process: `items` monitored items over every variable, 12 ms; prints notifications seen.

    It runs niced: on a shared 2-core machine, a Python client decoding tens of thousands of notifications a
    second would otherwise take the core the server needs (a PLC or SCADA client runs elsewhere)."""
    from asyncua import Client, ua

    try:
        os.nice(15)
    except OSError:
        pass

    count = 0

    class Handler:
        def datachange_notification(self, node, val, data):
            nonlocal count
            count += 1

    async with Client(url, timeout=60, watchdog_intervall=10) as c:
        ns = await c.get_namespace_index(f"urn:gripper-twin:station:{station}")
        folders = [c.get_node(ua.NodeId(f, ns)) for f in ("Gripper", "Fingers", "Robot", "Targets", "Controller", "Sim")]
        variables = []
        for f in folders:
            variables += await f.get_children(nodeclassmask=ua.NodeClass.Variable)
        sub = await c.create_subscription(12, Handler())
        nodes = [variables[i % len(variables)] for i in range(items)]
        for k in range(0, items, 250):
            await sub.subscribe_data_change(nodes[k:k + 250], sampling_interval=12)
        print("subscribed", flush=True)
        await asyncio.sleep(seconds)
        print(f"notifications {count}", flush=True)


def row(label: str, ua_ms: list[float], mb_ms: list[float] | None) -> str:
    def cell(v):
        return f"{pct(v, 50):7.2f} {pct(v, 99):7.2f}" if v else f"{'-':>7} {'-':>7}"

    ratio = f"{pct(ua_ms, 50) / pct(mb_ms, 50):5.2f}x" if mb_ms else "     "
    return f"{label:<44} {cell(ua_ms)}   {cell(mb_ms)}   {ratio}"


async def run(args) -> int:
    from twin.frontends.modbus.register_map import build_map

    rmap = build_map(args.station)
    station = rmap.station
    server = TwinServer(Path(args.station))
    try:
        b = Bench(server, station, rmap)
        await b.connect()
        stop = asyncio.Event()
        swing = asyncio.ensure_future(b.swing_fingers(stop))
        lat = await b.latencies(args.requests)
        ua_d, mb_d, src_d = await b.change_delays(args.changes)
        step_ms = (await b.mb_read("sim.dt_us")) / 1000
        print(f"station {station}, real time, step {step_ms:g} ms; {args.requests} requests each, one at a time (ms)")
        print(f"{'':<44} {'OPC UA':>15}   {'Modbus':>15}   OPC UA/")
        print(f"{'':<44} {'p50':>7} {'p99':>7}   {'p50':>7} {'p99':>7}   Modbus p50")
        for label, (u, m) in lat.items():
            print(row(label, u, m))
        print(row("write -> effect seen (subscription / 12 ms poll)", ua_d, mb_d))
        print(row("source timestamp -> notification received", src_d, None))
        # load: the same seconds without and with N monitored items
        base = await b.load_window(args.seconds)
        proc = subprocess.Popen([sys.executable, "-m", "bench", "opcua", "--subscriber", server.url, station,
                                 str(args.items), str(args.seconds + 2)], stdout=subprocess.PIPE, text=True, cwd=ROOT)
        loop = asyncio.get_running_loop()
        line = await loop.run_in_executor(None, proc.stdout.readline)
        if "subscribed" not in line:
            raise RuntimeError(f"the subscriber did not start: {line!r}")
        await asyncio.sleep(1.0)
        loaded = await b.load_window(args.seconds)
        line = await loop.run_in_executor(None, proc.stdout.readline)  # "notifications N" after its seconds
        received = int(line.split()[1]) if line.startswith("notifications") else None
        proc.wait()
        stop.set()
        await swing
        await b.close()
        print()
        print(f"load, {args.seconds:g} s each, fingers swinging (server process); read latency of L2.actual meanwhile (ms)")
        print(f"{'':<36} {'steps':>6} {'late':>5} {'late %':>7} {'x real':>7} {'CPU ms':>7} {'OPC UA':>7}   "
              f"{'OPC UA read':>13}   {'Modbus read':>13}")
        print(f"{'':<36} {'':>6} {'':>5} {'':>7} {'time':>7} {'/step':>7} {'ms/step':>7}   {'p50':>6} {'p99':>6}   "
              f"{'p50':>6} {'p99':>6}")
        for label, w in (("no monitored items", base), (f"{args.items} monitored items, 12 ms", loaded)):
            print(f"{label:<36} {w['steps']:6d} {w['late']:5d} {100 * w['late'] / max(1, w['steps']):6.2f}% "
                  f"{w['x']:7.3f} {1000 * w['cpu'] / max(1, w['steps']):7.2f} "
                  f"{1000 * w['ua_cpu'] / max(1, w['steps']):7.2f}   "
                  f"{pct(w['ua'], 50):6.2f} {pct(w['ua'], 99):6.2f}   {pct(w['mb'], 50):6.2f} {pct(w['mb'], 99):6.2f}")
        rate = "?" if received is None else f"{received / (args.seconds + 2):.0f}"
        print(f"the subscriber received {rate} notifications/s; CPU ms/step is the simulation's process's (budget: "
              f"the step, {step_ms:g} ms), OPC UA ms/step its OPC UA process's")
        late_pct = 100 * loaded["late"] / max(1, loaded["steps"])
        keeps = loaded["x"] >= 0.99 and late_pct <= 1.0
        print(f"{args.items} monitored items at 12 ms: simulation {'keeps' if keeps else 'does NOT keep'} real time "
              f"(x{loaded['x']:.3f} real time, {loaded['late']} of {loaded['steps']} steps late, {late_pct:.2f} %; "
              f"the target: x >= 0.99, <= 1 % late)")
        return 0
    finally:
        server.stop()


def main(argv: list[str]) -> int:
    if argv[:1] == ["--subscriber"]:
        url, station, items, seconds = argv[1], argv[2], int(argv[3]), float(argv[4])
        asyncio.run(subscriber(url, station, items, seconds))
        return 0
    p = argparse.ArgumentParser(prog="python -m bench opcua", description=__doc__.split("\n\n")[0])
    p.add_argument("--station", default=str(DEFAULT_STATION))
    p.add_argument("--requests", type=int, default=300, help="requests per latency figure (default 300)")
    p.add_argument("--changes", type=int, default=40, help="writes per change-delay figure (default 40)")
    p.add_argument("--items", type=int, default=1000, help="monitored items for the load figure (default 1000)")
    p.add_argument("--seconds", type=float, default=10.0, help="seconds per load window (default 10)")
    args = p.parse_args(argv)
    return asyncio.run(run(args))
