"""gripper-twin: the digital twin of a robot cell with a gripper.

By concept: `twin.core` is the stepped simulation (no sockets, no wall clock) and its static signal table;
`twin.runtime` runs a cell in time (the front-end contract `exchange`, the runners in `pacing`, the
watchdog, fault injection); `twin.devices` re-presents vendors' devices over the twin (Robotiq profiles);
`twin.frontends` serves the cell (Modbus/TCP, OPC UA, the live page, and the adapter that runs a front end
in a process of its own); `twin.observe` looks at it (frames, recordings, plots, pictures, the run report,
the event stream, the station doctor). The application that assembles them (the `twin` command, the cell,
argument types, plug-in loading) is `twin_app`, above this package.
"""
