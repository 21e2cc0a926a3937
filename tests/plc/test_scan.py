"""The scan cycle: input image, logic, output image, on a fixed cycle; user logic in a few lines."""
import pytest

from plc_client.scan import InputImage, ScanCycle, TwinIO
from tests.plc.conftest import BENCH
from twin.core import Twin


class RecordingIO:
    """A process that only records: what was read and written, and how far time advanced."""

    lockstep = True

    def __init__(self, values):
        self.values, self.reads, self.writes, self.advanced = dict(values), [], [], 0.0

    def read_image(self, names):
        self.reads.append(tuple(names))
        return {n: self.values[n] for n in names}

    def write_image(self, values):
        self.writes.append(dict(values))
        self.values.update(values)

    def advance(self, seconds):
        self.advanced += seconds


def test_user_logic_is_a_plain_function_of_the_input_image_and_its_state():
    def blink(inputs, state):  # a 50 ms blinker while "run" is set
        state.n = getattr(state, "n", 0) + 1
        return {"lamp": bool(inputs["run"]) and (inputs.scan // 5) % 2 == 1}

    io = RecordingIO({"run": True, "lamp": False})
    plc = ScanCycle(io, blink, inputs=["run"])
    plc.run(seconds=0.2)
    assert plc.scans == 20 and plc.state.n == 20 and io.advanced == pytest.approx(0.2)
    assert all(r == ("run",) for r in io.reads)  # the whole input image in one read per scan
    # the first scan writes the whole output image, then only changes (at 50, 100, 150 ms)
    assert io.writes == [{"lamp": False}, {"lamp": True}, {"lamp": False}, {"lamp": True}]
    assert plc.image.time == pytest.approx(0.19) and plc.image.scan == 19


def test_the_input_image_is_read_only_and_names_what_it_holds():
    image = InputImage({"a": 1}, time=0.0, cycle=0.01, scan=0)
    with pytest.raises(KeyError, match="'b' is not in the input image"):
        image["b"]
    with pytest.raises(TypeError):
        image["a"] = 2


def test_run_is_always_bounded_and_run_until_times_out_in_plc_time():
    plc = ScanCycle(RecordingIO({"x": 0}), lambda i, s: {}, inputs=["x"])
    with pytest.raises(ValueError):
        plc.run()
    with pytest.raises(TimeoutError, match="no result after 0.5 s"):
        plc.run_until(lambda i, s: i["x"] == 1, timeout=0.5)
    assert plc.scans == 50


def test_in_process_the_twin_is_stepped_by_cycle_over_dt_on_average():
    with Twin.from_station(BENCH) as twin:
        plc = ScanCycle(TwinIO(twin), lambda i, s: {}, inputs=["L2.actual"], cycle=0.010)
        plc.run(scans=600)  # 6 s of 10 ms scans = 500 steps of 12 ms
        assert twin.step_count == 500


def test_twin_io_speaks_the_map_units_mm_for_metres():
    with Twin.from_station(BENCH) as twin:
        io = TwinIO(twin)
        assert io.get("L2") == pytest.approx(330.0)
        io.write_image({"L2": 325.0})
        assert twin.read("L2") == pytest.approx(0.325)
        assert io.get("doGripped") is False


def test_real_time_scans_keep_the_cycle_against_the_wall_clock():
    io = RecordingIO({"x": 0})
    io.lockstep = False
    plc = ScanCycle(io, lambda i, s: {}, inputs=["x"], cycle=0.010)
    plc.run(scans=20)
    assert io.advanced == 0.0  # the process runs on its own clock
    assert plc.time == pytest.approx(0.200, abs=0.030)


def test_an_output_the_process_refuses_stops_the_scan_cycle_with_an_error_naming_it():
    from plc_client.errors import OutputRefusedError, ValueOutOfRangeError

    class Refusing(RecordingIO):
        def write_image(self, values):
            if values.get("L2", 0) > 441:
                raise ValueOutOfRangeError("L2", values["L2"], 0.0, 441.0, "mm")
            super().write_image(values)

    def ramp(inputs, state):
        return {"lamp": True, "L2": 400.0 + 20 * inputs.scan}

    io = Refusing({"run": True})
    plc = ScanCycle(io, ramp, inputs=["run"])
    with pytest.raises(OutputRefusedError) as caught:
        plc.run(scans=10)
    assert str(caught.value) == ("the PLC logic's output L2=460 refused at scan 3 (t=0.030 s): "
                                 "signal 'L2': 460 mm is out of range: 0 to 441 mm")
    assert caught.value.outputs == {"L2": 460.0} and plc.written["L2"] == 440.0  # not taken as written
