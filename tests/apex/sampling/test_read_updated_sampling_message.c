/* SPDX-License-Identifier: Apache-2.0 */
/* READ_UPDATED_SAMPLING_MESSAGE (ARINC 653 Part 2, sampling port extensions). The writer
 * (window 0-5 ms of a 20 ms frame) writes 2 ms into its periods 0, 2 and 3; the reader
 * (window 10-15 ms) reads each period: NO_ERROR with UPDATED = NEW_MESSAGE for a message not
 * read yet, NO_ACTION with CONSUMED_MESSAGE once it was read (by this service or by
 * READ_SAMPLING_MESSAGE), NO_ACTION with EMPTY_PORT from a port nothing was written to;
 * INVALID_PARAM (no such port) and INVALID_MODE (a source port). Each call reports every
 * output it wrote. */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE out, port_in, lonely, reader_out;

static void writer_process(void)
{
    for (int k = 0; k < 4; k++) {
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
 * "LENGTH=<n>,UPDATED=<name>,MESSAGE=<text>," for those written). */
static void try_read(const char *check, SAMPLING_PORT_ID_TYPE id, RETURN_CODE_TYPE expect)
{
    APEX_BYTE msg[16], before[16];
    memset(msg, 0x5A, sizeof msg);
    memcpy(before, msg, sizeof msg);
    MESSAGE_SIZE_TYPE len = UNTOUCHED;
    UPDATED_TYPE updated = (UPDATED_TYPE)UNTOUCHED;
    RETURN_CODE_TYPE rc;
    READ_UPDATED_SAMPLING_MESSAGE(id, msg, &len, &updated, &rc);
    check_rc(check, expect, rc);
    char written[96] = "";
    size_t n = 0;
    if (len != UNTOUCHED)
        n += (size_t)snprintf(written + n, sizeof written - n, "LENGTH=%d,", (int)len);
    if (updated != (UPDATED_TYPE)UNTOUCHED)
        n += (size_t)snprintf(written + n, sizeof written - n, "UPDATED=%s,",
                              updated_name(updated));
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
    try_read("empty", lonely, NO_ACTION);
    try_read("id_zero", 0, INVALID_PARAM);
    try_read("id_unknown", 99, INVALID_PARAM);
    try_read("source_port", reader_out, INVALID_MODE);
    try_read("new", port_in, NO_ERROR);
    try_read("consumed", port_in, NO_ACTION);
    PERIODIC_WAIT(&rc);
    /* 30 ms: nothing written in period 1. */
    try_read("still_consumed", port_in, NO_ACTION);
    PERIODIC_WAIT(&rc);
    /* 50 ms: msg2 written at 42 ms; READ_SAMPLING_MESSAGE reads it first. */
    APEX_BYTE msg[16];
    MESSAGE_SIZE_TYPE len;
    VALIDITY_TYPE v;
    READ_SAMPLING_MESSAGE(port_in, msg, &len, &v, &rc);
    setup_rc("READ_SAMPLING_MESSAGE", rc);
    try_read("consumed_by_read", port_in, NO_ACTION);
    PERIODIC_WAIT(&rc);
    /* 70 ms: msg3 written at 62 ms. */
    try_read("new_again", port_in, NO_ERROR);
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
