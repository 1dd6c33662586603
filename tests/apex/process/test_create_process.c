/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_PROCESS (ARINC 653 Part 1, 3.3.2). Scenario "codes": every return code but the
 * process limit; scenario "full": INVALID_CONFIG once the partition holds the maximum number
 * of processes. The partition period is 20 ms. */
#include "apex_check.h"

static void body(void) {}

/* Creates a process from attributes and checks the return code; a failed call must leave
 * the identifier alone. */
static void try_create(const char *check, PROCESS_ATTRIBUTE_TYPE a, RETURN_CODE_TYPE expect)
{
    PROCESS_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &id, &rc);
    check_rc(check, expect, rc);
    if (expect != NO_ERROR) {
        char n[64];
        snprintf(n, sizeof n, "%s.id_untouched", check);
        check_int(n, UNTOUCHED, id);
    }
}

static PROCESS_ATTRIBUTE_TYPE aperiodic(const char *name)
{
    return process_attributes(name, body, 10, INFINITE_TIME_VALUE, INFINITE_TIME_VALUE);
}

static PROCESS_ATTRIBUTE_TYPE periodic(const char *name, SYSTEM_TIME_TYPE period,
                                       SYSTEM_TIME_TYPE capacity)
{
    return process_attributes(name, body, 10, period, capacity);
}

static void in_normal(void)
{
    /* Processes are created only before NORMAL mode. */
    try_create("normal.create", aperiodic("late"), INVALID_MODE);
    PROCESS_ID_TYPE id;
    RETURN_CODE_TYPE rc;
    GET_PROCESS_ID("late", &id, &rc);
    check_rc("normal.create.not_created", INVALID_CONFIG, rc);
}

static void codes(void)
{
    PROCESS_ATTRIBUTE_TYPE a;
    PROCESS_ID_TYPE id = NULL_PROCESS_ID;
    RETURN_CODE_TYPE rc;

    a = aperiodic("alpha");
    CREATE_PROCESS(&a, &id, &rc);
    check_rc("aperiodic", NO_ERROR, rc);
    check_true("aperiodic.id_written", id != NULL_PROCESS_ID);
    try_create("periodic", periodic("beta", 40 * MS, 40 * MS), NO_ERROR);
    try_create("capacity_equals_period", periodic("gamma", 20 * MS, 20 * MS), NO_ERROR);

    /* The name is what identifies a process: the other attributes do not matter. */
    try_create("same_name", aperiodic("alpha"), NO_ACTION);
    try_create("same_name.other_attributes", periodic("alpha", 20 * MS, 5 * MS), NO_ACTION);

    a = aperiodic("s0");
    a.STACK_SIZE = 0;
    try_create("stack_zero", a, INVALID_PARAM);
    a = aperiodic("s1");
    a.STACK_SIZE = 0xFFFFFFFFu;
    try_create("stack_too_large", a, INVALID_PARAM);

    a = aperiodic("p0");
    a.BASE_PRIORITY = MIN_PRIORITY_VALUE - 1;
    try_create("priority_below_min", a, INVALID_PARAM);
    a = aperiodic("p1");
    a.BASE_PRIORITY = MAX_PRIORITY_VALUE + 1;
    try_create("priority_above_max", a, INVALID_PARAM);
    a = aperiodic("p2");
    a.BASE_PRIORITY = -5;
    try_create("priority_negative", a, INVALID_PARAM);
    a = aperiodic("p3");
    a.BASE_PRIORITY = MAX_PRIORITY_VALUE;
    try_create("priority_max", a, NO_ERROR);
    a = aperiodic("p4");
    a.BASE_PRIORITY = MIN_PRIORITY_VALUE;
    try_create("priority_min", a, NO_ERROR);

    try_create("period_zero", periodic("t0", 0, 10 * MS), INVALID_PARAM);
    try_create("period_negative", periodic("t1", -2, 10 * MS), INVALID_PARAM);
    try_create("period_not_multiple_30ms", periodic("t2", 30 * MS, 10 * MS), INVALID_CONFIG);
    try_create("period_not_multiple_10ms", periodic("t3", 10 * MS, 10 * MS), INVALID_CONFIG);

    a = aperiodic("c0");
    a.TIME_CAPACITY = 0;
    try_create("capacity_zero", a, INVALID_PARAM);
    a = aperiodic("c1");
    a.TIME_CAPACITY = -2;
    try_create("capacity_negative", a, INVALID_PARAM);
    a = aperiodic("c2");
    a.TIME_CAPACITY = 5 * MS; /* an aperiodic process may have a finite capacity */
    try_create("capacity_aperiodic", a, NO_ERROR);
    try_create("capacity_over_period", periodic("c3", 20 * MS, 40 * MS), INVALID_PARAM);

    /* A refused creation creates nothing. */
    GET_PROCESS_ID("s0", &id, &rc);
    check_rc("refused.not_created", INVALID_CONFIG, rc);

    start_new_process("in_normal", in_normal, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

static void full(void)
{
    RETURN_CODE_TYPE rc = NO_ERROR;
    int created = 0;
    while (created <= MAX_NUMBER_OF_PROCESSES) {
        char name[16];
        snprintf(name, sizeof name, "p%03d", created);
        PROCESS_ATTRIBUTE_TYPE a = aperiodic(name);
        PROCESS_ID_TYPE id;
        CREATE_PROCESS(&a, &id, &rc);
        if (rc != NO_ERROR)
            break;
        created++;
    }
    check_int("full.created", MAX_NUMBER_OF_PROCESSES, created);
    check_rc("full.one_more", INVALID_CONFIG, rc);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "codes") == 0)
        codes();
    else if (strcmp(scenario, "full") == 0)
        full();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
