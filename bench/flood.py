"""A flood of N connections pipelining reads flat out at a `twin serve`, from one process (selectors),
for the fairness test (`python -m bench.flood PORT N SECONDS`) and `python -m bench modbus`. Prints the
number of answers received."""
from __future__ import annotations

import selectors
import socket
import struct
import sys
import time


def flood(port: int, connections: int, seconds: float, batch: int = 200, host: str = "127.0.0.1") -> int:
    """Each connection keeps `batch` pipelined FC 4 reads of sim.step..sim.time_ms in flight."""
    frame = lambda tid: struct.pack(">HHHBBHH", tid & 0xFFFF, 0, 6, 1, 4, 0, 4)  # noqa: E731
    blob = b"".join(frame(i) for i in range(batch))
    answer = 7 + 2 + 8
    sel = selectors.DefaultSelector()
    socks = []
    for _ in range(connections):
        s = socket.create_connection((host, port), timeout=5)
        s.setblocking(False)
        socks.append(s)
        sel.register(s, selectors.EVENT_READ | selectors.EVENT_WRITE, {"out": blob, "in": 0, "pending": batch})
    received = 0
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        for key, events in sel.select(0.05):
            s, st = key.fileobj, key.data
            if events & selectors.EVENT_READ:
                try:
                    data = s.recv(1 << 16)
                except BlockingIOError:
                    data = None
                if data == b"":
                    sel.unregister(s)
                    continue
                if data:
                    done, st["in"] = divmod(st["in"] + len(data), answer)
                    received += done
                    st["pending"] -= done
                    if not st["out"] and st["pending"] <= batch // 2:  # keep the pipeline full
                        st["out"] = blob
                        st["pending"] += batch
            if st["out"]:
                try:
                    n = s.send(st["out"])
                    st["out"] = st["out"][n:]
                except BlockingIOError:
                    pass
            # wait for answers; ask to write only while something is left to send (no busy loop)
            sel.modify(s, selectors.EVENT_READ | (selectors.EVENT_WRITE if st["out"] else 0), st)
    for s in socks:
        s.close()
    return received


if __name__ == "__main__":
    print(flood(int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])), flush=True)
