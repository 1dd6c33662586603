# SPDX-License-Identifier: Apache-2.0
"""Prints a run's summary (ima.launch.summary) on the terminal: the flight judged from the
truth, the mission flown leg by leg (with --mission), then, with several nodes, what the
redundancy did."""

from __future__ import annotations


def _fmt(v, unit: str, d: int = 1) -> str:
    return "-" if v is None else f"{v:.{d}f} {unit}"


def print_flight(s: dict, console) -> None:
    from rich.table import Table

    console.rule(f"Flight summary — {s['run_dir']}")
    state = "[red]CRASHED[/]" if s["crashed"] else "[green]flying[/]"
    console.print(f"Flown {s['flown_s']:.0f} s emulated in {s.get('wall_s', 0):.1f} s wall "
                  f"(×{s.get('speedup') or 0:.0f}); aircraft {state}")
    console.print("Tracking error, judged on the truth over the hold segments:")
    t = Table(show_edge=False)
    for col in ("", "max |error|", "RMS"):
        t.add_column(col, justify="right")
    t.add_row("altitude", _fmt(s["alt_err_ft_max"], "ft"), _fmt(s["alt_err_ft_rms"], "ft"))
    t.add_row("airspeed", _fmt(s["airspeed_err_kt_max"], "kt"),
              _fmt(s["airspeed_err_kt_rms"], "kt"))
    t.add_row("heading", _fmt(s["heading_err_deg_max"], "°"), _fmt(s["heading_err_deg_rms"], "°"))
    console.print(t)
    segs = ", ".join(f"{g['t0_s']:.0f}–{g['t1_s']:.0f} s" for g in s["hold_segments"]) or "none"
    console.print(f"Hold segments judged: {segs}; max bank {s['bank_deg_max']:.1f}°")
    modes = " → ".join(f"{m['mode']}@{m['t_s']:.0f}s"
                       + (f" ({m['fallback']})" if m["fallback"] not in (None, "NONE") else "")
                       for m in s["mode_changes"]) or "none reported"
    console.print(f"Flight-control modes (downlink): {modes}")
    load, peak = (s.get("bus_load") or 0) * 100, (s.get("bus_load_max_1s") or 0) * 100
    console.print(f"CAN bus: {s.get('can_frames') or 0} frames, load {load:.1f} % (max 1 s: "
                  f"{peak:.1f} %), error frames {s.get('can_error_frames') or 0}")
    console.print(f"Health-monitor events: {s['hm_events']}")
    if s.get("plot"):
        console.print(f"Plot: {s['plot']}")
    for ev in s["hm_event_list"][:5]:
        console.print(f"  {ev['t_ns'] / 1e9:9.3f} s {ev['node']}/{ev.get('partition')}: "
                      f"{ev.get('error')} → {ev.get('action')}", markup=False)
    _print_host_stalls(s.get("host_stalls") or [], s.get("host_stall_count"), console)


def _print_host_stalls(stalls: list[dict], count: int | None, console) -> None:
    """Windows kept past their CPU budget by partitions no fault acts on (host_stalls, of
    which there are `count`)."""
    if not stalls:
        return
    first = stalls[0]
    n = max(count or 0, len(stalls))
    more = f" (and {n - 1} more)" if n > 1 else ""
    console.print(f"Warning: {first['node']}/{first['partition']} kept a window past its CPU "
                  f"budget at {first['t_ns'] / 1e9:.3f} s{more} with no fault on it. The RPAS "
                  "partitions use a small part of their budgets: the host stalled it (a "
                  "preempted virtual CPU, memory reclaim), and from there this flight is not "
                  "the one a quiet host flies. Fly it again to compare.",
                  style="yellow", markup=False)


def _pair(a, b, d: int = 1, sep: str = " / ") -> str:
    """"a / b" with d decimals; "-" when neither is known."""
    if a is None and b is None:
        return "-"
    return sep.join("-" if v is None else f"{v:.{d}f}" for v in (a, b))


def _at(t_s) -> str:
    return "-" if t_s is None else f"{t_s:.1f} s"


def _legs_flown(m: dict, legs: list[dict]) -> str:
    """"4/4 legs flown (and 2 of procedures)": the mission's legs (its IF is not flown) and the
    contingency procedures' legs, as the judge counted them."""
    planned, flown, extra = (m.get(k) for k in ("legs_planned", "legs_flown",
                                                  "procedure_legs_flown"))
    if not all(isinstance(x, int) for x in (planned, flown, extra)):
        return f"{len(legs)} legs flown"
    return f"{flown}/{planned} legs flown" + (f" (and {extra} of procedures)" if extra else "")


def _print_landing(a: dict | None, console) -> None:
    """The automatic landing's outcome (ima.mission.flown.autoland), one or two lines."""
    if not a:
        return
    if a.get("crashed"):
        console.print(f"Landing on {a['runway']}: crashed ({a.get('crash_reason')})",
                      markup=False)
        return
    if not a.get("landed"):
        console.print(f"Landing on {a['runway']}: not reached in the flight", markup=False)
        return
    stop = ("stopped {:.0f} m from the threshold{}".format(
        a["stop_from_threshold_m"], ", on the runway" if a["stopped_on_runway"] else
        ", OFF the runway") if a.get("stopped") else "not stopped by the end of the flight")
    console.print(f"Landing on {a['runway']}: touchdown at {a['touchdown_t_s']:.1f} s, "
                  f"{a['touchdown_from_aim_m']:+.0f} m from the aim point, "
                  f"{a['centerline_m']:.1f} m off the centre line, sink {a['sink_fps']:.1f} "
                  f"ft/s, {'bounced' if a['bounced'] else 'no bounce'}; {stop}", markup=False)


def print_mission(s: dict, console) -> None:
    """The mission flown (ima.mission.flown.judge): each leg's accuracy, the contingencies,
    the track's PNG."""
    from rich.markup import escape
    from rich.table import Table

    m = s.get("mission") or {}
    legs = s.get("legs") or []
    final = m.get("final_state") or "no state reported"
    at = f" at leg {m['final_leg']}" if m.get("final_leg") not in (None, -1) else ""
    console.print(f"Mission {escape(str(m.get('plan', '?')))} (plan {m.get('plan_id', '?')}, "
                  f"{m.get('node', '?')}'s mission manager): {final}{at}; "
                  f"{_legs_flown(m, legs)}")
    if legs:
        console.print("Legs, judged on the truth from their capture (xte: cross-track error):")
        # the label is "INDEX TYPE" unless the judge names legs otherwise: then it has a column
        labelled = any(g.get("label") != f"{g.get('index')} {g.get('type')}" for g in legs)
        t = Table(show_edge=False)
        for col in ("leg", "type") + (("label",) if labelled else ()) + (
                "time", "xte p95 / max", "alt err p95 / max", "airspeed", "captured"):
            t.add_column(col, justify="left" if col in ("type", "label") else "right")
        for g in legs:
            captured = "yes" if g.get("captured") else "[red]no[/]"
            row = [str(g.get("index")), escape(str(g.get("type")))]
            if labelled:
                row.append(escape(str(g.get("label"))))
            row += [_pair(g.get("t_start_s"), g.get("t_end_s"), sep="–") + " s",
                    _pair(g.get("xte_m_p95"), g.get("xte_m_max")) + " m",
                    _pair(g.get("alt_err_m_p95"), g.get("alt_err_m_max")) + " m",
                    _pair(g.get("ias_kt_min"), g.get("ias_kt_max"), sep="–") + " kt", captured]
            t.add_row(*row)
        console.print(t)
    else:
        console.print("No leg of the plan flown")
    conts = s.get("contingencies") or []
    if conts:
        console.print("Contingencies:")
        t = Table(show_edge=False)
        for col in ("event", "declared", "procedure", "began", "resumed", "resumed at leg"):
            t.add_column(col, justify="left" if col in ("event", "procedure") else "right")
        for c in conts:
            declared = _at(c.get("t_s")) + (f" (leg {c['leg']})" if c.get("leg") is not None
                                            else "")
            t.add_row(escape(str(c.get("event"))), declared, escape(str(c.get("procedure") or "-")),
                      _at(c.get("procedure_t_s")), _at(c.get("resumed_t_s")),
                      "-" if c.get("resumed_leg") is None else str(c["resumed_leg"]))
        console.print(t)
    else:
        console.print("Contingencies: none declared")
    _print_landing(s.get("autoland"), console)
    if s.get("track_png"):
        console.print(f"track: {s['track_png']}", markup=False)
    elif s.get("track_error"):
        console.print(f"track: not written: {s['track_error']}", markup=False)


def print_redundancy(s: dict, console) -> None:
    killed = ", ".join([f"{k['node']}@{k['t_s']:g}s (killed)" for k in s["killed"]]
                       + [f"{k['node']}@{k['t_s']:g}s (hung)" for k in s.get("hung", [])]) or "none"
    console.print(f"Nodes: {', '.join(s['nodes'])}; stopped on purpose: {killed}")
    vo = ", ".join(f"{v['node']}@{v['t_s']:.3f}s ({v['reason']})" for v in s["voted_out"]) or "none"
    console.print(f"Voted out by the actuators: {vo}; final vote {s.get('vote_status') or '-'}")
    agreed = "agreed" if s.get("membership_agreed") else "[red]NOT agreed[/]"
    console.print(f"Membership ({agreed}): {', '.join(s.get('membership') or []) or '-'}")
    for ev in s.get("membership_events", [])[:6]:
        console.print(f"  {ev['t_s']:9.3f} s {ev['node']}: {','.join(ev['members'])}")
    for ev in s.get("monitor_reports", [])[:6]:
        console.print(f"  {ev['t_s']:9.3f} s {ev['node']} monitor: {ev['text']}", markup=False)


def print_refused(s: dict, console) -> None:
    """Who stopped the run early, and what its processes refused (docs/security.md)."""
    if s.get("stopped_by") not in (None, "signal"):  # Ctrl-C says so at the top already
        console.print(f"Run stopped early by {s['stopped_by']}", markup=False)
    refused = s.get("refused") or []
    if refused:
        console.print(f"[bold yellow]Refused[/] {len(refused)} time(s) (summary.json "
                      "`refused`):")
        for e in refused[:5]:
            console.print(f"  {e.get('by')}: {e['what']}: {e['detail']}", markup=False)


def print_summary(s: dict, console) -> None:
    if s.get("interrupted"):
        at = s.get("interrupted_at_s")
        console.print("[bold yellow]Interrupted[/] (Ctrl-C)" +
                      (f" at {at:g} s of emulated time" if at is not None else "") +
                      ": what follows is the run up to there")
    print_flight(s, console)
    if "legs" in s:
        print_mission(s, console)
    if len(s.get("nodes", [])) > 1:
        print_redundancy(s, console)
    else:
        killed = [f"{k['node']}@{k['t_s']:g}s" for k in s.get("killed", [])]
        if killed:
            console.print(f"Node stopped on purpose: {', '.join(killed)}")
    print_refused(s, console)
