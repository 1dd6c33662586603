/* SPDX-License-Identifier: Apache-2.0 */
/* READ_SAMPLING_MESSAGE (ARINC 653 Part 1, 3.6.2.1). The writer (window 0-5 ms of a 20 ms
 * frame) writes in its first and third periods only; the reader (window 10-15 ms) reads each
 * period: NO_ERROR with VALID while the message is at most the refresh period (25 ms) old,
 * NO_ERROR with INVALID once it is older; NO_ACTION from a port nothing was ever written to;
 * INVALID_PARAM (no such port) and INVALID_MODE (a source port). NO_ACTION sets LENGTH 0 and
 * VALIDITY INVALID and leaves the message buffer alone; the errors leave every output alone. */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE out, port_in, lonely, reader_out;

static void writer_process(void)
{
    for (int k = 0; k < 3; k++) {
        RETURN_CODE_TYPE rc;
        if (k != 1) {
            char msg[8];
            snprintf(msg, sizeof msg, "msg%d", k);
            WRITE_SAMPLING_MESSAGE(out, (MESSAGE_ADDR_TYPE)msg, 5, &rc);
            setup_rc("WRITE_SAMPLING_MESSAGE", rc);
        }
        PERIODIC_WAIT(&rc);
    }
}

static void read_ok(const char *check, VALIDITY_TYPE validity, const char *text)
{
    APEX_BYTE msg[16];
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    VALIDITY_TYPE v = (VALIDITY_TYPE)UNTOUCHED;
    RETURN_CODE_TYPE rc;
    char n[64];
    READ_SAMPLING_MESSAGE(port_in, msg, &len, &v, &rc);
    snprintf(n, sizeof n, "%s.rc", check);
    check_rc(n, NO_ERROR, rc);
    snprintf(n, sizeof n, "%s.validity", check);
    check_str(n, validity_name(validity), validity_name(v));
    snprintf(n, sizeof n, "%s.length", check);
    check_int(n, 5, len);
    snprintf(n, sizeof n, "%s.message", check);
    check_str(n, text, message_text(msg, len));
}

/* A read that gets no message: which outputs it wrote, and to what. */
static void read_refused(const char *check, SAMPLING_PORT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    APEX_BYTE msg[16], before[16];
    memset(msg, 0x5A, sizeof msg);
    memcpy(before, msg, sizeof msg);
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    VALIDITY_TYPE v = (VALIDITY_TYPE)UNTOUCHED;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE(id, msg, &len, &v, &rc);
    check_rc(check, expect, rc);
    char touched[64] = "";
    if (len != UNTOUCHED)
        snprintf(touched, sizeof touched, "LENGTH=%d,", (int)len);
    if (v != (VALIDITY_TYPE)UNTOUCHED)
        snprintf(touched + strlen(touched), sizeof touched - strlen(touched), "VALIDITY=%s,",
                 validity_name(v));
    if (memcmp(msg, before, sizeof msg) != 0)
        strcat(touched, "MESSAGE,");
    char n[64];
    snprintf(n, sizeof n, "%s.outputs_written", check);
    check_str(n, "*", touched[0] ? touched : "none");
}

static void reader_process(void)
{
    RETURN_CODE_TYPE rc;
    /* 10 ms: written at 0. */
    read_ok("fresh", VALID, "msg0");
    read_refused("never_written", lonely, NO_ACTION);
    read_refused("id_zero", 0, INVALID_PARAM);
    read_refused("id_unknown", 99, INVALID_PARAM);
    read_refused("source_port", reader_out, INVALID_MODE);
    PERIODIC_WAIT(&rc);
    /* 30 ms: the message is 30 ms old, the refresh period 25 ms. */
    read_ok("stale", INVALID, "msg0");
    PERIODIC_WAIT(&rc);
    /* 50 ms: written again at 40. */
    read_ok("fresh_again", VALID, "msg2");
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
