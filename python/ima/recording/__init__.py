# SPDX-License-Identifier: Apache-2.0
"""The recording of a run: RUN_DIR/run.mcap, one MCAP file with every trace of the run on
channels of their own, JSON-encoded with a JSON schema each (Foxglove decodes them; the
world's position and attitude also as foxglove.LocationFix and foxglove.PoseInFrame).
docs/recording.md lists every channel."""
