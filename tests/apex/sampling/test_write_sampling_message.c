/* SPDX-License-Identifier: Apache-2.0 */
/* WRITE_SAMPLING_MESSAGE (ARINC 653 Part 1, 3.6.2.1). Scenario "writer": NO_ERROR (up to
 * the maximum size), INVALID_PARAM (no such sampling port, length <= 0), INVALID_CONFIG
 * (length above the maximum), INVALID_MODE (destination port), from the initialisation
 * process and from a process. Scenario "reader": sees the last successful write only. */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE out, back, port_in;
static QUEUING_PORT_ID_TYPE queue;

static void try_write(const char *check, SAMPLING_PORT_ID_TYPE id, const char *text,
                      MESSAGE_SIZE_TYPE len, RETURN_CODE_TYPE expect)
{
    APEX_BYTE msg[64];
    memset(msg, 'g', sizeof msg);
    memcpy(msg, text, strlen(text) + 1);
    RETURN_CODE_TYPE rc;
    WRITE_SAMPLING_MESSAGE(id, msg, len, &rc);
    check_rc(check, expect, rc);
}

static void writer_process(void)
{
    RETURN_CODE_TYPE rc;
    PERIODIC_WAIT(&rc); /* second period: 20 ms */
    try_write("normal.write", out, "normal", 7, NO_ERROR);
    try_write("normal.length_over_max", out, "garbage", 17, INVALID_CONFIG);
    try_write("normal.destination_port", back, "garbage", 8, INVALID_MODE);
}

static void writer(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_OUT", 16, SOURCE, 50 * MS, &out, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_OUT", rc);
    CREATE_SAMPLING_PORT("SP_BACK", 16, DESTINATION, 50 * MS, &back, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_BACK", rc);
    CREATE_QUEUING_PORT("QP_Q", 16, 2, SOURCE, FIFO, &queue, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_Q", rc);

    try_write("length_max", out, "0123456789abcdef", 16, NO_ERROR);
    try_write("write", out, "latest", 7, NO_ERROR);
    try_write("id_zero", 0, "garbage", 8, INVALID_PARAM);
    try_write("id_unknown", 99, "garbage", 8, INVALID_PARAM);
    try_write("queuing_port_id", queue, "garbage", 8, INVALID_PARAM);
    try_write("length_zero", out, "garbage", 0, INVALID_PARAM);
    try_write("length_negative", out, "garbage", -1, INVALID_PARAM);
    try_write("length_over_max", out, "garbage", 17, INVALID_CONFIG);
    try_write("destination_port", back, "garbage", 8, INVALID_MODE);
    start_new_process("writer", writer_process, 10, 20 * MS);
    enter_normal();
}

static void reader_process(void)
{
    for (int k = 0; k < 2; k++) {
        APEX_BYTE msg[16];
        MESSAGE_SIZE_TYPE len = 0;
        VALIDITY_TYPE v;
        RETURN_CODE_TYPE rc;
        char n[32];
        READ_SAMPLING_MESSAGE(port_in, msg, &len, &v, &rc);
        snprintf(n, sizeof n, "frame%d.read", k);
        check_rc(n, NO_ERROR, rc);
        snprintf(n, sizeof n, "frame%d.length", k);
        check_int(n, 7, len);
        snprintf(n, sizeof n, "frame%d.message", k);
        check_str(n, k == 0 ? "latest" : "normal", message_text(msg, len));
        PERIODIC_WAIT(&rc);
    }
}

static void reader(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_IN", 16, DESTINATION, 50 * MS, &port_in, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_IN", rc);
    start_new_process("reader", reader_process, 10, 20 * MS);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "writer") == 0)
        writer();
    else if (strcmp(scenario, "reader") == 0)
        reader();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
