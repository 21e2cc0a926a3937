"""gripper-twin: the digital twin of a robot cell with a gripper.

`twin.core` is the stepped simulation (no sockets, no wall clock) and its static signal table;
`twin.exchange` is the contract front ends use (snapshots out, validated writes in); `twin.modbus` is the
Modbus/TCP front end; `twin.pacing` advances a cell in real time or in lockstep. The application that
assembles them (the `twin` command, the cell) is `twin_app`, above this package.
"""
from .moved import install as _install_moved

_install_moved()  # old import paths of code that moved beside its station (twin.moved)
