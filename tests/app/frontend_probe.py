"""A front end for tests/app/test_frontend_process.py, run in its own process by `twin.frontends.process`:
it writes, advances and refuses as a client would, and records what it saw in a JSON file."""
from __future__ import annotations

import asyncio
import json


class Probe:
    def __init__(self, options: dict):
        self.out, self.script = options["out"], options["script"]
        self.steps: list[int] = []
        self.task = None

    async def start(self, remote):
        self.remote = remote
        remote.subscribe(lambda snap: self.steps.append(snap.step))
        self.task = asyncio.ensure_future(self.run())
        return ["probe: started"], [{"name": "probe", "protocol": "none"}]

    async def run(self):
        remote, seen = self.remote, []
        for kind, arg in self.script:
            try:
                if kind == "submit":
                    result = await remote.submit([tuple(w) for w in arg])
                elif kind == "advance":
                    result = await remote.advance(arg)
                    result = [result, remote.snapshot.step, dict(remote.snapshot.values)]
                seen.append(["ok", result])
            except Exception as exc:  # noqa: BLE001 - recorded for the test
                seen.append(["err", type(exc).__module__ + "." + type(exc).__qualname__, str(exc)])
        with open(self.out, "w") as f:
            json.dump({"results": seen, "steps": self.steps}, f)

    async def close(self):
        return len(self.script)


def probe(options: dict) -> Probe:
    return Probe(options)
