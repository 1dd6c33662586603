/* SPDX-License-Identifier: Apache-2.0 */
/* GET_PARTITION_STATUS (ARINC 653 Part 1, 3.2.2): the status seen by the initialisation
 * process and by a process in NORMAL mode. Its only return code is NO_ERROR. */
#include "apex_check.h"

static void report_status(const char *phase, OPERATING_MODE_TYPE mode)
{
    PARTITION_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    char n[64];
    snprintf(n, sizeof n, "%s.rc", phase);
    check_rc(n, NO_ERROR, rc);
    snprintf(n, sizeof n, "%s.period", phase);
    observe_int(n, st.PERIOD);
    snprintf(n, sizeof n, "%s.duration", phase);
    observe_int(n, st.DURATION);
    snprintf(n, sizeof n, "%s.identifier", phase);
    observe_int(n, st.IDENTIFIER);
    snprintf(n, sizeof n, "%s.operating_mode", phase);
    check_str(n, mode_name(mode), mode_name(st.OPERATING_MODE));
    snprintf(n, sizeof n, "%s.start_condition", phase);
    check_str(n, "NORMAL_START", start_condition_name(st.START_CONDITION));
    snprintf(n, sizeof n, "%s.num_assigned_cores", phase);
    check_int(n, 1, st.NUM_ASSIGNED_CORES);
    if (mode == NORMAL) {
        /* No process holds the preemption lock. */
        snprintf(n, sizeof n, "%s.lock_level", phase);
        check_int(n, 0, st.LOCK_LEVEL);
    }
}

static void worker(void) { report_status("normal", NORMAL); }

int main(void)
{
    report_status("init", COLD_START);
    start_new_process("worker", worker, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
