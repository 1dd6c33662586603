/* SPDX-License-Identifier: Apache-2.0 */
/* GET_BLACKBOARD_ID (ARINC 653 Part 1, 3.7.2.2): NO_ERROR with the identifier
 * CREATE_BLACKBOARD gave; INVALID_CONFIG for a name no blackboard has (output untouched), during
 * initialisation and in NORMAL mode. The partition period is 20 ms; its window is the first
 * 10 ms of it. */
#include "apex_check.h"

static BLACKBOARD_ID_TYPE first, second;

static void try_get(const char *check, const char *name, RETURN_CODE_TYPE expect,
                    BLACKBOARD_ID_TYPE id_expect)
{
    BLACKBOARD_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    GET_BLACKBOARD_ID(name, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id", check);
    check_int(n, id_expect, id);
}

static void proc(void)
{
    try_get("normal.first", "FIRST", NO_ERROR, first);
    try_get("normal.second", "SECOND", NO_ERROR, second);
    try_get("normal.unknown", "THIRD", INVALID_CONFIG, UNTOUCHED);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    try_get("init.none_created", "FIRST", INVALID_CONFIG, UNTOUCHED);
    CREATE_BLACKBOARD("FIRST", 8, &first, &rc);
    setup_rc("CREATE_BLACKBOARD FIRST", rc);
    CREATE_BLACKBOARD("SECOND", 8, &second, &rc);
    setup_rc("CREATE_BLACKBOARD SECOND", rc);
    check_true("init.distinct", first != second);
    try_get("init.first", "FIRST", NO_ERROR, first);
    try_get("init.second", "SECOND", NO_ERROR, second);
    try_get("init.prefix", "FIRS", INVALID_CONFIG, UNTOUCHED);
    try_get("init.longer", "FIRSTS", INVALID_CONFIG, UNTOUCHED);
    try_get("init.case", "first", INVALID_CONFIG, UNTOUCHED);
    try_get("init.empty", "", INVALID_CONFIG, UNTOUCHED);
    /* A NAME_TYPE filled to its 30 characters, no terminator. */
    NAME_TYPE full;
    memcpy(full, "SECOND........................", MAX_NAME_LENGTH);
    try_get("init.other_name_type", full, INVALID_CONFIG, UNTOUCHED);
    start_new_process("proc", proc, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
