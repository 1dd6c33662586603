/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_EVENT (ARINC 653 Part 1, 3.7.2.4). Scenario "create": NO_ERROR (the event starts
 * DOWN), NO_ACTION, INVALID_PARAM and INVALID_MODE. Scenario "limits": MAX_NUMBER_OF_EVENTS
 * events, then INVALID_CONFIG. */
#include "apex_check.h"

static void try_create(const char *check, const char *name, RETURN_CODE_TYPE expect)
{
    EVENT_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_EVENT(name, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id", check);
    if (expect != NO_ERROR) {
        check_int(n, UNTOUCHED, id);
        return;
    }
    EVENT_ID_TYPE by_name = UNTOUCHED;
    GET_EVENT_ID(name, &by_name, &rc);
    setup_rc("GET_EVENT_ID", rc);
    check_int(n, by_name, id);
    EVENT_STATUS_TYPE st;
    GET_EVENT_STATUS(id, &st, &rc);
    setup_rc("GET_EVENT_STATUS", rc);
    snprintf(n, sizeof n, "%s.state", check);
    check_str(n, "DOWN", event_state_name(st.EVENT_STATE));
}

static void late(void)
{
    try_create("normal.new", "LATE", INVALID_MODE);
    try_create("normal.existing", "E1", NO_ACTION);
}

static void create(void)
{
    try_create("init.created", "E1", NO_ERROR);
    try_create("init.same_name", "E1", NO_ACTION);
    try_create("init.empty_name", "", INVALID_PARAM);
    try_create("init.second", "E2", NO_ERROR);
    start_new_process("late", late, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

static void limits(void)
{
    int created = 0;
    for (int i = 0; i < MAX_NUMBER_OF_EVENTS; i++) {
        char name[16];
        snprintf(name, sizeof name, "L%d", i);
        EVENT_ID_TYPE id;
        RETURN_CODE_TYPE rc;
        CREATE_EVENT(name, &id, &rc);
        created += rc == NO_ERROR && id == i + 1;
    }
    check_int("limits.created", MAX_NUMBER_OF_EVENTS, created);
    try_create("limits.one_more", "MORE", INVALID_CONFIG);
    try_create("limits.existing_name", "L0", INVALID_CONFIG);
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
