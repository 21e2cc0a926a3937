"""Mimic joints are a linkage: the followers are tied to their master, not driven on their own."""
from pathlib import Path

import pytest

from twin.core import Twin

CHUCK = Path(__file__).resolve().parent / "data" / "chuck3"


def test_a_self_centring_chuck_pushes_an_off_centre_shaft_to_the_centre_and_grips_it():
    with Twin.from_station(CHUCK) as twin:
        twin.write("jaw_1", 0.02)  # past the shaft's 30 mm radius
        twin.step(round(5.0 / twin.dt))  # 30 mm at 10 mm/s, then some
        (x, y, _), _ = twin.object_pose("shaft")
        assert abs(x) < 0.001 and abs(y) < 0.001  # the first jaw pushed the 7 kg shaft into the middle
        assert twin.read("GrippedPart") == "shaft"
        forces = list(twin.finger_forces().values())
        # one 200 N drive moves three jaws through a 1:1:1 linkage: statics gives each a third of it
        assert sum(forces) == pytest.approx(200.0, rel=0.1)
        q = twin.joint_positions()["jaw_1"]
        client, body = twin.world.client, twin.world.machine
        followers = [client.getJointState(body, twin.world.joint_index[j])[0] for j in ("jaw_2_slide", "jaw_3_slide")]
        assert followers == pytest.approx([q, q], abs=0.0015)  # the linkage holds under the squeeze (the master jaw sinks ~1 mm into the round shaft)


def test_the_followers_track_their_master_while_moving():
    with Twin.from_station(CHUCK) as twin:
        twin.object_pose("shaft")
        twin.remove_object("shaft")
        twin.write("jaw_1", 0.065)
        worst = 0.0
        client, body = twin.world.client, twin.world.machine
        for _ in range(100):
            twin.step()
            q = twin.joint_positions()["jaw_1"]
            for j in ("jaw_2_slide", "jaw_3_slide"):
                worst = max(worst, abs(client.getJointState(body, twin.world.joint_index[j])[0] - q))
        assert worst < 0.0005
