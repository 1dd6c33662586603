/* SPDX-License-Identifier: Apache-2.0 */
/* SET_PARTITION_MODE (ARINC 653 Part 1, 3.2.2). One program, three scenarios chosen by
 * the partition's argument:
 *   codes    the return codes: NO_ERROR (NORMAL from the initialisation process), NO_ACTION
 *            (NORMAL when already NORMAL), INVALID_PARAM (no such mode), INVALID_MODE
 *            (WARM_START while in COLD_START);
 *   idle     a process asks for IDLE in its third period: the partition stops for good;
 *   restart  asks for COLD_START, then (after that restart) for WARM_START; every start
 *            reports its START_CONDITION and OPERATING_MODE as a "BOOT" line. */
#include "apex_check.h"

/* The initialisation process never returns from SET_PARTITION_MODE(NORMAL): a process reads
 * the return code it left. */
static RETURN_CODE_TYPE normal_rc = (RETURN_CODE_TYPE)UNTOUCHED;

static OPERATING_MODE_TYPE current_mode(void)
{
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    setup_rc("GET_PARTITION_STATUS", rc);
    return st.OPERATING_MODE;
}

static void codes_checker(void)
{
    RETURN_CODE_TYPE rc;
    check_rc("init.normal", NO_ERROR, normal_rc);
    check_str("normal.mode", "NORMAL", mode_name(current_mode()));
    SET_PARTITION_MODE(NORMAL, &rc);
    check_rc("normal.normal_again", NO_ACTION, rc);
    SET_PARTITION_MODE((OPERATING_MODE_TYPE)4, &rc);
    check_rc("normal.mode_4", INVALID_PARAM, rc);
    check_str("normal.mode_after", "NORMAL", mode_name(current_mode()));
}

static void codes(void)
{
    RETURN_CODE_TYPE rc;
    check_str("init.mode", "COLD_START", mode_name(current_mode()));
    SET_PARTITION_MODE(WARM_START, &rc);
    check_rc("init.warm_start_in_cold_start", INVALID_MODE, rc);
    SET_PARTITION_MODE((OPERATING_MODE_TYPE)4, &rc);
    check_rc("init.mode_4", INVALID_PARAM, rc);
    SET_PARTITION_MODE((OPERATING_MODE_TYPE)-1, &rc);
    check_rc("init.mode_minus_1", INVALID_PARAM, rc);
    check_str("init.mode_after", "COLD_START", mode_name(current_mode()));
    start_new_process("checker", codes_checker, 10, INFINITE_TIME_VALUE);
    SET_PARTITION_MODE(NORMAL, &normal_rc);
    report("SETUP SET_PARTITION_MODE(NORMAL) returned %s", rc_name(normal_rc));
}

static void idler(void)
{
    for (int k = 0;; k++) {
        RETURN_CODE_TYPE rc;
        report("TICK %d", k);
        if (k == 2) {
            SET_PARTITION_MODE(IDLE, &rc);
            report("SETUP SET_PARTITION_MODE(IDLE) returned %s", rc_name(rc));
        }
        PERIODIC_WAIT(&rc);
    }
}

static void idle(void)
{
    start_new_process("idler", idler, 10, 30 * MS);
    enter_normal();
}

static OPERATING_MODE_TYPE restart_request; /* NORMAL: stay */

static void restarter(void)
{
    RETURN_CODE_TYPE rc;
    if (restart_request == NORMAL) {
        report("STAYING");
        return;
    }
    report("REQUEST %s", mode_name(restart_request));
    SET_PARTITION_MODE(restart_request, &rc);
    report("SETUP SET_PARTITION_MODE(%s) returned %s", mode_name(restart_request), rc_name(rc));
}

static void restart(void)
{
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    setup_rc("GET_PARTITION_STATUS", rc);
    report("BOOT start=%s mode=%s", start_condition_name(st.START_CONDITION),
           mode_name(st.OPERATING_MODE));
    if (st.START_CONDITION == NORMAL_START)
        restart_request = COLD_START;
    else if (st.OPERATING_MODE == COLD_START)
        restart_request = WARM_START;
    else
        restart_request = NORMAL;
    start_new_process("restarter", restarter, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "codes") == 0)
        codes();
    else if (strcmp(scenario, "idle") == 0)
        idle();
    else if (strcmp(scenario, "restart") == 0)
        restart();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
