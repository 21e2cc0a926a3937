"""Modbus benchmark: `twin serve` (simulation running in real time) against a bare pymodbus server.

    python -m bench modbus [--requests N] [--seconds S] [--clients C] [--station DIR] [--flood N] [--flood-seconds S]

Both servers run in their own process on loopback; the client side is one process with minimal raw
sockets (so the figures are the servers', not a client library's). Measured in one run, side by side:

- round-trip latency of one register read (FC 4, all the station's input registers from GrippedPart
  on: 41 on the ring rig; the same addresses on both), one request at a time on one connection: p50 and p99;
- throughput: requests per second with 1 client, then with C clients (default 10) each polling
  request-after-response over its own connection;
- for `twin serve`: how many simulation steps were late (finished after their wall-clock deadline)
  while the C clients polled, from the server's own `sim.step` and `sim.late_steps` registers.

- the flood scenario (`twin serve` only): N connections (default 40, `bench.flood`, in another process)
  pipelining reads flat out for `--flood-seconds` (default 10) while one client polls every 5 ms;
  its latency and the late steps, side by side with the same poller on a quiet server.

The bare server is pymodbus's `ModbusTcpServer` on a `SimDevice` (the datastore that survives v4)
with the same number of coils, discrete inputs, holding and input registers as the station's map.
Targets: twin p50 within 1.5x of the bare server; fewer than 1% of steps late with 10 clients.
"""
from __future__ import annotations

import argparse
import asyncio
import os
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_STATION = ROOT / "stations" / "ring_rig"  # the thesis rig: arm, 3-finger gripper, ring


# -- the servers --------------------------------------------------------------------------------------------
class Server:
    def __init__(self, cmd: list[str], port_from_events: bool, port: int | None = None):
        """`port_from_events`: a `twin serve` command; it gets `--events FILE` and its ports come from `ready`."""
        self.events = None
        if port_from_events:
            from plc_client.events import EventLog

            self._dir = tempfile.TemporaryDirectory(prefix="bench-serve-")
            path = Path(self._dir.name) / "events.jsonl"
            cmd = [*cmd, "--events", str(path)]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                                     env={**os.environ, "PYTHONUNBUFFERED": "1"})
        self.port = port
        self.lines: list[str] = []

        def drain():
            for line in self.proc.stderr:
                self.lines.append(line)

        threading.Thread(target=drain, daemon=True).start()
        if port_from_events:
            self.events = EventLog(path, self.proc)
            ready = self.events.wait("ready", 120)
            if ready is not None:
                self.port = next((f["port"] for f in ready["front_ends"] if f["name"] == "modbus"), None)
        end = time.monotonic() + 30
        while True:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                break
            except (OSError, TypeError):
                if time.monotonic() > end or self.proc.poll() is not None:
                    self.stop()
                    raise RuntimeError("server did not start:\n" + "".join(self.lines))
                time.sleep(0.05)

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_bare_server(port: int, sizes: list[int]) -> None:
    """A bare pymodbus server (SimDevice) with `sizes` = [coils, discrete inputs, holding, input registers]."""
    import logging

    from pymodbus.server import ModbusTcpServer
    from pymodbus.simulator import DataType, SimData, SimDevice

    logging.getLogger("pymodbus").setLevel(logging.ERROR)
    nc, nd, nh, ni = (max(1, n) for n in sizes)
    device = SimDevice(id=1, simdata=([SimData(0, count=nc, values=False, datatype=DataType.BITS)],
                                      [SimData(0, count=nd, values=False, datatype=DataType.BITS)],
                                      [SimData(0, count=nh, values=0, datatype=DataType.REGISTERS)],
                                      [SimData(0, count=ni, values=0, datatype=DataType.REGISTERS)]))

    async def serve():
        await ModbusTcpServer(device, address=("127.0.0.1", port)).serve_forever()

    asyncio.run(serve())


# -- the client side ----------------------------------------------------------------------------------------
def frame(tid: int, fc: int, address: int, count: int) -> bytes:
    return struct.pack(">HHHBBHH", tid, 0, 6, 1, fc, address, count)


class Conn:
    def __init__(self, port: int):
        self.sock = socket.create_connection(("127.0.0.1", port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.tid = 0

    def call(self, fc: int, address: int, count: int) -> bytes:
        self.tid = (self.tid + 1) & 0xFFFF
        self.sock.sendall(frame(self.tid, fc, address, count))
        head = self._exact(7)
        body = self._exact(struct.unpack_from(">H", head, 4)[0] - 1)
        if body[0] & 0x80:
            raise RuntimeError(f"exception {body[1]} for FC {fc} at {address}+{count}")
        return body

    def _exact(self, n: int) -> bytes:
        out = b""
        while len(out) < n:
            chunk = self.sock.recv(n - len(out))
            if not chunk:
                raise ConnectionError("server closed the connection")
            out += chunk
        return out

    def close(self) -> None:
        self.sock.close()


def latency(port: int, address: int, count: int, n: int) -> list[float]:
    c = Conn(port)
    try:
        for _ in range(200):  # warm up
            c.call(4, address, count)
        out = []
        clock = time.perf_counter
        for _ in range(n):
            t0 = clock()
            c.call(4, address, count)
            out.append(clock() - t0)
        return out
    finally:
        c.close()


class _Poller(asyncio.Protocol):
    """One client polling request-after-response, lean (a callback, no coroutine per request)."""

    def __init__(self, request: bytes, until: float, done: asyncio.Future):
        self.request, self.until, self.done = request, until, done
        self.buf = b""
        self.count = 0

    def connection_made(self, transport) -> None:
        self.transport = transport
        transport.get_extra_info("socket").setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        transport.write(self.request)

    def data_received(self, data: bytes) -> None:
        self.buf += data
        while len(self.buf) >= 6:
            n = 6 + struct.unpack_from(">H", self.buf, 4)[0]
            if len(self.buf) < n:
                return
            self.buf = self.buf[n:]
            self.count += 1
            if asyncio.get_running_loop().time() < self.until:
                self.transport.write(self.request)
            else:
                self.transport.close()

    def connection_lost(self, exc) -> None:
        if not self.done.done():
            self.done.set_result(self.count)


def throughput(port: int, address: int, count: int, clients: int, seconds: float) -> float:
    """Requests per second of `clients` connections polling for `seconds`."""

    async def run():
        loop = asyncio.get_running_loop()
        until = loop.time() + seconds
        request = frame(1, 4, address, count)
        dones = []
        t0 = time.perf_counter()
        for _ in range(clients):
            done = loop.create_future()
            await loop.create_connection(lambda d=done: _Poller(request, until, d), "127.0.0.1", port)
            dones.append(done)
        total = sum(await asyncio.gather(*dones))
        return total / (time.perf_counter() - t0)

    return asyncio.run(run())


def poll_phase(port: int, counters, seconds: float, flood: int = 0) -> dict:
    """One client polling every 5 ms for `seconds` (while `flood` connections flood, if any): its latency,
    the steps and late steps meanwhile, the flood's answers."""
    flooder = None
    if flood:
        flooder = subprocess.Popen([sys.executable, "-m", "bench.flood", str(port), str(flood), str(seconds + 1.0)],
                                   stdout=subprocess.PIPE, text=True, cwd=ROOT)
        time.sleep(0.5)
    poller = Conn(port)
    s0, l0 = counters()
    t0 = time.monotonic()
    lat = []
    while time.monotonic() - t0 < seconds:
        t1 = time.perf_counter()
        poller.call(3, 16, 1)
        lat.append(time.perf_counter() - t1)
        time.sleep(0.005)
    s1, l1 = counters()
    wall = time.monotonic() - t0
    poller.close()
    answered = int(flooder.communicate(timeout=60)[0] or 0) if flooder else 0
    return {"p50": percentile(lat, 50) * 1e3, "p99": percentile(lat, 99) * 1e3, "steps": s1 - s0, "late": l1 - l0,
            "wall": wall, "flood_rps": answered / (seconds + 1.0)}


def percentile(values: list[float], p: float) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(round(p / 100 * (len(s) - 1))))]


# -- the run ------------------------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench modbus", description=__doc__.split("\n\n")[0])
    parser.add_argument("--requests", type=int, default=3000, help="requests for the latency figures")
    parser.add_argument("--seconds", type=float, default=5.0, help="duration of each throughput run")
    parser.add_argument("--clients", type=int, default=10)
    parser.add_argument("--station", default=str(DEFAULT_STATION))
    parser.add_argument("--flood", type=int, default=40, help="flooding connections in the flood scenario (0: skip it)")
    parser.add_argument("--flood-seconds", type=float, default=10.0)
    parser.add_argument("--bare-server", nargs=5, type=int, metavar=("PORT", "COILS", "DI", "HR", "IR"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.bare_server:
        run_bare_server(args.bare_server[0], args.bare_server[1:])
        return 0

    from twin.frontends.modbus.register_map import (COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER, LATE_STEPS, STEP,
                                          build_map)

    rmap = build_map(args.station)
    sizes = [rmap.size(t) for t in (COIL, DISCRETE_INPUT, HOLDING_REGISTER, INPUT_REGISTER)]
    address = 16  # the station's input registers (GrippedPart, actual positions, forces)
    count = rmap.size(INPUT_REGISTER) - address
    py = sys.executable
    results: dict[str, dict[str, float]] = {}

    twin = Server([py, "-m", "twin", "serve", args.station, "--port", "0"], port_from_events=True)
    port = free_port()
    try:
        bare = Server([py, "-m", "bench.modbus_latency", "--bare-server", str(port), *map(str, sizes)],
                      port_from_events=False, port=port)
    except Exception:
        twin.stop()
        raise
    servers = {"twin": twin, "bare": bare}
    try:
        # Alternate the two servers in rounds, so a noisy neighbour on the machine hits both alike.
        lat = {k: [] for k in servers}
        rounds = 10
        for _ in range(rounds):
            for k, srv in servers.items():
                lat[k] += latency(srv.port, address, count, args.requests // rounds)
        rps1 = {k: [] for k in servers}
        rpsn = {k: [] for k in servers}
        probe = Conn(twin.port)

        def counters():
            words = struct.unpack(">6H", probe.call(4, rmap[STEP].address, 6)[2:])
            return words[0] << 16 | words[1], words[4] << 16 | words[5]

        assert rmap[LATE_STEPS].address == rmap[STEP].address + 4
        steps = late = 0
        for _ in range(2):
            for k, srv in servers.items():
                rps1[k].append(throughput(srv.port, address, count, 1, args.seconds / 2))
            for k, srv in servers.items():
                s0, l0 = counters() if k == "twin" else (0, 0)
                rpsn[k].append(throughput(srv.port, address, count, args.clients, args.seconds / 2))
                if k == "twin":
                    s1, l1 = counters()
                    steps, late = steps + s1 - s0, late + l1 - l0
        quiet = flooded = None
        if args.flood:
            quiet = poll_phase(twin.port, counters, args.flood_seconds)
            flooded = poll_phase(twin.port, counters, args.flood_seconds, args.flood)
        probe.close()
        for k in servers:
            results[k] = {"p50": percentile(lat[k], 50) * 1e6, "p99": percentile(lat[k], 99) * 1e6,
                          "rps1": statistics.mean(rps1[k]), "rpsN": statistics.mean(rpsn[k])}
        results["twin"].update(steps=steps, late=late)
    finally:
        twin.stop()
        bare.stop()

    t, b = results["twin"], results["bare"]
    print(f"Modbus/TCP on loopback, FC 4 read of {count} input registers, station {rmap.station!r} "
          f"({sum(sizes)} addresses), {os.cpu_count()} CPUs")
    print(f"{'':<28}{'twin serve':>12}{'bare pymodbus':>15}{'twin/bare':>11}")
    rows = [("latency p50 (us)", "p50"), ("latency p99 (us)", "p99"), ("req/s, 1 client", "rps1"),
            (f"req/s, {args.clients} clients", "rpsN")]
    for label, key in rows:
        print(f"{label:<28}{t[key]:>12.0f}{b[key]:>15.0f}{t[key] / b[key]:>11.2f}")
    late_pct = 100.0 * t["late"] / t["steps"] if t["steps"] else float("nan")
    print(f"twin serve, real time, {args.clients} clients polling: {t['steps']:.0f} steps in {args.seconds:g} s, "
          f"{t['late']:.0f} late ({late_pct:.2f} %)")
    flood_ok = True
    if quiet is not None:
        print(f"\nflood: {args.flood} connections pipelining reads flat out for {args.flood_seconds:g} s, one client "
              f"polling every 5 ms (twin serve, real time)")
        print(f"{'':<28}{'quiet':>12}{'flood':>12}")
        pct = lambda r: 100.0 * r["late"] / r["steps"] if r["steps"] else float("nan")  # noqa: E731
        for label, f in (("poller latency p50 (ms)", lambda r: f"{r['p50']:.2f}"),
                         ("poller latency p99 (ms)", lambda r: f"{r['p99']:.2f}"),
                         ("late steps (%)", lambda r: f"{pct(r):.2f}"),
                         ("steps per s", lambda r: f"{r['steps'] / r['wall']:.1f}"),
                         ("flood answers per s", lambda r: f"{r['flood_rps']:.0f}")):
            print(f"{label:<28}{f(quiet):>12}{f(flooded):>12}")
        flood_ok = pct(flooded) < 1.0 and flooded["p99"] < 20.0
        print(f"targets under the flood: late steps < 1 %, poller p99 < 20 ms: {'met' if flood_ok else 'MISSED'}")
    p50_ok = t["p50"] <= 1.5 * b["p50"]
    late_ok = late_pct < 1.0
    print(f"targets: p50 within 1.5x of bare: {'met' if p50_ok else 'MISSED'} ({t['p50'] / b['p50']:.2f}x); "
          f"late steps < 1 %: {'met' if late_ok else 'MISSED'}")
    return 0 if (p50_ok and late_ok and flood_ok) else 1


if __name__ == "__main__":
    raise SystemExit(main())
