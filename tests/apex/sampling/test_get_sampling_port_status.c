/* SPDX-License-Identifier: Apache-2.0 */
/* GET_SAMPLING_PORT_STATUS (ARINC 653 Part 1, 3.6.2.1): NO_ERROR with the configured
 * refresh period, maximum size and direction and the validity of the last message read;
 * INVALID_PARAM for an unknown identifier (output untouched). The writer (window 0-5 ms of a
 * 20 ms frame) writes once, at 0; the reader (window 10-15 ms) reads at 10 ms (valid) and
 * 30 ms (older than the 25 ms refresh period: invalid). */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE port;

static void check_status(const char *phase, SAMPLING_PORT_ID_TYPE id)
{
    SAMPLING_PORT_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_SAMPLING_PORT_STATUS(id, &st, &rc);
    char n[64];
    snprintf(n, sizeof n, "%s.rc", phase);
    check_rc(n, NO_ERROR, rc);
    snprintf(n, sizeof n, "%s.refresh_period", phase);
    observe_int(n, st.REFRESH_PERIOD);
    snprintf(n, sizeof n, "%s.max_message_size", phase);
    observe_int(n, st.MAX_MESSAGE_SIZE);
    snprintf(n, sizeof n, "%s.port_direction", phase);
    check_str(n, "*", direction_name(st.PORT_DIRECTION));
}

static void bad_id(const char *check, SAMPLING_PORT_ID_TYPE id)
{
    SAMPLING_PORT_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_SAMPLING_PORT_STATUS(id, &st, &rc);
    check_rc(check, INVALID_PARAM, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.untouched", check);
    check_int(n, UNTOUCHED, st.MAX_MESSAGE_SIZE);
}

static const char *last_validity(void)
{
    SAMPLING_PORT_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_SAMPLING_PORT_STATUS(port, &st, &rc);
    setup_rc("GET_SAMPLING_PORT_STATUS", rc);
    return validity_name(st.LAST_MSG_VALIDITY);
}

static void reader_process(void)
{
    for (int k = 0; k < 2; k++) {
        APEX_BYTE msg[24];
        MESSAGE_SIZE_TYPE len;
        VALIDITY_TYPE v;
        RETURN_CODE_TYPE rc;
        READ_SAMPLING_MESSAGE(port, msg, &len, &v, &rc);
        setup_rc("READ_SAMPLING_MESSAGE", rc);
        check_str(k == 0 ? "after_valid_read.last_msg_validity"
                         : "after_invalid_read.last_msg_validity",
                  k == 0 ? "VALID" : "INVALID", last_validity());
        PERIODIC_WAIT(&rc);
    }
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    RETURN_CODE_TYPE rc;
    if (strcmp(scenario, "writer") == 0) {
        CREATE_SAMPLING_PORT("SP_OUT", 24, SOURCE, 25 * MS, &port, &rc);
        setup_rc("CREATE_SAMPLING_PORT SP_OUT", rc);
        APEX_BYTE msg[24] = "state";
        WRITE_SAMPLING_MESSAGE(port, msg, sizeof msg, &rc);
        setup_rc("WRITE_SAMPLING_MESSAGE", rc);
    } else if (strcmp(scenario, "reader") == 0) {
        CREATE_SAMPLING_PORT("SP_IN", 24, DESTINATION, 25 * MS, &port, &rc);
        setup_rc("CREATE_SAMPLING_PORT SP_IN", rc);
        start_new_process("reader", reader_process, 10, 20 * MS);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    check_status("status", port);
    bad_id("id_zero", 0);
    bad_id("id_unknown", port + 1);
    enter_normal();
    return 1;
}
