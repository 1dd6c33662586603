/* SPDX-License-Identifier: Apache-2.0 */
/* STOP_SELF (ARINC 653 Part 1, 3.3.2): the caller becomes DORMANT, never returns from the
 * call, and can be started again. The partition period is 20 ms; its window is the first
 * 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE victim_id, cyclic_id;
static int victim_runs, cyclic_runs, returned_from_stop;
static SYSTEM_TIME_TYPE cyclic_release[2];

static const char *state_of(PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    return state_name(st.PROCESS_STATE);
}

static void victim(void)
{
    victim_runs++;
    STOP_SELF();
    returned_from_stop++;
}

static void cyclic(void)
{
    if (cyclic_runs < 2)
        cyclic_release[cyclic_runs] = now_ns();
    cyclic_runs++;
    STOP_SELF();
    returned_from_stop++;
}

static void observer(void)
{
    RETURN_CODE_TYPE rc;
    /* victim and cyclic have the higher priority: both ran and stopped before this runs. */
    check_int("aperiodic.runs", 1, victim_runs);
    check_str("aperiodic.state", "DORMANT", state_of(victim_id));
    START(victim_id, &rc);
    check_rc("aperiodic.start_again", NO_ERROR, rc);
    check_int("aperiodic.runs_again", 2, victim_runs);
    check_str("aperiodic.state_again", "DORMANT", state_of(victim_id));

    check_int("periodic.runs", 1, cyclic_runs);
    check_str("periodic.state", "DORMANT", state_of(cyclic_id));
    TIMED_WAIT(1 * MS, &rc);
    START(cyclic_id, &rc);
    check_rc("periodic.start_again", NO_ERROR, rc);
    TIMED_WAIT(20 * MS, &rc);
    check_int("periodic.runs_again", 2, cyclic_runs);
    check_str("periodic.state_again", "DORMANT", state_of(cyclic_id));
    check_int("periodic.first_release", 0, cyclic_release[0]);
    check_int("periodic.release_after_restart", 20 * MS, cyclic_release[1]);

    check_int("never_returns", 0, returned_from_stop);
}

int main(void)
{
    victim_id = start_new_process("victim", victim, 20, INFINITE_TIME_VALUE);
    cyclic_id = start_new_process("cyclic", cyclic, 20, 20 * MS);
    start_new_process("observer", observer, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
