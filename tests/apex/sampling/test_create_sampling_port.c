/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_SAMPLING_PORT (ARINC 653 Part 1, 3.6.2.1): NO_ERROR for a port as configured;
 * INVALID_CONFIG for an unknown name or a size, direction or refresh period that differs from
 * the configuration; NO_ACTION once created; INVALID_MODE in NORMAL mode. A refused call
 * leaves the identifier alone. Configuration: SP_SRC (source, 32 bytes, 50 ms), SP_DST
 * (destination, 32 bytes, 50 ms), SP_LATE (source, 8 bytes, 20 ms), queuing port QP_X. */
#include "apex_check.h"

static void try_create(const char *check, const char *name, MESSAGE_SIZE_TYPE size,
                       PORT_DIRECTION_TYPE dir, SYSTEM_TIME_TYPE refresh,
                       RETURN_CODE_TYPE expect)
{
    SAMPLING_PORT_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT(name, size, dir, refresh, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id_untouched", check);
    check_int(n, UNTOUCHED, id);
}

static void in_normal(void)
{
    try_create("normal.create", "SP_LATE", 8, SOURCE, 20 * MS, INVALID_MODE);
    SAMPLING_PORT_ID_TYPE id;
    RETURN_CODE_TYPE rc;
    GET_SAMPLING_PORT_ID("SP_LATE", &id, &rc);
    check_rc("normal.create.not_created", INVALID_CONFIG, rc);
}

int main(void)
{
    try_create("unknown_name", "SP_NOPE", 32, SOURCE, 50 * MS, INVALID_CONFIG);
    try_create("queuing_port_name", "QP_X", 32, SOURCE, 50 * MS, INVALID_CONFIG);
    try_create("size_smaller", "SP_SRC", 16, SOURCE, 50 * MS, INVALID_CONFIG);
    try_create("size_larger", "SP_SRC", 33, SOURCE, 50 * MS, INVALID_CONFIG);
    try_create("size_zero", "SP_SRC", 0, SOURCE, 50 * MS, INVALID_CONFIG);
    try_create("size_negative", "SP_SRC", -32, SOURCE, 50 * MS, INVALID_CONFIG);
    try_create("direction_differs", "SP_SRC", 32, DESTINATION, 50 * MS, INVALID_CONFIG);
    try_create("direction_invalid", "SP_SRC", 32, (PORT_DIRECTION_TYPE)7, 50 * MS, INVALID_CONFIG);
    try_create("refresh_differs", "SP_SRC", 32, SOURCE, 100 * MS, INVALID_CONFIG);
    try_create("refresh_negative", "SP_SRC", 32, SOURCE, -50 * MS, INVALID_CONFIG);
    try_create("refresh_infinite", "SP_SRC", 32, SOURCE, INFINITE_TIME_VALUE, INVALID_CONFIG);

    SAMPLING_PORT_ID_TYPE src = UNTOUCHED, dst = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_SRC", 32, SOURCE, 50 * MS, &src, &rc);
    check_rc("source", NO_ERROR, rc);
    check_true("source.id_written", src != UNTOUCHED);
    CREATE_SAMPLING_PORT("SP_DST", 32, DESTINATION, 50 * MS, &dst, &rc);
    check_rc("destination", NO_ERROR, rc);
    check_true("destination.id_written", dst != UNTOUCHED);
    check_true("ids_distinct", src != dst);

    try_create("already_created", "SP_SRC", 32, SOURCE, 50 * MS, NO_ACTION);
    try_create("already_created.destination", "SP_DST", 32, DESTINATION, 50 * MS, NO_ACTION);

    /* The port is usable under the identifier it got. */
    APEX_BYTE msg[32] = "created";
    WRITE_SAMPLING_MESSAGE(src, msg, sizeof msg, &rc);
    check_rc("source.usable", NO_ERROR, rc);

    start_new_process("in_normal", in_normal, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
