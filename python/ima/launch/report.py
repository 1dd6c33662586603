# SPDX-License-Identifier: Apache-2.0
"""Prints a run's summary (ima.launch.summary) on the terminal: the flight judged from the
truth, then, with several nodes, what the redundancy did."""

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
    if len(s.get("nodes", [])) > 1:
        print_redundancy(s, console)
    else:
        killed = [f"{k['node']}@{k['t_s']:g}s" for k in s.get("killed", [])]
        if killed:
            console.print(f"Node stopped on purpose: {', '.join(killed)}")
    print_refused(s, console)
