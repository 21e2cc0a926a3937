"""`twin campaign SPEC.toml`: run a commissioning campaign (see docs/campaigns.md).

Exit status: 0 when every scenario passed, 1 when one failed or could not run, 2 for a campaign file
with a mistake (one line naming the file, the key and the scenario) or bad options.
"""
from __future__ import annotations

import argparse
import os
import sys

from twin_app.cli_args import positive_float
from pathlib import Path


def _workers(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if n < 1:
        raise argparse.ArgumentTypeError("at least 1 worker")
    return n


def _indices(text: str) -> list[int]:
    out = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        try:
            out += list(range(int(lo), int(hi) + 1)) if hi else [int(lo)]
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: scenario numbers such as 0,3,5-9") from None
    return out


def add_command(subparsers) -> None:
    p = subparsers.add_parser("campaign", help="run a commissioning campaign: a matrix of scenarios with faults and expectations",
                              description="Run every scenario of a campaign file in lockstep, each in a fresh process, "
                                          "and write results.csv, junit.xml and summary.txt (docs/campaigns.md).")
    p.add_argument("spec", help="the campaign file (TOML)")
    p.add_argument("--workers", "-j", type=_workers, default=None,
                   help="scenarios run at once on this machine (default: the number of CPUs)")
    p.add_argument("--cluster", metavar="ADDRESS", help="run on the Dask cluster whose scheduler is at ADDRESS "
                   "(e.g. tcp://10.0.0.5:8786; needs pip install 'gripper-twin[cluster]')")
    p.add_argument("--out", "-o", help="the output folder (default: campaign-results/SPEC_NAME)")
    p.add_argument("--resume", action="store_true", help="skip the scenarios already in the output folder's results file")
    p.add_argument("--timeout", type=positive_float, help="wall seconds one scenario may take (default: run.timeout of the file)")
    p.add_argument("--only", type=_indices, metavar="N,M-K", help="run only these scenarios (by number)")
    p.add_argument("--recordings", type=int, default=10, metavar="N",
                   help="record and plot at most N failing scenarios (re-run, in failures/; default 10, 0: none)")
    p.add_argument("--list", action="store_true", help="list the scenarios and their expectations, run nothing")
    p.add_argument("--plc", metavar="REF", default=None,
                   help="run another PLC than the file's driver.plc: \"module:logic\" or Structured Text files beside "
                        "the campaign file (\"gripper.st io.st\")")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress line")
    p.set_defaults(func=cmd_campaign)


def with_plc(campaign, ref: str):
    """The campaign with another PLC driver (`--plc`), checked as `driver.plc` is."""
    import dataclasses

    from .spec import SpecError, st_files

    if campaign.driver.kind != "plc":
        raise SpecError(campaign.file, "driver", f"--plc {ref}: the campaign's driver is {campaign.driver.kind}, not plc")
    if st_files(ref):
        missing = [n for n in st_files(ref) if not (campaign.driver.base / n).is_file()]
        if missing:
            raise SpecError(campaign.file, "driver.plc", f"--plc: {missing[0]}: no such file in {campaign.driver.base}")
        ref = " ".join(st_files(ref))
    else:
        from twin_app.plugins import LoadError, load_object

        try:
            load_object(ref, campaign.driver.base)
        except LoadError as exc:
            raise SpecError(campaign.file, "driver.plc", f"--plc: {exc}") from None
    return dataclasses.replace(campaign, driver=dataclasses.replace(campaign.driver, ref=ref))


def cmd_campaign(args) -> int:
    from .backends import DaskBackend, LocalBackend
    from .runner import run_campaign
    from .spec import SpecError, load_campaign
    from .verdict import expectations

    try:
        campaign = load_campaign(args.spec)
        if args.plc:
            campaign = with_plc(campaign, args.plc)
    except SpecError as exc:
        print(f"twin campaign: error: {exc}", file=sys.stderr)
        return 2
    if args.only:
        bad = [i for i in args.only if not 0 <= i < len(campaign.scenarios)]
        if bad:
            print(f"twin campaign: error: --only: no scenario {bad[0]} (0 to {len(campaign.scenarios) - 1})", file=sys.stderr)
            return 2
    if args.list:
        for sc in campaign.scenarios:
            exp = ", ".join(f"{k}={v}" for k, v in expectations(campaign, sc).items())
            print(f"{sc.index:4d}  {sc.name}  ->  {exp}")
        return 0
    if args.cluster:
        try:
            backend = DaskBackend(args.cluster, timeout=args.timeout)
        except RuntimeError as exc:
            print(f"twin campaign: error: {exc}", file=sys.stderr)
            return 2
    else:
        backend = LocalBackend(args.workers or os.cpu_count() or 1, timeout=args.timeout)
    out = Path(args.out) if args.out else Path("campaign-results") / Path(args.spec).stem
    if Path(args.spec).stem == "campaign":
        out = Path(args.out) if args.out else Path("campaign-results") / Path(args.spec).resolve().parent.name
    try:
        result = run_campaign(campaign, backend, out, resume=args.resume, indices=args.only, quiet=args.quiet,
                              max_recordings=max(0, args.recordings))
    except RuntimeError as exc:
        print(f"twin campaign: error: {exc}", file=sys.stderr)
        return 2
    sys.stdout.write((out / "summary.txt").read_text())
    print(f"results: {out / 'results.csv'}, {out / 'junit.xml'}")
    return 0 if result.ok else 1
