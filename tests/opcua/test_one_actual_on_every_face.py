"""Issue 18, item 4: an actual never leaves its joint's range, and every face shows the same value. A continuous
joint's input spans -pi..pi (docs/station-format.md); here a lever whose weight hangs beyond pi is held at pi by a
drive too weak for it, so pybullet's joint sags past the range's end. The simulation API, Modbus and OPC UA (one
`twin serve --lockstep` process, the same station, writes and step count) must all read the range's end."""
from __future__ import annotations

import asyncio
import math
import sys
from pathlib import Path

import pytest
from asyncua import Client

from opcua_helpers import OpcUaServerProcess, namespace, node

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "modbus"))
from plc_client.client import RegisterMap, TwinClient  # noqa: E402

STEPS = 60  # 0.7 s: the lever has sagged 0.17 rad and more past pi by then (it swings about pi + 0.29 rad)
INERTIA = '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/>'


@pytest.fixture(scope="module")
def station(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lever")
    # a 1 kg lever on a continuous joint, its centre of mass 0.29 rad off its length: hanging, it rests at pi + 0.29
    # rad; gravity's torque there (~0.28 N m) is far beyond the drive's 0.05 N m
    (folder / "lever.urdf").write_text(f"""<?xml version="1.0"?>
<robot name="lever">
  <link name="palm"><inertial><mass value="0.5"/>{INERTIA}</inertial>
    <collision><geometry><box size="0.04 0.04 0.02"/></geometry></collision></link>
  <joint name="pivot" type="continuous"><parent link="palm"/><child link="lever"/><origin xyz="0.05 0 0"/>
    <axis xyz="1 0 0"/><limit effort="0.05" velocity="1"/></joint>
  <link name="lever"><inertial><origin xyz="0 0.03 0.1"/><mass value="1"/>{INERTIA}</inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.01 0.01 0.2"/></geometry></collision></link>
</robot>
""")
    (folder / "station.toml").write_text('[station]\nname = "lever"\n\n[gripper]\nurdf = "lever.urdf"\n'
                                         'always_active = true\ninitial = { lever = 3.14159 }\n'
                                         'mount = { xyz = [0.0, 0.0, 0.5] }\n')
    return folder


def test_a_joint_sagging_past_its_range_end_reads_the_end_on_every_face(station):
    from twin.core import Twin

    with Twin.from_station(station) as twin:
        lo, hi = twin.spec("lever.actual").min, twin.spec("lever.actual").max
        assert (lo, hi) == (-math.pi, math.pi)
        twin.write("lever", math.pi)
        twin.step(STEPS)
        raw = twin.world.client.getJointState(twin.world.machine, twin.gripper.joint["lever"])[0]
        assert raw > math.pi + 0.05  # the joint itself has passed the end
        api = twin.read("lever.actual")
    assert lo <= api <= hi

    rmap = RegisterMap.from_station(station)
    with OpcUaServerProcess(station, "--lockstep") as server:
        with TwinClient.connect(port=server.port, map=rmap) as client:
            client.write(lever=180.0)  # deg: the range's end
            client.advance(STEPS)
            over_modbus = client.get("lever.actual")  # deg, 0.01 deg counts

        async def read():
            async with Client(server.url, timeout=60) as c:
                ns = await namespace(c, "lever")
                return await node(c, ns, "lever.actual").read_value()

        over_opcua = asyncio.run(asyncio.wait_for(read(), 120))
    assert lo <= over_opcua <= hi
    assert over_opcua == api  # the same station, writes and steps: the same value, bit for bit
    assert over_modbus == pytest.approx(math.degrees(api), abs=0.006)  # the same, as 0.01 deg counts
