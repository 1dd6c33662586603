# SPDX-License-Identifier: Apache-2.0
"""The launcher's watch over a run's processes: a node the run kills is killed, not failed,
even when the run ends before the watch's next look."""

from __future__ import annotations

import signal
from types import SimpleNamespace

from ima.launch import procs


def _procs(**codes: int) -> SimpleNamespace:
    return SimpleNamespace(procs={name: SimpleNamespace(returncode=code)
                                  for name, code in codes.items()},
                           failed={})


def test_a_kill_the_run_ended_too_soon_to_see_is_a_kill():
    ps = _procs(node1=0, node2=-signal.SIGKILL, node3=-signal.SIGTERM, world=0)
    watch = procs.Watch(ps, {"node2": 3.0, "node3": 5.0}, stop_run=lambda: True)
    watch.settle()
    # node2 was killed by the bus; node3's kill never came (the run's end stopped it)
    assert watch.killed == {"node2": 3.0}


def test_a_node_the_run_did_not_kill_is_not_made_a_kill():
    ps = _procs(node1=-signal.SIGKILL, node2=0)
    watch = procs.Watch(ps, {"node2": 3.0}, stop_run=lambda: True)
    watch.settle()
    assert watch.killed == {}
