"""Running a cell in time: the front-end contract (`exchange`: snapshots out, validated writes in), the runners
(`pacing`: the only wall clock), the comm-loss `watchdog` and plant `faults`. Imports only `twin.core`."""
