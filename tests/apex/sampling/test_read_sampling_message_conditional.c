/* SPDX-License-Identifier: Apache-2.0 */
/* READ_SAMPLING_MESSAGE_CONDITIONAL (ARINC 653 Part 2, sampling port extensions). The writer
 * (window 0-5 ms of a 20 ms frame) writes 2 ms into its periods 0 and 2; the reader (window
 * 10-15 ms) reads with reference time stamps before, at and after the message's: NO_ERROR
 * with the message and its TIME_STAMP when it is newer than REF_TIME_STAMP; NO_ACTION when it
 * is not (TIME_STAMP says when it was written) or the port is empty; INVALID_PARAM (no such
 * port, a negative REF_TIME_STAMP) and INVALID_MODE (a source port). Each call reports every
 * output it wrote. */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE out, port_in, lonely, reader_out;

static void writer_process(void)
{
    for (int k = 0; k < 3; k++) {
        RETURN_CODE_TYPE rc;
        TIMED_WAIT(2 * MS, &rc);
        if (k != 1) {
            char msg[8];
            snprintf(msg, sizeof msg, "msg%d", k);
            WRITE_SAMPLING_MESSAGE(out, (MESSAGE_ADDR_TYPE)msg, 5, &rc);
            setup_rc("WRITE_SAMPLING_MESSAGE", rc);
        }
        PERIODIC_WAIT(&rc);
    }
}

/* One call: "<check>" is its return code, "<check>.outputs" what it wrote ("none", or
 * "LENGTH=<n>,TIME_STAMP=<ns>,MESSAGE=<text>," for those written). */
static void try_read(const char *check, SAMPLING_PORT_ID_TYPE id, SYSTEM_TIME_TYPE ref,
                     RETURN_CODE_TYPE expect)
{
    APEX_BYTE msg[16], before[16];
    memset(msg, 0x5A, sizeof msg);
    memcpy(before, msg, sizeof msg);
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    SYSTEM_TIME_TYPE stamp = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    READ_SAMPLING_MESSAGE_CONDITIONAL(id, ref, msg, &len, &stamp, &rc);
    check_rc(check, expect, rc);
    char written[96] = "";
    size_t n = 0;
    if (len != UNTOUCHED)
        n += (size_t)snprintf(written + n, sizeof written - n, "LENGTH=%d,", (int)len);
    if (stamp != UNTOUCHED)
        n += (size_t)snprintf(written + n, sizeof written - n, "TIME_STAMP=%lld,", stamp);
    if (memcmp(msg, before, sizeof msg) != 0)
        snprintf(written + n, sizeof written - n, "MESSAGE=%s,",
                 message_text(msg, len == UNTOUCHED ? (MESSAGE_SIZE_TYPE)sizeof msg : len));
    char name[64];
    snprintf(name, sizeof name, "%s.outputs", check);
    check_str(name, "*", written[0] ? written : "none");
}

static void reader_process(void)
{
    RETURN_CODE_TYPE rc;
    /* 10 ms: msg0 written at 2 ms. */
    try_read("empty", lonely, 0, NO_ACTION);
    try_read("id_zero", 0, 0, INVALID_PARAM);
    try_read("id_unknown", 99, 0, INVALID_PARAM);
    try_read("source_port", reader_out, 0, INVALID_MODE);
    try_read("ref_negative", port_in, -5, INVALID_PARAM);
    try_read("ref_infinite", port_in, INFINITE_TIME_VALUE, INVALID_PARAM);
    try_read("newer", port_in, 1 * MS, NO_ERROR);
    try_read("same_time", port_in, 2 * MS, NO_ACTION);
    try_read("older", port_in, 5 * MS, NO_ACTION);
    PERIODIC_WAIT(&rc);
    PERIODIC_WAIT(&rc);
    /* 50 ms: msg2 written at 42 ms, newer than the last time stamp read. */
    try_read("next", port_in, 2 * MS, NO_ERROR);
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
