"""A motion instruction as the robot's planner takes it: speeddata, zonedata, AccSet and the payload in SI units.

One rule, used by every host that plans motions (the station's `TwinHost`, offline or in the cell).
"""
from __future__ import annotations

import math

from twin.core.motion import Speed, payload_factor
from twin.core.planner import FINE, Zone

from .host import MotionRequest


def speed_of(req: MotionRequest, rated_payload_kg: float | None = None) -> Speed:
    """speeddata (mm/s, deg/s; VelSet already applied) with \\T, AccSet, PathAccLim and the payload's factor.
    v_leax and v_reax concern external axes, which the twin has none of."""
    f = req.speed.fields
    acc, ramp = req.acc
    return Speed(v_tcp=float(f["v_tcp"]) / 1000.0, v_ori=math.radians(float(f["v_ori"])),
                 acc=acc / 100.0 * payload_factor(req.load_kg, rated_payload_kg), ramp=ramp / 100.0,
                 time=req.time, tcp_acc=req.path_acc)


def zone_of(req: MotionRequest) -> Zone:
    """zonedata in m and rad (\\Z replaces pzone_tcp); FINE for a stop point (fine, \\Inpos)."""
    if req.stop_point:
        return FINE
    f = req.zone.fields
    tcp = float(req.zone_size if req.zone_size is not None else f["pzone_tcp"]) / 1000.0
    return Zone(False, tcp, float(f["pzone_ori"]) / 1000.0, float(f["pzone_eax"]) / 1000.0,
                math.radians(float(f["zone_ori"])), float(f["zone_leax"]) / 1000.0, math.radians(float(f["zone_reax"])))


def conf_of(req: MotionRequest) -> tuple[int, int, int] | None:
    """The robtarget's (cf1, cf4, cf6) when configuration monitoring is on for this motion, else None."""
    if not req.conf or req.target.type != "robtarget":
        return None
    c = req.target.fields["robconf"].fields
    return int(c["cf1"]), int(c["cf4"]), int(c["cf6"])
