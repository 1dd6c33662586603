# SPDX-License-Identifier: Apache-2.0
"""`ima launch`: a whole system model (several emulated processors) flown in the world."""
