# SPDX-License-Identifier: Apache-2.0
"""`--live`: a run's channels served over the Foxglove WebSocket protocol while it flies
(docs/recording.md)."""
