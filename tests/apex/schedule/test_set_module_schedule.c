/* SPDX-License-Identifier: Apache-2.0 */
/* SET_MODULE_SCHEDULE, GET_MODULE_SCHEDULE_STATUS, GET_MODULE_SCHEDULE_ID (ARINC 653 Part 2):
 * the partition named by argv[1] plays its part of test_set_module_schedule.xml. */
#include <stdlib.h>

#include "../apex_check.h"

static const char *role;

static void status(const char *name)
{
    SCHEDULE_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    char n[64];
    GET_MODULE_SCHEDULE_STATUS(&st, &rc);
    snprintf(n, sizeof n, "%s.status", name);
    check_rc(n, NO_ERROR, rc);
    snprintf(n, sizeof n, "%s.current", name);
    observe_int(n, st.CURRENT_SCHEDULE);
    snprintf(n, sizeof n, "%s.next", name);
    observe_int(n, st.NEXT_SCHEDULE);
    snprintf(n, sizeof n, "%s.last_switch", name);
    observe_int(n, st.TIME_OF_LAST_SCHEDULE_SWITCH);
}

static void run(void)
{
    RETURN_CODE_TYPE rc;
    for (int release = 1;; release++) {
        if (release == 3 && strcmp(role, "switcher") == 0) {
            SET_MODULE_SCHEDULE(99, &rc);
            check_rc("switch.unknown_id", INVALID_PARAM, rc);
            SET_MODULE_SCHEDULE(2, &rc);
            check_rc("switch.degraded", NO_ERROR, rc);
            status("after_request"); /* still NOMINAL; DEGRADED from the next major frame */
        }
        if (release == 4 && strcmp(role, "switcher") == 0)
            status("after_switch");
        PERIODIC_WAIT(&rc);
    }
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    role = argc > 1 ? argv[1] : "?";
    if (strcmp(role, "switcher") == 0) {
        SCHEDULE_ID_TYPE id = UNTOUCHED;
        GET_MODULE_SCHEDULE_ID("DEGRADED", &id, &rc);
        check_rc("id.degraded", NO_ERROR, rc);
        check_int("id.degraded.value", 2, id);
        id = UNTOUCHED;
        GET_MODULE_SCHEDULE_ID("NO_SUCH", &id, &rc);
        check_rc("id.unknown", INVALID_CONFIG, rc);
        check_int("id.unknown.untouched", UNTOUCHED, id);
        status("init");
    } else if (strcmp(role, "other") == 0) {
        SET_MODULE_SCHEDULE(2, &rc);
        check_rc("switch.not_allowed", INVALID_CONFIG, rc);
    }
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = 40 * MS, .TIME_CAPACITY = 40 * MS, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)run,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "main"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
