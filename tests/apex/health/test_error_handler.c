/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_ERROR_HANDLER, GET_ERROR_STATUS, RAISE_APPLICATION_ERROR, REPORT_APPLICATION_MESSAGE
 * (ARINC 653 Part 1, 3.10): the partition named by argv[1] plays its part of
 * test_error_handler.xml. */
#include "../apex_check.h"

static const char *role;
static PROCESS_ID_TYPE worker_id;
static int handled_errors;

static void handler(void)
{
    RETURN_CODE_TYPE rc;
    ERROR_STATUS_TYPE st;
    for (;;) {
        memset(&st, 0x5A, sizeof st);
        GET_ERROR_STATUS(&st, &rc);
        if (rc != NO_ERROR) {
            check_rc(handled_errors ? "status.drained" : "status.empty", NO_ACTION, rc);
            break;
        }
        handled_errors++;
        check_rc("status.rc", NO_ERROR, rc);
        check_int("status.code", APPLICATION_ERROR, st.ERROR_CODE);
        check_int("status.failed", worker_id, st.FAILED_PROCESS_ID);
        check_str("status.message", "sensor.out.of.range", message_text(st.MESSAGE, st.LENGTH));
        check_int("status.length", 19, st.LENGTH);
        PROCESS_ID_TYPE me = UNTOUCHED;
        GET_MY_ID(&me, &rc);
        check_rc("handler.get_my_id", INVALID_MODE, rc); /* the handler has no process ID */
        TIMED_WAIT(MS, &rc);
        check_rc("handler.timed_wait", INVALID_MODE, rc); /* the handler may not wait */
    }
    STOP_SELF();
}

static void work(void)
{
    RETURN_CODE_TYPE rc;
    ERROR_STATUS_TYPE st;
    GET_ERROR_STATUS(&st, &rc);
    check_rc("status.not_handler", INVALID_CONFIG, rc);
    RAISE_APPLICATION_ERROR(NUMERIC_ERROR, (MESSAGE_ADDR_TYPE) "x", 1, &rc);
    check_rc("raise.wrong_code", INVALID_PARAM, rc);
    RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "x", MAX_ERROR_MESSAGE_SIZE + 1, &rc);
    check_rc("raise.too_long", INVALID_PARAM, rc);
    RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "x", -1, &rc);
    check_rc("raise.negative", INVALID_PARAM, rc);
    RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "sensor out of range", 19, &rc);
    check_rc("raise.ok", NO_ERROR, rc);
    /* The handler ran before this process went on (it has the highest priority). */
    check_int("raise.handled_before_return", 1, handled_errors);
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE) "x", -1, &rc);
    check_rc("report.negative", INVALID_PARAM, rc);
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE) "x", MAX_ERROR_MESSAGE_SIZE + 1, &rc);
    check_rc("report.too_long", INVALID_PARAM, rc);
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE) "hello", 5, &rc);
    check_rc("report.ok", NO_ERROR, rc);
    for (;;)
        PERIODIC_WAIT(&rc);
}

static void idle_work(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)handler, 65536, &rc);
    check_rc("create.normal_mode", INVALID_MODE, rc);
    for (;;)
        PERIODIC_WAIT(&rc);
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    role = argc > 1 ? argv[1] : "?";
    bool handled = strcmp(role, "handled") == 0;
    if (handled) {
        CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)handler, 0, &rc);
        check_rc("create.stack_zero", INVALID_CONFIG, rc);
        CREATE_ERROR_HANDLER(NULL, 65536, &rc);
        check_rc("create.no_entry", INVALID_CONFIG, rc);
        CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)handler, 65536, &rc);
        check_rc("create.ok", NO_ERROR, rc);
        CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)handler, 65536, &rc);
        check_rc("create.again", NO_ACTION, rc);
    }
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = 20 * MS, .TIME_CAPACITY = 20 * MS,
        .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)(handled ? work : idle_work), .STACK_SIZE = 65536,
        .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "worker"};
    CREATE_PROCESS(&a, &worker_id, &rc);
    START(worker_id, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
