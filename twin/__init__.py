"""gripper-twin: the digital twin of a robot cell with a gripper.

`twin.core` is the stepped simulation (no sockets, no wall clock); `twin.modbus` serves it on Modbus/TCP;
`twin.pacing` advances it in real time or in lockstep; `twin.cli` is the `twin` command.
"""
