"""The runtime through its embedding API: the standard blocks against the standard's timing diagrams and
algebra, tasks, RETAIN, process images, STOP; and the bench at a tiny size."""
from __future__ import annotations

import pytest

from structured_text.errors import PlcFault
from structured_text.runtime import Plc, compile_files

MS = 1_000_000


def plc_of(tmp_path, text: str, name: str = "p.st") -> Plc:
    path = tmp_path / name
    path.write_text(text)
    return Plc(compile_files([path]))


def run(plc: Plc, scans: int, cycle_ms: int, drive: dict, watch: list[str]) -> list[tuple]:
    """Scan k at k x cycle; drive: {scan: {name: value}} set before that scan; returns (scan, values...)."""
    rows = []
    for k in range(scans):
        for name, value in drive.get(k, {}).items():
            plc.set(name, value)
        plc.scan_ns(k * cycle_ms * MS)
        rows.append((k, *(plc.get(w) for w in watch)))
    return rows


TIMERS = """
PROGRAM main
VAR inp : BOOL; ton1 : TON; tof1 : TOF; tp1 : TP; END_VAR
ton1(IN := inp, PT := T#30ms);
tof1(IN := inp, PT := T#30ms);
tp1(IN := inp, PT := T#30ms);
END_PROGRAM
"""


def test_ton_delays_the_rise_and_follows_the_fall(tmp_path):
    # IEC 61131-3 TON diagram: Q rises PT after IN rose (if IN stayed TRUE); ET counts up to PT and stays;
    # IN FALSE resets Q and ET at once; a pulse shorter than PT gives no Q.
    plc = plc_of(tmp_path, TIMERS)
    rows = run(plc, 12, 10, {1: {"inp": True}, 3: {"inp": False}, 4: {"inp": True}, 9: {"inp": False}},
               ["ton1.Q", "ton1.ET"])
    q = [r[1] for r in rows]
    et = [r[2] // MS for r in rows]
    assert q == [False, False, False, False, False, False, False, True, True, False, False, False]
    assert et == [0, 0, 10, 0, 0, 10, 20, 30, 30, 0, 0, 0]


def test_tof_holds_q_pt_after_the_fall(tmp_path):
    # TOF: Q follows IN's rise at once and falls PT after IN fell; ET counts from the fall, 0 while IN.
    plc = plc_of(tmp_path, TIMERS)
    rows = run(plc, 10, 10, {1: {"inp": True}, 3: {"inp": False}}, ["tof1.Q", "tof1.ET"])
    assert [r[1] for r in rows] == [False, True, True, True, True, True, False, False, False, False]
    assert [r[2] // MS for r in rows] == [0, 0, 0, 0, 10, 20, 30, 30, 30, 30]


def test_tp_gives_one_pulse_of_pt_not_retriggered(tmp_path):
    # TP: a rising edge starts a pulse of PT; edges during the pulse do nothing; after it ET stays PT while
    # IN is TRUE and returns to 0 once IN is FALSE.
    plc = plc_of(tmp_path, TIMERS)
    rows = run(plc, 10, 10, {1: {"inp": True}, 2: {"inp": False}, 3: {"inp": True}, 5: {"inp": True},
                             7: {"inp": False}}, ["tp1.Q", "tp1.ET"])
    assert [r[1] for r in rows] == [False, True, True, True, False, False, False, False, False, False]
    assert [r[2] // MS for r in rows] == [0, 0, 10, 20, 30, 30, 30, 0, 0, 0]


def test_counters_bistables_and_edges_follow_the_standards_algebra(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR cu, cd, r, ld, s : BOOL; up : CTU; dn : CTD; ud : CTUD; sr1 : SR; rs1 : RS; rt : R_TRIG; ft : F_TRIG; END_VAR
up(CU := cu, R := r, PV := 2);
dn(CD := cd, LD := ld, PV := 2);
ud(CU := cu, CD := cd, R := r, LD := ld, PV := 2);
sr1(S1 := s, R := r);
rs1(S := s, R1 := r);
rt(CLK := cu);
ft(CLK := cu);
END_PROGRAM
""")
    plc.scan_ns(0)
    assert plc.get("ft.Q") is True  # F_TRIG: Q := NOT CLK AND NOT M, M starts FALSE: TRUE on the first call
    pulses = []
    for k in range(1, 9):  # CU toggles: rising edges on scans 1, 3, 5, 7
        plc.set("cu", k % 2 == 1)
        plc.scan_ns(k * 10 * MS)
        pulses.append(plc.get("rt.Q"))
    assert pulses == [True, False] * 4
    # four edges, PV = 2: the counters stop at PV (PVmax is the implementation's: PV, as matiec's)
    assert plc.get("up.CV") == 2 and plc.get("up.Q")
    assert plc.get("ud.CV") == 2 and plc.get("ud.QU") and not plc.get("ud.QD")
    plc.set("cu", False)
    plc.scan_ns(90 * MS)
    plc.set("cd", True)  # CU and CD both rise: CTUD does not count
    plc.set("cu", True)
    plc.scan_ns(100 * MS)
    assert plc.get("ud.CV") == 2
    assert plc.get("dn.CV") == 0 and plc.get("dn.Q")  # CTD stops at 0
    plc.set("ld", True)
    plc.scan_ns(110 * MS)
    assert plc.get("dn.CV") == 2 and plc.get("ud.CV") == 2
    plc.set("s", True)
    plc.set("r", True)  # set and reset together: SR's set dominates, RS's reset dominates
    plc.scan_ns(120 * MS)
    assert plc.get("sr1.Q1") is True and plc.get("rs1.Q1") is False
    assert plc.get("up.CV") == 0 and plc.get("ud.CV") == 0  # R dominates LD in CTUD


def test_ctud_counts_down_to_zero_and_up_to_pv(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR c : CTUD; k : INT; END_VAR
FOR k := 1 TO 3 DO c(CU := FALSE, CD := TRUE, PV := 2); c(CU := FALSE, CD := FALSE, PV := 2); END_FOR;
END_PROGRAM
""")
    plc.scan_ns(0)
    assert plc.get("c.CV") == 0 and plc.get("c.QD")  # three downward edges from 0: stays at 0


TASKS = """
PROGRAM Fast
VAR_EXTERNAL log : DINT; END_VAR
VAR n : INT; END_VAR
n := n + 1;
log := (log * 10 + 1) MOD 100000000;
END_PROGRAM
PROGRAM Slow
VAR_EXTERNAL log : DINT; END_VAR
VAR n : INT; END_VAR
n := n + 1;
log := (log * 10 + 2) MOD 100000000;
END_PROGRAM
CONFIGURATION cell
  VAR_GLOBAL log : DINT; END_VAR
  RESOURCE cpu ON PLC
    TASK fastT (INTERVAL := T#10ms, PRIORITY := 2);
    TASK slowT (INTERVAL := T#25ms, PRIORITY := 1);
    PROGRAM f WITH fastT : Fast;
    PROGRAM s WITH slowT : Slow;
  END_RESOURCE
END_CONFIGURATION
"""


def test_tasks_run_at_their_intervals_higher_priority_first(tmp_path):
    plc = plc_of(tmp_path, TASKS)
    assert plc.base_cycle() == 5 * MS  # gcd(10 ms, 25 ms)
    logs = []
    for k in range(11):  # t = 0 .. 50 ms
        plc.scan_ns(k * 5 * MS)
        logs.append(plc.get("log"))
    # t=0: both (slow first: PRIORITY 1); 10, 20: fast; 25: slow; 30, 40: fast; 50: both, slow first
    assert logs == [21, 21, 211, 211, 2111, 21112, 211121, 211121, 2111211, 2111211, 211121121 % 100_000_000]
    assert plc.get("f.n") == 6 and plc.get("s.n") == 3


def test_retain_survives_a_warm_restart_and_not_a_cold_one(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR RETAIN kept : INT := 7; END_VAR
VAR lost : INT := 7; END_VAR
kept := kept + 1;
lost := lost + 1;
END_PROGRAM
""")
    for k in range(3):
        plc.scan_ns(k * 10 * MS)
    assert (plc.get("kept"), plc.get("lost")) == (10, 10)
    plc.warm_restart()
    plc.scan_ns(30 * MS)
    assert (plc.get("kept"), plc.get("lost")) == (11, 8)
    plc.cold_restart()
    plc.scan_ns(0)
    assert (plc.get("kept"), plc.get("lost")) == (8, 8)


def test_located_variables_go_through_the_process_images(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR
  start AT %IX100.0 : BOOL;
  level AT %IW100 : INT;
  motor AT %QX100.0 : BOOL;
  speed AT %QW100 : INT;
  count AT %MD4 : DINT;
END_VAR
motor := start;
speed := level * 2;
count := count + 1;
END_PROGRAM
""")
    plc.write_located("%IX100.0", True)
    plc.write_located("%IW100", 21)
    plc.scan(0.0)
    assert plc.read_located("%QX100.0") is True and plc.read_located("%QW100") == 42
    assert plc.read_located("%MD4") == 1
    plc.write_located("%IX100.0", False)
    plc.scan(0.01)
    assert plc.read_located("%QX100.0") is False and plc.get("main.count") == 2
    assert plc.located() == [("%IX100.0", "start", "BOOL"), ("%IW100", "level", "INT"), ("%QX100.0", "motor", "BOOL"),
                             ("%QW100", "speed", "INT"), ("%MD4", "count", "DINT")]


def test_a_signed_located_input_reads_its_word_as_twos_complement(tmp_path):
    """An input image holds words as a fieldbus hands them over (0..65535); `AT %IW : INT` takes their bits, so a
    32-bit value split into a signed high word and a low word (a Modbus int32 in two registers) comes back whole."""
    import struct
    plc = plc_of(tmp_path, """
PROGRAM main
VAR
  hi AT %IW100 : INT;
  lo AT %IW101 : UINT;
  small AT %IB3 : SINT;
  word AT %IW102 : WORD;
END_VAR
VAR
  value : DINT;
END_VAR
value := INT_TO_DINT(hi) * 65536 + UINT_TO_DINT(lo);
END_PROGRAM
""")
    for v in (-1, -123456, -2**31, 2**31 - 1, 70000):
        hi, lo = struct.unpack(">HH", struct.pack(">i", v))  # the two registers of a big-endian int32
        plc.write_located("%IW100", hi)
        plc.write_located("%IW101", lo)
        plc.write_located("%IB3", 0xFE)
        plc.write_located("%IW102", 0xFFFF)
        plc.scan(0.0)
        assert (plc.get("main.value"), plc.get("main.lo")) == (v, lo)
        assert (plc.get("main.small"), plc.get("main.word")) == (-2, 0xFFFF)


def test_a_signed_located_output_writes_its_bits_as_the_word_a_fieldbus_sends(tmp_path):
    """The mirror of the input side: `AT %QW : INT` holding -1 puts 16#FFFF in the output image (a Modbus holding
    register takes 0..65535), and a DINT split into two INT/UINT output words reassembles to the same int32."""
    import struct
    plc = plc_of(tmp_path, """
PROGRAM main
VAR
  neg AT %QW100 : INT;
  hi AT %QW101 : INT;
  lo AT %QW102 : UINT;
  small AT %QB7 : SINT;
END_VAR
VAR
  value : DINT := -123456;
END_VAR
neg := -1;
hi := DINT_TO_INT(value / 65536 - BOOL_TO_DINT(value MOD 65536 < 0));
lo := DINT_TO_UINT(value - INT_TO_DINT(hi) * 65536);
small := -2;
END_PROGRAM
""")
    plc.scan(0.0)
    assert plc.read_located("%QW100") == 0xFFFF and plc.read_located("%QB7") == 0xFE
    words = struct.pack(">HH", plc.read_located("%QW101"), plc.read_located("%QW102"))
    assert struct.unpack(">i", words)[0] == -123456  # the big-endian int32 of the two registers


def test_a_runtime_error_keeps_the_plc_in_stop(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR a : ARRAY[1..3] OF INT; i : INT := 2; END_VAR
i := i + 1;
a[i] := 1;
END_PROGRAM
""")
    plc.scan_ns(0)
    with pytest.raises(PlcFault) as e:
        plc.scan_ns(10 * MS)
    assert (e.value.span.line, e.value.span.col) == (5, 3) and "out of bounds" in e.value.message
    assert e.value.task == "MAIN_TASK" and e.value.instance == "main"
    with pytest.raises(PlcFault):
        plc.scan_ns(20 * MS)
    plc.cold_restart()
    plc.scan_ns(0)


def test_runs_are_repeatable_bit_for_bit(tmp_path):
    text = """
PROGRAM main
VAR r : REAL := 0.1; x : LREAL := 1.0; t : TON; END_VAR
r := r * 1.1 + SIN(r);
x := x * 1.0000001 + SQRT(x);
t(IN := NOT t.Q, PT := T#20ms);
END_PROGRAM
"""
    a, b = plc_of(tmp_path, text, "a.st"), plc_of(tmp_path, text, "b.st")
    for k in range(50):
        a.scan_ns(k * 10 * MS)
        b.scan_ns(k * 10 * MS)
        assert (a.get("r"), a.get("x"), a.get("t.ET")) == (b.get("r"), b.get("x"), b.get("t.ET"))


def test_the_bench_runs_at_a_tiny_size(capsys):
    from bench.st_scan import main
    assert main(["--scans", "30", "--statements", "60", "--repeat", "1"]) == 0
    out = capsys.readouterr().out
    assert "ST / Python" in out and "60-statement program" in out


def test_named_time_functions_and_bcd_conversions(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR t : TIME; w : WORD; i : INT; d : DT; dd : DATE := D#2024-01-01; tod1 : TOD := TOD#01:00:00; END_VAR
t := DIVTIME(MULTIME(ADD_TIME(T#1s, T#500ms), 2), 4);
w := INT_TO_BCD(1234);
i := WORD_BCD_TO_INT(16#0987);
d := CONCAT_DATE_TOD(dd, tod1);
END_PROGRAM
""")
    plc.scan_ns(0)
    assert plc.get("t") == 750 * MS  # (1.5 s x 2) / 4
    assert plc.get("w") == 0x1234 and plc.get("i") == 987  # one decimal digit per nibble
    assert plc.resolve("d").json() == "DT#2024-01-01-01:00:00"


def test_en_eno_skip_a_call_and_say_so(tmp_path):
    # EN FALSE: the block or function does not run, ENO is FALSE (a function gives its type's default)
    plc = plc_of(tmp_path, """
FUNCTION Inc : INT
VAR_INPUT x : INT; END_VAR
Inc := x + 1;
END_FUNCTION
PROGRAM main
VAR c : CTU; go, ok : BOOL; a : INT := 7; END_VAR
c(EN := go, CU := TRUE, PV := 3, ENO => ok);
a := Inc(EN := go, x := 10);
END_PROGRAM
""")
    plc.scan_ns(0)
    assert (plc.get("c.CV"), plc.get("ok"), plc.get("a")) == (0, False, 0)
    plc.set("go", True)
    plc.scan_ns(10 * MS)
    assert (plc.get("c.CV"), plc.get("ok"), plc.get("a")) == (1, True, 11)


def test_global_constants_size_arrays_and_structs_hold_block_instances(tmp_path):
    plc = plc_of(tmp_path, """
TYPE Pair : STRUCT a : Acc; n : INT; END_STRUCT; END_TYPE
FUNCTION_BLOCK Acc
VAR_INPUT x : INT; END_VAR
VAR_OUTPUT s : INT; END_VAR
s := s + x;
END_FUNCTION_BLOCK
PROGRAM main
VAR_EXTERNAL CONSTANT N : INT; END_VAR
VAR arr : ARRAY[1..N] OF INT; p : Pair; k : INT; END_VAR
FOR k := 1 TO N DO arr[k] := k * k; END_FOR;
p.a(x := 2);
p.n := arr[N];
END_PROGRAM
CONFIGURATION c
VAR_GLOBAL CONSTANT N : INT := 4; END_VAR
RESOURCE r ON PLC
  TASK t (INTERVAL := T#10ms, PRIORITY := 1);
  PROGRAM m WITH t : main;
END_RESOURCE
END_CONFIGURATION
""")
    plc.scan_ns(0)
    plc.scan_ns(10 * MS)
    assert (plc.get("m.p.n"), plc.get("m.p.a.s"), plc.get("m.arr[4]"), plc.get("m.k")) == (16, 4, 16, 5)


def test_a_real_too_large_for_an_integer_stops_the_plc(tmp_path):
    plc = plc_of(tmp_path, """
PROGRAM main
VAR r : REAL := 1.0E10; i : INT; n : REAL; END_VAR
n := SQRT(-1.0);
i := REAL_TO_INT(r);
END_PROGRAM
""")
    with pytest.raises(PlcFault) as e:
        plc.scan_ns(0)
    assert (e.value.span.line, e.value.span.col) == (5, 6) and "does not fit" in e.value.message
    assert plc.resolve("n").json() == "NaN"  # IEC 60559's invalid operation, as a JSON string


def test_eno_of_a_function_on_the_right_of_an_assignment(tmp_path):
    plc = plc_of(tmp_path, """
FUNCTION Twice : INT
VAR_INPUT v : INT; END_VAR
Twice := v * 2;
END_FUNCTION
PROGRAM main
VAR e, ok : BOOL; y : INT := 3; END_VAR
y := Twice(EN := e, v := 5, ENO => ok);
END_PROGRAM
""")
    plc.scan_ns(0)
    assert (plc.get("y"), plc.get("ok")) == (0, False)
    plc.set("e", True)
    plc.scan_ns(10 * MS)
    assert (plc.get("y"), plc.get("ok")) == (10, True)


def test_time_converts_to_and_from_numbers_in_seconds(tmp_path):
    # the unit is the implementation's (IEC 61131-3); seconds, as matiec/OpenPLC's library
    plc = plc_of(tmp_path, """
PROGRAM main
VAR d : DINT; r : REAL; t1, t2 : TIME; END_VAR
d := TIME_TO_DINT(T#1500ms);
r := TIME_TO_REAL(T#1500ms);
t1 := DINT_TO_TIME(2);
t2 := REAL_TO_TIME(0.25);
END_PROGRAM
""")
    plc.scan_ns(0)
    assert (plc.get("d"), plc.get("r"), plc.get("t1"), plc.get("t2")) == (1, 1.5, 2000 * MS, 250 * MS)
