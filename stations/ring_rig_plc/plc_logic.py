"""The ring rig's gripper PLC (thesis section 3.1): the grip sequence with the rig's numbers, in mm and N.

Fingers (axes L2, L3, L4; finger forces L2, L3 and L5, the fine axis on finger 3) close from outside onto
the ring's 320 mm outer radius, or open from inside into its 240 mm bore (finger outer faces at setpoint
+ 40 mm, so touching at 200 mm). A grip that reaches 290 mm (outside) or 230 mm (inside) without force
has missed the ring. A release opens at least back to where the next grip of the same kind starts
(330 mm outside, 150 mm inside).

`sequence()` uses the generic handshake names (grip_request, gripped, ...), for benches where a test
plays the robot; `cell_sequence()` speaks the robot program of `stations/ring_rig_plc` (doGripRequest,
diGripDone, ...), with the prepare request that puts the fingers where the robot asks (aoFingerReady):

    plc --port 5020 --station stations/ring_rig_plc run stations.ring_rig_plc.plc_logic:cell_sequence
    plc --port 5020 --station stations/ring_rig_plc run          # the same: station.toml names it ([plugins])
"""
from __future__ import annotations

from plc_client.grip_sequence import GripSequence, Handshake

AXES = ("L2", "L3", "L4")
FORCES = ("L2.force", "L3.force", "L5.force")
CONTACTS = ("L2.contact", "L3.contact", "L5.contact")


def sequence(handshake: Handshake | None = None, **overrides) -> GripSequence:
    """The ring rig's grip sequence; any `GripSequence` parameter can be overridden."""
    params = dict(axes=AXES, forces=FORCES, contacts=CONTACTS, speed=20.0, threshold=200.0, travel_speed=100.0,
                  end_of_travel={"outside": 290.0, "inside": 230.0},
                  ready_position={"outside": 330.0, "inside": 150.0},
                  release_limit={"outside": 441.0, "inside": 0.0},
                  travel=(0.0, 441.0),  # the axes' setpoint range (L2..L4: 0..441 mm)
                  press=1.0,  # then 1 mm on: 1500 N per finger, and the ring is held by friction alone
                  handshake=handshake or Handshake())
    params.update(overrides)
    return GripSequence(**params)


# The handshake with stations/ring_rig_plc/ring_rig_plc.mod (robot DOs are the PLC's inputs, and back).
CELL_HANDSHAKE = Handshake(grip_request="doGripRequest", release_request="doReleaseRequest", inside="doGripInside",
                           gripped="diGripOk", fault="diGripFault", busy=None, done="diGripDone",
                           prepare_request="doPrepare", prepare_position="aoFingerReady")


def cell_sequence(**overrides) -> GripSequence:
    """The gripper PLC of `stations/ring_rig_plc`: the rig's grip sequence on the robot program's handshake."""
    return sequence(CELL_HANDSHAKE, **overrides)
