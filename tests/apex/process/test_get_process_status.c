/* SPDX-License-Identifier: Apache-2.0 */
/* GET_PROCESS_STATUS (ARINC 653 Part 1, 3.3.2): NO_ERROR with the attributes, state,
 * current priority and deadline of a process; INVALID_PARAM for an unknown identifier
 * (output untouched). The partition period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE runner_id, ready_id, sleeper_id, never_id, cyclic_id;

static void dormant_body(void) {}

static PROCESS_STATUS_TYPE status_of(PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    return st;
}

static void check_state(const char *check, PROCESS_ID_TYPE id, const char *expect)
{
    check_str(check, expect, state_name(status_of(id).PROCESS_STATE));
}

static void bad_id(const char *check, PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    check_rc(check, INVALID_PARAM, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.untouched", check);
    check_int(n, UNTOUCHED, st.CURRENT_PRIORITY);
}

static void sleeper(void)
{
    RETURN_CODE_TYPE rc;
    TIMED_WAIT(5 * MS, &rc);
}

static void ready_one(void) {}

static void cyclic(void)
{
    for (int k = 0; k < 2; k++) {
        RETURN_CODE_TYPE rc;
        char n[32];
        snprintf(n, sizeof n, "cyclic.deadline.%d", k);
        check_int(n, now_ns() + 8 * MS, status_of(cyclic_id).DEADLINE_TIME);
        PERIODIC_WAIT(&rc);
    }
}

static void runner(void)
{
    /* Started by the initialisation process at 0, with no time capacity. */
    PROCESS_STATUS_TYPE st = status_of(runner_id);
    check_str("normal.self", "RUNNING", state_name(st.PROCESS_STATE));
    check_int("normal.self.deadline", INFINITE_TIME_VALUE, st.DEADLINE_TIME);
    check_state("normal.lower_priority", ready_id, "READY");
    st = status_of(ready_id);
    check_int("normal.lower_priority.current_priority", 10, st.CURRENT_PRIORITY);
    check_int("normal.lower_priority.deadline", 0 + 50 * MS, st.DEADLINE_TIME);
    check_state("normal.timed_wait", sleeper_id, "WAITING");
    check_state("normal.periodic_wait", cyclic_id, "WAITING");
    check_state("normal.never_started", never_id, "DORMANT");
    bad_id("normal.id_zero", 0);
}

int main(void)
{
    runner_id = new_process("runner", runner, 20, INFINITE_TIME_VALUE);
    PROCESS_ATTRIBUTE_TYPE a = process_attributes("ready_one", ready_one, 10, INFINITE_TIME_VALUE,
                                                  50 * MS);
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &ready_id, &rc);
    setup_rc("CREATE_PROCESS ready_one", rc);
    sleeper_id = new_process("sleeper", sleeper, 30, INFINITE_TIME_VALUE);
    a = process_attributes("cyclic", cyclic, 25, 20 * MS, 8 * MS);
    CREATE_PROCESS(&a, &cyclic_id, &rc);
    setup_rc("CREATE_PROCESS cyclic", rc);
    a = process_attributes("never", dormant_body, 7, INFINITE_TIME_VALUE, 5 * MS);
    a.STACK_SIZE = 131072;
    a.DEADLINE = HARD;
    CREATE_PROCESS(&a, &never_id, &rc);
    setup_rc("CREATE_PROCESS never", rc);

    PROCESS_STATUS_TYPE st = status_of(never_id);
    check_str("init.dormant", "DORMANT", state_name(st.PROCESS_STATE));
    char name[MAX_NAME_LENGTH + 1] = "";
    memcpy(name, st.ATTRIBUTES.NAME, MAX_NAME_LENGTH);
    check_str("init.name", "never", name);
    check_int("init.base_priority", 7, st.ATTRIBUTES.BASE_PRIORITY);
    check_int("init.current_priority", 7, st.CURRENT_PRIORITY);
    check_int("init.period", INFINITE_TIME_VALUE, st.ATTRIBUTES.PERIOD);
    check_int("init.time_capacity", 5 * MS, st.ATTRIBUTES.TIME_CAPACITY);
    check_int("init.stack_size", 131072, st.ATTRIBUTES.STACK_SIZE);
    check_str("init.deadline", "HARD", deadline_name(st.ATTRIBUTES.DEADLINE));
    check_true("init.entry_point", st.ATTRIBUTES.ENTRY_POINT == (SYSTEM_ADDRESS_TYPE)dormant_body);
    st = status_of(cyclic_id);
    check_int("init.periodic.period", 20 * MS, st.ATTRIBUTES.PERIOD);
    check_int("init.periodic.time_capacity", 8 * MS, st.ATTRIBUTES.TIME_CAPACITY);

    bad_id("init.id_zero", 0);
    bad_id("init.id_negative", -1);
    bad_id("init.id_unknown", never_id + 1);

    /* Started before NORMAL mode, a process waits for NORMAL mode (Part 1, 2.3.2). */
    START(runner_id, &rc);
    setup_rc("START runner", rc);
    check_state("init.started", runner_id, "WAITING");
    START(ready_id, &rc);
    setup_rc("START ready_one", rc);
    START(sleeper_id, &rc);
    setup_rc("START sleeper", rc);
    START(cyclic_id, &rc);
    setup_rc("START cyclic", rc);
    enter_normal();
    return 1;
}
