"""Faults in commissioning checks over Modbus/TCP: plant faults in the served twin (`twin serve --faults`),
link faults on the check's side of the network."""
import pytest

from plc_client.link import LINK_OK, LinkFaults
from plc_client.scan import ScanCycle, plc_logic
from plc_client.testing import ServerStartError, twin_server
from tests.conftest import ROOT

BENCH = ROOT / "tests" / "plc" / "stations" / "ring_bench"


def test_a_served_twin_meets_the_faults_of_its_faults_file(tmp_path):
    faults = tmp_path / "faults.toml"
    faults.write_text('[faults.jam]\nkind = "finger_jammed"\ninput = "L2"\nposition_mm = 326.0\n\n'
                      '[faults.drift]\nkind = "force_offset"\nfinger = "L3"\noffset = 50.0\n')
    with twin_server(BENCH, faults=faults) as server, server.client() as plc:
        plc.write(L2=300.0)  # only finger 1 closes: it jams 6 mm before the ring
        plc.advance(150)
        values = plc.read("L2.actual", "L2.contact", "L2.force", "L2.effort", "L3.actual", "L3.force")
    assert values["L2.actual"] == pytest.approx(326.0, abs=0.5) and not values["L2.contact"]  # jammed short
    assert values["L2.effort"] < -1000.0 and values["L2.force"] == 0.0  # its drive presses on the jam, on no part
    assert values["L3.actual"] == pytest.approx(330.0, abs=0.5)  # finger 2 stands free ...
    assert values["L3.force"] == pytest.approx(50.0, abs=1.0)  # ... and reads 50 N too much


def test_a_faults_file_with_a_mistake_stops_the_server_with_the_key(tmp_path):
    faults = tmp_path / "faults.toml"
    faults.write_text('[faults.jam]\nkind = "finger_jammed"\ninput = "L9"\n')
    with pytest.raises(ServerStartError, match=r"faults.toml: faults.jam.input: no gripper input 'L9'"):
        with twin_server(BENCH, faults=faults):
            pass
    faults.write_text('[faults.cut]\nkind = "link_lost"\nduration = 1.0\n')
    with pytest.raises(ServerStartError, match=r"faults.cut.kind: link_lost is a fault of the PLC's link"):
        with twin_server(BENCH, faults=faults):
            pass


@plc_logic(inputs=["L2.actual", LINK_OK])
def close_l2(inputs, state):
    return {"L2": 330.0 if inputs.time < 0.1 else 300.0 if inputs.time < 0.4 else 320.0}


def test_a_link_loss_between_the_check_and_the_server(tmp_path):
    with twin_server(BENCH) as server, server.client() as client:
        link = LinkFaults(server.io(client), lost=[(0.2, 0.6)])
        plc = ScanCycle(link, close_l2, cycle=0.012)
        plc.run(seconds=0.5)  # the link is down since 0.2 s: the 320 mm of 0.4 s has not arrived
        assert client.get("L2") == pytest.approx(300.0) and not plc.image[LINK_OK]
        frozen = plc.image["L2.actual"]
        assert client.get("L2.actual") < frozen - 3.0  # the finger moved on; the PLC still reads the old value
        plc.run(seconds=0.2)  # back at 0.6 s: the latest output is written at once
        assert client.get("L2") == pytest.approx(320.0) and plc.image[LINK_OK]


@pytest.mark.parametrize("signal, value, reason", [
    ("GrippedPart", "7", r"faults.toml: faults: ReadingStuck GrippedPart: value: .*one of '', 'ring'"),
    ("L2.force", "-5.0", r"faults: ReadingStuck L2.force: value: .*-5.*outside the range 0"),
    ("doGripped", "2", r"faults: ReadingStuck doGripped: value: .*a bool"),
])
def test_a_stuck_reading_no_signal_could_show_is_refused_when_the_file_is_loaded(tmp_path, signal, value, reason):
    """The one validation of values (`SignalSpec.check`) holds for a stuck reading too: a value the reading could
    never show (an enumeration's index past its choices, a force below 0, a bool of 2) is refused at load, naming
    the fault and the signal, instead of reaching the PLC as something else (index 7 read as 'none')."""
    from twin.core import Twin
    from twin_app.campaign.faultfile import load_fault_file
    from twin_app.campaign.spec import SpecError

    faults = tmp_path / "faults.toml"
    faults.write_text(f'[faults.bad]\nkind = "reading_stuck"\nsignal = "{signal}"\nvalue = {value}\n')
    with Twin.from_station(BENCH) as twin:
        with pytest.raises(SpecError, match=reason):
            load_fault_file(faults, twin)
        faults.write_text('[faults.ok]\nkind = "reading_stuck"\nsignal = "GrippedPart"\nvalue = 1\n')
        (stuck,) = load_fault_file(faults, twin)
        assert stuck.value == "ring"  # index 1: the first target, as the Modbus map numbers them
