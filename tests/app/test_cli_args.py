"""Every command refuses a bad number the same way: one line naming the option and what it needs."""
import pytest

from plc_client.cli import build_parser as plc_parser
from twin_app.cli import build_parser as twin_parser

BAD = [
    # (parser, argv, the option's message)
    (twin_parser, ["serve", "S", "--port", "70000"], "argument --port: a TCP port is 0..65535, not 70000"),
    (twin_parser, ["serve", "S", "--port", "five"], "argument --port: needs a whole number (a TCP port), not 'five'"),
    (twin_parser, ["serve", "S", "--opcua", "-1"], "argument --opcua: a TCP port is 0..65535, not -1"),
    (twin_parser, ["serve", "S", "--speed", "0"], "argument --speed: must be greater than 0, not 0"),
    (twin_parser, ["serve", "S", "--speed", "inf"], "argument --speed: must be greater than 0, not inf"),
    (twin_parser, ["serve", "S", "--watchdog", "-2"], "argument --watchdog: must be 0 or more, not -2"),
    (twin_parser, ["serve", "S", "--watchdog", "nan"], "argument --watchdog: must be 0 or more, not nan"),
    (twin_parser, ["serve", "S", "--max-connections", "0"], "argument --max-connections: must be at least 1, not 0"),
    (twin_parser, ["view", "S", "--port", "65536"], "argument --port: a TCP port is 0..65535, not 65536"),
    (twin_parser, ["campaign", "C", "--timeout", "-1"], "argument --timeout: must be greater than 0, not -1"),
    (plc_parser, ["run", "m:f", "--cycle", "x"], "argument --cycle: needs a number, not 'x'"),
    (plc_parser, ["run", "m:f", "--scans", "0"], "argument --scans: must be at least 1, not 0"),
]


@pytest.mark.parametrize("parser, argv, message", BAD, ids=[" ".join(b[1]) for b in BAD])
def test_a_bad_number_is_refused_with_the_option_named(parser, argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        parser().parse_args(argv)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err


def test_good_numbers_pass():
    args = twin_parser().parse_args(["serve", "S", "--port", "0", "--watchdog", "0", "--speed", "2.5"])
    assert (args.port, args.watchdog, args.speed) == (0, 0.0, 2.5)
