# SPDX-License-Identifier: Apache-2.0
"""Null and invalid addresses given to APEX services: never a raw SIGSEGV.

"faults": each pointer parameter the APEX headers declare, null in turn, a null RETURN_CODE
and addresses the partition cannot read or write are the caller's ILLEGAL_REQUEST for the
health monitor, as an invalid message address always was, and write no output; here the
module handles it at process level, so the error handler sees each one and the victim process
only stops.

"nulls": the documented exceptions, where a null is not an address the service uses:
REPORT_APPLICATION_MESSAGE with LENGTH 0 reads nothing, so a null address is accepted;
CREATE_ERROR_HANDLER answers a null ENTRY_POINT with INVALID_CONFIG, as the standard's "entry
point" check does; CREATE_PROCESS a null ENTRY_POINT field of its attributes with
INVALID_PARAM.
"""

import re

from ima import apex_coverage

FRAMES = 24

# Where a null pointer is not the caller's ILLEGAL_REQUEST (docs/apex-coverage.md).
NULL_EXCEPTIONS = {
    "CREATE_ERROR_HANDLER.ENTRY_POINT": "INVALID_CONFIG",
    "REPORT_APPLICATION_MESSAGE.MESSAGE_ADDR_LENGTH_0": "NO_ERROR",
    "CREATE_PROCESS.ENTRY_POINT": "INVALID_PARAM",
}
# Pointer cases beyond the parameters: a field of a parameter, another length.
NULL_EXTRA = ["CREATE_PROCESS.ENTRY_POINT", "REPORT_APPLICATION_MESSAGE.MESSAGE_ADDR_LENGTH_0"]
BAD_ADDRESSES = [
    "bad.RETURN_CODE_read_only",
    "bad.GET_TIME.SYSTEM_TIME",
    "bad.GET_PARTITION_STATUS.PARTITION_STATUS",
    "bad.CREATE_PROCESS.ATTRIBUTES",
    "bad.GET_PROCESS_ID.PROCESS_NAME",
    "bad.READ_SAMPLING_MESSAGE.LENGTH",
    "bad.GET_SAMPLING_PORT_CURRENT_STATUS.read_only",
    "bad.SEND_BUFFER.MESSAGE_ADDR",
]

_DECL = re.compile(r"^extern void ([A-Z_]+)\s*\((.*?)\);", re.M | re.S)
_PARAM = re.compile(r"/\*(in |out)\*/\s*([^,]*?)\s*(\w+)\s*(?:,|$)")
_POINTER_TYPES = ("MESSAGE_ADDR_TYPE", "SYSTEM_ADDRESS_TYPE")


def pointer_parameters() -> list[str]:
    """SERVICE.PARAMETER for every pointer parameter of every declared service but RETURN_CODE."""
    include = apex_coverage.paths.repo_root() / "ske" / "apex" / "include"
    found = []
    for header in sorted(include.glob("apex_*.h")):
        for service, params in _DECL.findall(header.read_text()):
            for _, ptype, name in _PARAM.findall(params.replace("\n", " ")):
                pointer = ptype.endswith("*") or ptype in _POINTER_TYPES
                if pointer and name != "RETURN_CODE":
                    found.append(f"{service}.{name}")
    return found


def _null_checks() -> dict:
    table = {}
    for case in NULL_EXCEPTIONS:
        table[case] = NULL_EXCEPTIONS[case]
        table[f"untouched.{case}"] = "yes"
    return table


def _illegal_nulls() -> list[str]:
    return [c for c in pointer_parameters() + NULL_EXTRA if c not in NULL_EXCEPTIONS]


def _fault_checks() -> dict:
    services = [s for s, _ in apex_coverage.services() if s != "STOP_SELF"]
    table = {f"rc_null.{s}": "ILLEGAL_REQUEST" for s in services + BAD_ADDRESSES}
    for case in _illegal_nulls():
        table[f"null.{case}"] = "ILLEGAL_REQUEST"
        table[f"untouched.{case}"] = "yes"
    table["rc_null.message"] = "yes"
    table["rc_null.cases_run"] = len(services) + len(BAD_ADDRESSES) + len(_illegal_nulls())
    return table


CHECKS = {"nulls": _null_checks(), "faults": _fault_checks()}


def test_every_check_reported(apex):
    apex.assert_complete(CHECKS)


def test_check(apex, check):
    apex.assert_check(*check)


def test_the_tables_cover_the_headers():
    # Every service but STOP_SELF has a RETURN_CODE; a parser that found too few pointer
    # parameters would make the null table pass vacuously.
    assert len(pointer_parameters()) >= 60
    assert len(_illegal_nulls()) >= 60
    assert len(_fault_checks()) >= 124


def test_faults_are_illegal_requests_decided_at_process_level(apex):
    apex.assert_ran()
    hm = apex.of_kind("hm")
    assert hm, "no health-monitor decision recorded"
    assert {(e["partition"], e["error"], e["level"], e["action"], e["process"]) for e in hm} == {
        ("faults", "ILLEGAL_REQUEST", "PROCESS", "ERROR_HANDLER", "victim")
    }
    assert len(hm) == CHECKS["faults"]["rc_null.cases_run"]
    assert all(e["message"].startswith("APEX service given an invalid address") for e in hm)


def test_no_partition_was_stopped(apex):
    apex.assert_ran()
    assert not apex.of_kind("partition_exit")
    assert all(w.get("partition_state", "running") != "idle" for w in apex.of_kind("window_start"))
