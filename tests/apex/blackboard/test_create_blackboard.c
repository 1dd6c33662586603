/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_BLACKBOARD (ARINC 653 Part 1, 3.7.2.2). Scenario "create": NO_ERROR, NO_ACTION,
 * INVALID_PARAM and INVALID_MODE. Scenario "limits": the partition's message storage, then
 * MAX_NUMBER_OF_BLACKBOARDS, each exceeded returns INVALID_CONFIG. */
#include "apex_check.h"

#define MIB SYSTEM_LIMIT_MESSAGE_SIZE

static void try_create(const char *check, const char *name, MESSAGE_SIZE_TYPE size,
                       RETURN_CODE_TYPE expect)
{
    BLACKBOARD_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_BLACKBOARD(name, size, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id", check);
    if (expect != NO_ERROR) {
        check_int(n, UNTOUCHED, id);
        return;
    }
    BLACKBOARD_ID_TYPE by_name = UNTOUCHED;
    GET_BLACKBOARD_ID(name, &by_name, &rc);
    setup_rc("GET_BLACKBOARD_ID", rc);
    check_int(n, by_name, id);
}

static void late(void)
{
    try_create("normal.new", "LATE", 8, INVALID_MODE);
    try_create("normal.existing", "BB", 8, NO_ACTION);
}

static void create(void)
{
    try_create("init.created", "BB", 16, NO_ERROR);
    BLACKBOARD_ID_TYPE id;
    RETURN_CODE_TYPE rc;
    GET_BLACKBOARD_ID("BB", &id, &rc);
    setup_rc("GET_BLACKBOARD_ID", rc);
    BLACKBOARD_STATUS_TYPE st;
    GET_BLACKBOARD_STATUS(id, &st, &rc);
    setup_rc("GET_BLACKBOARD_STATUS", rc);
    check_str("init.created.empty_indicator", "EMPTY", empty_indicator_name(st.EMPTY_INDICATOR));
    check_int("init.created.max_message_size", 16, st.MAX_MESSAGE_SIZE);

    try_create("init.same_name", "BB", 32, NO_ACTION);
    try_create("init.size_zero", "B2", 0, INVALID_PARAM);
    try_create("init.size_negative", "B2", -1, INVALID_PARAM);
    try_create("init.size_over_limit", "B2", MIB + 1, INVALID_PARAM);
    try_create("init.empty_name", "", 8, INVALID_PARAM);
    try_create("init.largest", "B2", MIB, NO_ERROR);
    start_new_process("late", late, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

static void limits(void)
{
    /* 255 blackboards in 15 MiB and a little of the partition's 16 MiB of message storage. */
    int created = 0;
    for (int i = 0; i < MAX_NUMBER_OF_BLACKBOARDS - 1; i++) {
        char name[16];
        snprintf(name, sizeof name, "L%d", i);
        BLACKBOARD_ID_TYPE id;
        RETURN_CODE_TYPE rc;
        CREATE_BLACKBOARD(name, i < 15 ? MIB : 1, &id, &rc);
        created += rc == NO_ERROR && id == i + 1;
    }
    check_int("limits.created", MAX_NUMBER_OF_BLACKBOARDS - 1, created);
    try_create("limits.storage", "LARGE", MIB, INVALID_CONFIG);
    try_create("limits.last", "LAST", 1, NO_ERROR);
    try_create("limits.one_more", "MORE", 1, INVALID_CONFIG);
    try_create("limits.existing_name", "L0", 1, INVALID_CONFIG);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "create") == 0)
        create();
    else if (strcmp(scenario, "limits") == 0)
        limits();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
