"""The application: what assembles and runs a cell, on top of every other package.

- `twin_app.cell`: one place that assembles a running cell (twin, controller as a device, front ends,
  runner) and documents the front-end contract;
- `twin_app.cli`: the `twin` command (`info`, `map`, `serve`, `demo`);

Nothing below imports it: `twin.core` is the bottom, the controller (`rapid_like`) and the front ends
(`twin.frontends.modbus`, ...) sit between.
"""
