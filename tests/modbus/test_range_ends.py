"""Item 5 of issue 9: a revolute input's range end (0.9 rad = 51.566 deg) is writable over Modbus and through
the client, though the map's 0.01 deg counts cannot hold it exactly; a hair beyond it is still refused."""
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))
from urdfs import joint, link, urdf  # noqa: E402

from modbus_helpers import ServerProcess  # noqa: E402
from plc_client.client import RegisterMap, TwinClient  # noqa: E402
from plc_client.errors import ValueOutOfRangeError  # noqa: E402

END = 0.9  # rad


@pytest.fixture(scope="module")
def station(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hinge")
    urdf(folder / "hinge.urdf", link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
         joint("jh", "revolute", "palm", "flap", limit=f'lower="-{END}" upper="{END}"', axis="0 0 1"), link("flap"))
    (folder / "station.toml").write_text('[station]\nname = "hinge"\n\n[gripper]\nurdf = "hinge.urdf"\n'
                                         'always_active = true\n')
    return folder


def test_the_exact_ends_of_a_revolute_range_are_accepted_over_modbus_and_through_the_client(station):
    rmap = RegisterMap.from_station(station)
    with ServerProcess(station, "--lockstep") as server, TwinClient.connect(port=server.port, map=rmap) as client:
        for end in (END, -END):
            client.write(flap=math.degrees(end))  # what a PLC sends for the end: 51.566... deg
            client.advance(1)
            assert client.get("flap") == pytest.approx(math.degrees(end), abs=0.006)  # the end, as 0.01 deg counts
        with pytest.raises(ValueOutOfRangeError):
            client.write(flap=math.degrees(END) + 0.01)  # beyond the end: refused, as before
        entry = rmap["flap"]
        lo, hi = entry.count_range
        assert (lo, hi) == (-5157, 5157)  # the counts nearest the ends (51.57 deg) mean the ends
        from twin.core import Twin
        with Twin.from_station(station) as twin:  # and what the twin gets from the end's count is the exact end
            from twin.frontends.modbus.register_map import build_register_map
            served = {e.name: e for e in build_register_map(twin.signals).entries}["flap"]
            twin.write("flap", served.si_of_words(served.encode(END)))
            assert twin.read("flap") == END
            assert served.si_of_words([5158]) is None  # one count further: refused
