/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_SEMAPHORE (ARINC 653 Part 1, 3.7.2.3). Scenario "create": NO_ERROR, NO_ACTION,
 * INVALID_PARAM and INVALID_MODE. Scenario "limits": MAX_NUMBER_OF_SEMAPHORES semaphores,
 * then INVALID_CONFIG. */
#include "apex_check.h"

static void try_create(const char *check, const char *name, SEMAPHORE_VALUE_TYPE current,
                       SEMAPHORE_VALUE_TYPE maximum, QUEUING_DISCIPLINE_TYPE discipline,
                       RETURN_CODE_TYPE expect)
{
    SEMAPHORE_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_SEMAPHORE(name, current, maximum, discipline, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id", check);
    if (expect != NO_ERROR) {
        check_int(n, UNTOUCHED, id);
        return;
    }
    SEMAPHORE_ID_TYPE by_name = UNTOUCHED;
    GET_SEMAPHORE_ID(name, &by_name, &rc);
    setup_rc("GET_SEMAPHORE_ID", rc);
    check_int(n, by_name, id);
    SEMAPHORE_STATUS_TYPE st;
    GET_SEMAPHORE_STATUS(id, &st, &rc);
    setup_rc("GET_SEMAPHORE_STATUS", rc);
    snprintf(n, sizeof n, "%s.values", check);
    char got[32];
    snprintf(got, sizeof got, "%d/%d/%d", (int)st.CURRENT_VALUE, (int)st.MAXIMUM_VALUE,
             (int)st.WAITING_PROCESSES);
    check_str(n, "*", got);
}

static void late(void)
{
    try_create("normal.new", "LATE", 0, 1, FIFO, INVALID_MODE);
    try_create("normal.existing", "S1", 0, 1, FIFO, NO_ACTION);
}

static void create(void)
{
    try_create("init.created", "S1", 0, 1, FIFO, NO_ERROR);
    try_create("init.same_name", "S1", 1, 2, PRIORITY, NO_ACTION);
    try_create("init.current_negative", "S2", -1, 1, FIFO, INVALID_PARAM);
    try_create("init.current_over_limit", "S2", MAX_SEMAPHORE_VALUE + 1, MAX_SEMAPHORE_VALUE, FIFO,
               INVALID_PARAM);
    try_create("init.maximum_negative", "S2", 0, -1, FIFO, INVALID_PARAM);
    try_create("init.maximum_over_limit", "S2", 0, MAX_SEMAPHORE_VALUE + 1, FIFO, INVALID_PARAM);
    try_create("init.current_above_maximum", "S2", 3, 2, FIFO, INVALID_PARAM);
    try_create("init.discipline", "S2", 0, 1, (QUEUING_DISCIPLINE_TYPE)2, INVALID_PARAM);
    try_create("init.empty_name", "", 0, 1, FIFO, INVALID_PARAM);
    try_create("init.largest", "S2", MAX_SEMAPHORE_VALUE, MAX_SEMAPHORE_VALUE, PRIORITY, NO_ERROR);
    try_create("init.maximum_zero", "S3", 0, 0, FIFO, NO_ERROR);
    start_new_process("late", late, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

static void limits(void)
{
    int created = 0;
    for (int i = 0; i < MAX_NUMBER_OF_SEMAPHORES; i++) {
        char name[16];
        snprintf(name, sizeof name, "L%d", i);
        SEMAPHORE_ID_TYPE id;
        RETURN_CODE_TYPE rc;
        CREATE_SEMAPHORE(name, 0, 1, FIFO, &id, &rc);
        created += rc == NO_ERROR && id == i + 1;
    }
    check_int("limits.created", MAX_NUMBER_OF_SEMAPHORES, created);
    try_create("limits.one_more", "MORE", 0, 1, FIFO, INVALID_CONFIG);
    try_create("limits.existing_name", "L0", 0, 1, FIFO, INVALID_CONFIG);
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
