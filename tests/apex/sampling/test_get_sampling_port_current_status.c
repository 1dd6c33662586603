/* SPDX-License-Identifier: Apache-2.0 */
/* GET_SAMPLING_PORT_CURRENT_STATUS (ARINC 653 Part 2, sampling port extensions). The writer
 * (window 0-5 ms of a 20 ms frame) writes 2 ms into its periods 0 and 2; the reader (window
 * 10-15 ms) asks the status of its ports as messages arrive, age and are read: NO_ERROR with
 * every field, INVALID_PARAM for an unknown identifier (the status left alone). */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE out, port_in, lonely, reader_out;

static void writer_process(void)
{
    for (int k = 0; k < 3; k++) {
        RETURN_CODE_TYPE rc;
        TIMED_WAIT(2 * MS, &rc);
        if (k != 1) {
            WRITE_SAMPLING_MESSAGE(out, (MESSAGE_ADDR_TYPE) "msg", 4, &rc);
            setup_rc("WRITE_SAMPLING_MESSAGE", rc);
        }
        PERIODIC_WAIT(&rc);
    }
}

/* "<check>" is the return code, "<check>.<field>" each field (the table holds the values). */
static void status(const char *check, SAMPLING_PORT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    SAMPLING_PORT_CURRENT_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_SAMPLING_PORT_CURRENT_STATUS(id, &st, &rc);
    check_rc(check, expect, rc);
    char n[64];
    if (expect != NO_ERROR) {
        SAMPLING_PORT_CURRENT_STATUS_TYPE untouched;
        memset(&untouched, 0x5A, sizeof untouched);
        snprintf(n, sizeof n, "%s.untouched", check);
        check_true(n, memcmp(&st, &untouched, sizeof st) == 0);
        return;
    }
    snprintf(n, sizeof n, "%s.refresh_period", check);
    observe_int(n, st.REFRESH_PERIOD);
    snprintf(n, sizeof n, "%s.time_stamp", check);
    observe_int(n, st.TIME_STAMP);
    snprintf(n, sizeof n, "%s.max_message_size", check);
    observe_int(n, st.MAX_MESSAGE_SIZE);
    snprintf(n, sizeof n, "%s.port_direction", check);
    check_str(n, "*", direction_name(st.PORT_DIRECTION));
    snprintf(n, sizeof n, "%s.message_age", check);
    check_str(n, "*", age_name(st.MESSAGE_AGE));
    snprintf(n, sizeof n, "%s.updated", check);
    check_str(n, "*", updated_name(st.UPDATED));
}

static void read_in(void)
{
    APEX_BYTE msg[16];
    MESSAGE_SIZE_TYPE len;
    VALIDITY_TYPE v;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE(port_in, msg, &len, &v, &rc);
    setup_rc("READ_SAMPLING_MESSAGE", rc);
}

static void reader_process(void)
{
    RETURN_CODE_TYPE rc;
    /* 10 ms: the message written at 2 ms is 8 ms old. */
    status("empty", lonely, NO_ERROR);
    status("id_zero", 0, INVALID_PARAM);
    status("id_unknown", 99, INVALID_PARAM);
    status("new", port_in, NO_ERROR);
    read_in();
    status("read", port_in, NO_ERROR);
    status("source.before_write", reader_out, NO_ERROR);
    WRITE_SAMPLING_MESSAGE(reader_out, (MESSAGE_ADDR_TYPE) "out", 4, &rc);
    setup_rc("WRITE_SAMPLING_MESSAGE", rc);
    status("source.written", reader_out, NO_ERROR);
    PERIODIC_WAIT(&rc);
    /* 30 ms: nothing written in period 1, the message is 28 ms old (refresh period 25 ms). */
    status("stale", port_in, NO_ERROR);
    PERIODIC_WAIT(&rc);
    /* 50 ms: written again at 42 ms. */
    status("new_again", port_in, NO_ERROR);
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    RETURN_CODE_TYPE rc;
    if (strcmp(scenario, "writer") == 0) {
        CREATE_SAMPLING_PORT("SP_OUT", 16, SOURCE, 25 * MS, &out, &rc);
        setup_rc("CREATE_SAMPLING_PORT SP_OUT", rc);
        start_new_process("writer", writer_process, 10, 20 * MS);
    } else if (strcmp(scenario, "reader") == 0) {
        CREATE_SAMPLING_PORT("SP_IN", 16, DESTINATION, 25 * MS, &port_in, &rc);
        setup_rc("CREATE_SAMPLING_PORT SP_IN", rc);
        CREATE_SAMPLING_PORT("SP_LONELY", 16, DESTINATION, 25 * MS, &lonely, &rc);
        setup_rc("CREATE_SAMPLING_PORT SP_LONELY", rc);
        CREATE_SAMPLING_PORT("SP_R_OUT", 16, SOURCE, 25 * MS, &reader_out, &rc);
        setup_rc("CREATE_SAMPLING_PORT SP_R_OUT", rc);
        start_new_process("reader", reader_process, 10, 20 * MS);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    enter_normal();
    return 1;
}
