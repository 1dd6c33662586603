# SPDX-License-Identifier: Apache-2.0
"""Command line of the world process: python -m imaworld --bus SOCK --run-dir DIR ..."""

from __future__ import annotations

import argparse
import math
import signal
import sys
from pathlib import Path

from ima.errors import ImaError

from .config import VotingParams

TEST_SWITCHES = ("no-vote-out", "every-quantum", "python-only")


def _fault_classes() -> str:
    from .faults import describe

    return describe()


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="python -m imaworld",
        description="The simulated world (JSBSim aircraft, sensors, smart actuators, wind, "
                    "C2 link, remote pilot station) as a LOCKSTEP client of the CAN bus.")
    ap.add_argument("--bus", required=True, help="the bus socket (ima-canbus --socket)")
    ap.add_argument("--run-dir", required=True, help="where truth.jsonl, world.jsonl and "
                    "world.json go")
    ap.add_argument("--seed", type=int, default=0, help="seed of every random process")
    ap.add_argument("--pilot", required=True, help="remote pilot station script (YAML)")
    ap.add_argument("--turbulence", choices=["none", "light", "moderate"], default=None,
                    help="MIL-F-8785C turbulence (JSBSim Milspec; default: the script's, "
                    "else none)")
    ap.add_argument("--wind", type=float, default=None, metavar="KT",
                    help="steady wind speed in kt (default: the script's, else calm)")
    ap.add_argument("--wind-from", type=float, default=None, metavar="DEG",
                    help="direction the wind blows from, degrees true (default 270)")
    ap.add_argument("--terrain-ft", type=float, default=500.0,
                    help="elevation of the flat terrain (ft MSL, default 500)")
    ap.add_argument("--channels", type=int, choices=(1, 2, 3), default=None,
                    help="flight-control replicas commanding the actuators on ACT_CMD_A..; "
                    "given, the actuators vote over them as the four --vote-* options say "
                    "(default: one, not voted: the lowest live channel is used)")
    ap.add_argument("--vote-threshold", default=None, metavar="ELEV,AIL,RUD,THR",
                    help="miscompare thresholds of the vote per axis, normalised (the system "
                    "model's voting.thresholds)")
    ap.add_argument("--vote-persist", type=int, default=None, metavar="N",
                    help="consecutive bad votes before a channel is voted out (voting.persist)")
    ap.add_argument("--vote-offset", type=float, default=None, metavar="S",
                    help="when the actuators vote in each frame, in seconds from its start "
                    "(voting.offset_s)")
    ap.add_argument("--vote-period", type=float, default=None, metavar="S",
                    help="the voting frame: the system's major frame (schedule.major_frame_s)")
    ap.add_argument("--fault", action="append", default=[], metavar="SPEC",
                    help="inject a fault (repeatable): CLASS:fid=ID,at=TIME[,until=TIME]"
                    "[,period=TIME,on=TIME][,KEY=VALUE...] (faultinject/include/fi/spec.h); "
                    "classes: " + _fault_classes())
    ap.add_argument("--test-switch", action="append", default=[], choices=TEST_SWITCHES,
                    metavar="NAME",
                    help="TEST ONLY: no-vote-out makes the actuators' voter never vote a "
                    "channel out (to show that a campaign oracle can fail); every-quantum makes "
                    "the world ask for every quantum of the bus, not only those a task of it "
                    "falls in (to show that the quanta it skips change nothing); python-only "
                    "makes it run its Python where it has C++: the physics steps, the AHRS, the "
                    "air data and the truth (to show that the C++ changes nothing)")
    ap.add_argument("--uplink", action="append", default=[], metavar="T:FILE",
                    help="uplink the mission plan image FILE (`ima mission` compiles one) over "
                    "the C2 link at T seconds; repeatable (a later plan replaces the earlier)")
    ap.add_argument("--status", action="store_true",
                    help="print one JSON progress line per emulated second on stdout")
    ap.add_argument("--name", default="world", help="client name on the bus")
    ap.add_argument("--debug", action="store_true", help="show tracebacks")
    return ap


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return run(args)
    except ImaError as e:
        if args.debug:
            raise
        print(f"imaworld: {e}", file=sys.stderr)
        return e.exit_code


_VOTE_OPTIONS = ("vote_threshold", "vote_persist", "vote_offset", "vote_period")


def vote_options(args) -> dict:
    """The voting options as World Options fields; ImaError (exit 2) when one is bad. The
    world has no voting settings of its own: with --channels every --vote-* option is given
    (ima launch passes the system model's)."""
    given = [f"--{k.replace('_', '-')}" for k in _VOTE_OPTIONS if getattr(args, k) is not None]
    if args.channels is None:
        if given:
            raise ImaError(f"{', '.join(given)}: only with --channels (without it nothing is "
                           "voted)", exit_code=2)
        return {"channels": None, "voting": None}
    thr: tuple = ()
    if args.vote_threshold is not None:
        try:
            thr = tuple(float(x) for x in args.vote_threshold.split(","))
        except ValueError:
            thr = ()
        if len(thr) != 4 or not all(0 <= x < math.inf for x in thr):  # also refuses NaN
            raise ImaError(f"--vote-threshold {args.vote_threshold!r}: expected four numbers "
                           ">= 0, elev,ail,rud,thr", exit_code=2)
    if args.vote_persist is not None and args.vote_persist < 1:
        raise ImaError("--vote-persist must be at least 1", exit_code=2)
    period = args.vote_period
    if period is not None and not 0 < period < math.inf:
        raise ImaError(f"--vote-period {period:g}: must be a positive number of seconds",
                       exit_code=2)
    if args.vote_offset is not None and period is not None and not 0 <= args.vote_offset < period:
        raise ImaError(f"--vote-offset {args.vote_offset:g}: must be within the {period:g} s "
                       f"major frame, 0 <= S < {period:g}", exit_code=2)
    missing = [f"--{k.replace('_', '-')}" for k in _VOTE_OPTIONS if getattr(args, k) is None]
    if missing:
        raise ImaError(f"--channels {args.channels}: the vote needs {', '.join(missing)} too "
                       "(the system model's voting; ima launch passes them)", exit_code=2)
    return {"channels": args.channels,
            "voting": VotingParams(thr, args.vote_persist, args.vote_offset, period)}


def fault_options(args) -> list:
    """The --fault specs, parsed and checked against the world's classes (ImaError, exit 2,
    one line, when one is bad)."""
    from .config import DEFAULT
    from .faults import check_all
    from .faultspec import parse

    specs = [parse(text) for text in args.fault]
    check_all(specs, DEFAULT.faults)
    return specs


def uplink_options(args) -> list[tuple[int, bytes]]:
    """The --uplink plans: [(t_ns, image)]; ImaError (exit 2, one line) when one is bad."""
    from .config import NS
    from .uplink import MAX_IMAGE

    out = []
    for text in args.uplink:
        t, sep, path = text.partition(":")
        try:
            t_s = float(t)
        except ValueError:
            t_s = math.nan
        if not sep or not 0 <= t_s < math.inf:
            raise ImaError(f"--uplink {text!r}: expected T:FILE, T seconds >= 0", exit_code=2)
        try:
            image = Path(path).read_bytes()
        except OSError as e:
            raise ImaError(f"--uplink {text!r}: cannot read {path}: {e.strerror}",
                           exit_code=2) from e
        if not 0 < len(image) <= MAX_IMAGE:
            raise ImaError(f"--uplink {text!r}: {len(image)} bytes is no plan image",
                           exit_code=2)
        out.append((round(t_s * NS), image))
    return out


def run(args) -> int:
    from ima.canbus import proto
    from ima.canbus.client import BusClient

    from . import pilot
    from .fdm import quiet_stdout
    from .world import Options, World

    script = pilot.load(args.pilot)  # bad scripts fail before we join the bus
    if args.wind is not None and args.wind < 0:
        raise ImaError("--wind must not be negative", exit_code=2)
    voting = vote_options(args)
    faults = fault_options(args)
    uploads = uplink_options(args)
    status_out = quiet_stdout()  # JSBSim prints to stdout; only --status lines may go there
    opts = Options(seed=args.seed, turbulence=args.turbulence or script.turbulence or "none",
                   wind_kt=args.wind, wind_from_deg=args.wind_from,
                   terrain_ft=args.terrain_ft, status=args.status, faults=faults,
                   test_switches=tuple(dict.fromkeys(args.test_switch)), uploads=uploads,
                   **voting)
    if script.start["altitude_ft"] - opts.terrain_ft < 200:
        raise ImaError(f"{args.pilot}: start.altitude_ft {script.start['altitude_ft']} is less "
                       f"than 200 ft above the terrain ({opts.terrain_ft} ft)", exit_code=2)
    # Trim before joining: a start the aircraft cannot fly never holds up the bus.
    world = World(None, script, args.run_dir, opts,
                  status_out=status_out if args.status else None)
    world.bus = bus = BusClient(args.bus, args.name, proto.ROLE_CAN | proto.ROLE_LOCKSTEP)

    def interrupt(_signum: int, _frame: object) -> None:
        world.interrupted = True  # the run loop stops the bus at the end of this quantum

    for s in (signal.SIGTERM, signal.SIGINT):
        signal.signal(s, interrupt)
    try:
        return world.run()
    finally:
        bus.close()


if __name__ == "__main__":
    sys.exit(main())
