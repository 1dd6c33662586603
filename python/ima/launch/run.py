# SPDX-License-Identifier: Apache-2.0
"""Runs a system model: deploys it, then the CAN bus, one DDS agent and one ima-ske per node,
and the world, in lockstep, in a run directory. `ima launch`, `ima fly` (the one-node system)
and `ima demo` all run through here.

The order is fixed so that the run is deterministic: the bus; every node's DDS agent (with
more than one node; each waits until it has discovered the others, then says `ready`); every
node's SKE, joining the bus in node order; the world (the last lockstep client: T=0 starts
when it joins).

Files in the run directory:
  deploy/        the system deployed: one module per node, the C glue (ima deploy)
  launch.json    how the run was started (system, domain ID, commands, faults)
  can.jsonl      every frame on the bus; canbus.json its statistics; canbus.log
  nodeK.jsonl    node K's SKE trace (schedule, HM, partition reports); nodeK.json; nodeK.log
  ddsK.jsonl     node K's DDS agent trace (wall clock); ddsK.json its statistics; nodeK-dds.log
  dds-security/  the run's DDS Security certificates and signed documents (ima.dds.security)
  truth.jsonl    the aircraft's true state; world.jsonl, world.json, world.log
  summary.json   written by ima.launch.summary, with flight.png
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import threading
import time
from collections.abc import Callable
from pathlib import Path

from ima import outdir
from ima.canbus.control import BusControl
from ima.deploy.model import canbus_socket_name, dds_socket_name
from ima.errors import ImaError
from ima.launch import commands, procs
from ima.launch import faults as fault_plan
from ima.launch.options import (
    TURBULENCE,
    LaunchOptions,
    LaunchRun,
    default_pilot,
    new_run_dir,
    socket_dir,
)

_READY_TIMEOUT_S = 60.0
_WORLD_STOP_S = 5.0  # Ctrl-C: how long the world has to stop the bus itself


def launch(opts: LaunchOptions, on_status: Callable[[dict], None] | None = None,
           stop_when: Callable[[dict], bool] | None = None, system=None) -> LaunchRun:
    """Runs the system to its end (or Ctrl-C, or the first status line `stop_when` accepts);
    the caller summarises the run directory. `system`: opts.system already loaded (a
    campaign's worker reads it once)."""
    from ima import dds
    from ima.deploy import generate, load_system
    from imaworld import pilot as pilot_script

    if opts.turbulence not in TURBULENCE:
        raise ImaError(f"--turbulence must be one of {', '.join(TURBULENCE)}")
    if not opts.duration_s > 0:
        raise ImaError("--duration must be positive")
    if system is None:
        system = load_system(Path(opts.system))
    names = [n.name for n in system.nodes]
    if opts.netns and os.geteuid() != 0:
        raise ImaError("--netns needs root (it creates network namespaces)")
    pilot = Path(opts.pilot) if opts.pilot else default_pilot(opts.mission is not None)
    pilot_script.load(pilot)  # a bad script is reported before anything starts
    images: list[bytes] = []
    if opts.replan and opts.mission is None:
        raise ImaError("--replan replaces the plan of --mission: give --mission too", exit_code=2)
    if opts.mission is not None:  # a bad plan too
        from ima.mission import image as plan_image
        from ima.mission import plan as mission_plan

        images = [plan_image.encode(mission_plan.load(p))
                  for p in [opts.mission, *(p for _, p in opts.replan)]]

    run_dir = Path(opts.run_dir) if opts.run_dir else new_run_dir(opts.kind, opts.seed)
    outdir.usable_dir(run_dir, "run directory")
    run_dir = run_dir.resolve()  # the nodes run in the socket directory: paths are absolute
    for k, image in enumerate(images):  # the plan, then the replacements (commands.plan)
        (run_dir / ("mission.img" if k == 0 else f"mission-{k}.img")).write_bytes(image)
    plan = fault_plan.prepare(opts, system, run_dir, launch)
    kills, hangs = plan.kills, plan.hangs
    both = sorted(set(kills) & set(hangs))
    if both:
        raise ImaError(f"{', '.join(both)}: a node is either killed or hung, not both")
    deployed = generate(system, run_dir / "deploy",
                        {(node, "io"): words for node, words in plan.io.items()})
    sock_dir, sock_tmp = socket_dir(run_dir)
    domain = dds.domain_for_run() if len(names) > 1 else None
    try:
        security = None
        if domain is not None:
            from ima.dds import security as dds_security

            mode = opts.dds_security or system.dds.get("security", dds_security.DEFAULT_MODE)
            material = dds_security.prepare(run_dir, len(names), domain, mode)
            security = material.dir if material is not None else None
        return _fly(opts, system, names, run_dir, pilot, deployed, plan, sock_dir, sock_tmp,
                    domain, on_status, stop_when, security)
    finally:
        # Every process of the run has ended: its DDS domain is free for the next run (a
        # campaign's worker launches hundreds of runs from one process).
        if domain is not None:
            dds.release_domain(domain)


def _fly(opts, system, names, run_dir, pilot, deployed, plan, sock_dir, sock_tmp, domain,
         on_status, stop_when, security) -> LaunchRun:
    kills, hangs = plan.kills, plan.hangs
    procs_plan = commands.plan(system, opts, run_dir, sock_dir, pilot, deployed.modules, plan,
                               domain, security)
    # The launcher's channels, inherited, never paths: the bus's control channel (faults,
    # stop) and, per agent, the pipe that tells it its node's SKE (only that SKE's partitions
    # may be its io).
    control = BusControl()
    procs_plan.bus += ["--control-fd", str(control.child_fd)]
    ske_pipes = {name: os.pipe() for name in procs_plan.agents}  # agent -> (read, write)
    for name, (r, _) in ske_pipes.items():
        procs_plan.agents[name] = procs_plan.agents[name] + ["--ske-pid-fd", str(r)]
    open_fds = {fd for pipe in ske_pipes.values() for fd in pipe}  # closed once, at most
    (run_dir / "launch.json").write_text(json.dumps({
        "kind": opts.kind, "system": str(system.path), "nodes": names, "seed": opts.seed,
        "duration_s": opts.duration_s, "pilot": str(pilot), "turbulence": opts.turbulence,
        "mission": str(Path(opts.mission).resolve()) if opts.mission else None,
        "wind_kt": opts.wind_kt, "wind_from_deg": opts.wind_from_deg, "realtime": opts.realtime,
        "host_cpus": len(os.sched_getaffinity(0)), "quantum_us": opts.quantum_us,
        "dds_domain": domain,
        "dds_config": str(system.dds["config"]),
        "dds_security": str(security) if security is not None else None,
        "faults": [{"id": f.fid, "spec": f.spec(), "class": f.cls, "t_s": f.trigger.at_s}
                   for f in plan.faults],
        "netns": opts.netns, "socket": str(procs_plan.bus_socket), "socket_dir": str(sock_dir),
        "modules": {k: str(v) for k, v in deployed.modules.items()},
        "commands": {"canbus": procs_plan.bus, "world": procs_plan.world, **procs_plan.agents,
                     **procs_plan.nodes},
    }, indent=2) + "\n")

    ps = procs.Processes(run_dir)
    interrupted = False
    t0 = time.monotonic()
    previous = {}
    watch: procs.Watch | None = None
    hung: dict[str, float] = {}  # node -> emulated time the bus froze it
    netns = None

    def on_signal(signum: int, _frame: object) -> None:
        nonlocal interrupted
        again = interrupted
        interrupted = True
        if watch is not None:
            watch.stopping.set()
        bus, world = ps.procs.get("canbus"), ps.procs.get("world")
        running = bus is not None and bus.poll() is None
        if running and not again and world is not None and world.poll() is None:
            # The world first: it ends its quantum, asks the bus to stop and closes its traces,
            # so that every trace is complete up to the stop. The bus is told itself if the
            # world has not done it within a few seconds, or at a second Ctrl-C.
            world.send_signal(signal.SIGTERM)
            t = threading.Timer(_WORLD_STOP_S, lambda: bus.poll() is None
                                and bus.send_signal(signal.SIGTERM))
            t.daemon = True
            t.start()
        elif running:
            bus.send_signal(signal.SIGTERM)  # the bus ends the run for everyone
        else:  # still starting: stop what has started
            ps.signal_all(signal.SIGTERM)

    try:
        if threading.current_thread() is threading.main_thread():  # (a Dask worker's is not)
            for s in (signal.SIGINT, signal.SIGTERM):
                previous[s] = signal.signal(s, on_signal)
        if opts.netns:
            from ima.launch import netns as netns_mod

            netns = netns_mod.Namespaces(names, run_dir)
            netns.create()
        ps.start("canbus", procs_plan.bus, pass_fds=(control.child_fd,))
        control.started()
        procs.wait_for_socket(procs_plan.bus_socket, ps)
        _link(run_dir / canbus_socket_name(), procs_plan.bus_socket)
        agents = {}
        for name, cmd in procs_plan.agents.items():
            node = name.split("/")[0]
            if netns is not None:
                cfg = netns.dds_config(node, run_dir)
                cmd = netns.wrap(node, [c if c != str(system.dds["config"]) else str(cfg)
                                        for c in cmd] + ["--bind-device", netns.device])
            agents[name] = ps.start(name, cmd, stdout=subprocess.PIPE,
                                    pass_fds=(ske_pipes[name][0],))
            _close(open_fds, ske_pipes[name][0])
        procs.wait_ready(agents, ps, _READY_TIMEOUT_S)
        netns_pids: list[int] = []
        for k, node in enumerate(names, start=1):
            cmd = procs_plan.nodes[node]
            if netns is not None:
                cmd = netns.wrap(node, cmd)
            proc = ps.start(node, cmd, cwd=sock_dir)
            # its clients on the bus: the SKE and its partitions
            control.process(next(n.index for n in system.nodes if n.name == node), proc.pid)
            if f"{node}/dds" in ske_pipes:
                _tell_ske(open_fds, ske_pipes[f"{node}/dds"][1], proc.pid)
            if netns is not None:
                netns_pids.append(proc.pid)
            procs.wait_joined(procs_plan.bus_socket, k, ps, pids=tuple(netns_pids))
        world = ps.start("world", procs_plan.world, stdout=subprocess.PIPE)
        control.process(0, world.pid)
        watch = procs.Watch(ps, kills, control.stop)
        threading.Thread(target=watch, daemon=True).start()
        procs.follow_world(world, _watching(on_status, stop_when, control))
        # A hung processor is switched off at the end of the run: its frozen processes would
        # not even take a SIGTERM. Its agent ends with the others.
        for node in hangs:
            proc = ps.procs.get(node)
            if proc is not None and proc.poll() is None:
                if procs.frozen(proc.pid):  # the bus froze it: it never runs again
                    hung[node] = hangs[node]
                ps.kill_group(node)
        # The world has stopped: the bus ends the run within a quantum; then the nodes. The
        # agents end on SIGTERM in stop(), after the nodes.
        ps.wait_all(procs.GRACE_S, skip=lambda name: name.endswith("/dds"))
    finally:
        ps.stop()
        ps.close()
        control.close()
        for fd in list(open_fds):  # of agents never started, or whose SKE never was
            _close(open_fds, fd)
        if netns is not None:
            netns.destroy()
        for s, h in previous.items():
            signal.signal(s, h)
        for name in [canbus_socket_name(), *(dds_socket_name(n.index) for n in system.nodes)]:
            (sock_dir / name).unlink(missing_ok=True)
        if (run_dir / canbus_socket_name()).is_symlink():
            (run_dir / canbus_socket_name()).unlink()
        if sock_tmp is not None:
            shutil.rmtree(sock_tmp, ignore_errors=True)
    wall = time.monotonic() - t0
    if ps.failed:
        raise ImaError("the run stopped early: " + "; ".join(
            f"{k} {v}" for k, v in ps.failed.items()) + f" (run directory {run_dir})")
    if watch is not None:
        watch.settle()
    killed = dict(watch.killed) if watch is not None else {}
    return LaunchRun(run_dir=run_dir, nodes=names, returncodes=ps.returncodes(), wall_s=wall,
                     interrupted=interrupted, killed=killed, domain=domain, hung=hung,
                     plan=plan if plan.faults else None)


def _link(link: Path, target: Path) -> None:
    """RUN_DIR/can.sock, a link to the bus's socket in the run's private socket directory."""
    if link == target:
        return
    try:
        if link.is_symlink():
            link.unlink()
        link.symlink_to(target)
    except OSError:
        pass  # a tool then finds the socket from launch.json's `socket`


def _close(open_fds: set[int], fd: int) -> None:
    """Closes a descriptor of ours once: its number may be another file's afterwards."""
    if fd in open_fds:
        open_fds.discard(fd)
        os.close(fd)


def _tell_ske(open_fds: set[int], w: int, pid: int) -> None:
    """Writes the SKE's pid to its node's agent (--ske-pid-fd), then closes the pipe."""
    try:
        os.write(w, f"{pid}\n".encode())
    except OSError:
        pass  # the agent has gone: the watch reports it
    finally:
        _close(open_fds, w)


def _watching(on_status: Callable[[dict], None] | None, stop_when: Callable[[dict], bool] | None,
              control: BusControl) -> Callable[[dict], None] | None:
    """The world's status lines to on_status; the bus told to end the run at the first one
    stop_when accepts (a run that resolves a fault's condition need go no further)."""
    if stop_when is None:
        return on_status
    stopped = False

    def watch(st: dict) -> None:
        nonlocal stopped
        if on_status is not None:
            on_status(st)
        if not stopped and stop_when(st):
            stopped = True
            control.stop()
    return watch
