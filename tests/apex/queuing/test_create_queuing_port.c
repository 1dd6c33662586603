/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_QUEUING_PORT (ARINC 653 Part 1, 3.6.2.2): NO_ERROR for a port as configured;
 * INVALID_CONFIG for an unknown name or a size, capacity or direction that differs from the
 * configuration; INVALID_PARAM for an invalid queuing discipline; NO_ACTION once created;
 * INVALID_MODE in NORMAL mode. A refused call leaves the identifier alone. Configuration:
 * QP_SRC (source, 32 bytes, 4 messages), QP_DST (destination, 32 bytes, 6 messages), QP_LATE
 * (source, 8 bytes, 2 messages), sampling port SP_S. */
#include "apex_check.h"

static void try_create(const char *check, const char *name, MESSAGE_SIZE_TYPE size,
                       MESSAGE_RANGE_TYPE nb, PORT_DIRECTION_TYPE dir,
                       QUEUING_DISCIPLINE_TYPE discipline, RETURN_CODE_TYPE expect)
{
    QUEUING_PORT_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT(name, size, nb, dir, discipline, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id_untouched", check);
    check_int(n, UNTOUCHED, id);
}

static void in_normal(void)
{
    try_create("normal.create", "QP_LATE", 8, 2, SOURCE, FIFO, INVALID_MODE);
    QUEUING_PORT_ID_TYPE id;
    RETURN_CODE_TYPE rc;
    GET_QUEUING_PORT_ID("QP_LATE", &id, &rc);
    check_rc("normal.create.not_created", INVALID_CONFIG, rc);
}

int main(void)
{
    try_create("unknown_name", "QP_NOPE", 32, 4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("sampling_port_name", "SP_S", 32, 4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("size_smaller", "QP_SRC", 16, 4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("size_larger", "QP_SRC", 64, 4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("size_zero", "QP_SRC", 0, 4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("size_negative", "QP_SRC", -32, 4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("nb_message_smaller", "QP_SRC", 32, 3, SOURCE, FIFO, INVALID_CONFIG);
    try_create("nb_message_larger", "QP_SRC", 32, 5, SOURCE, FIFO, INVALID_CONFIG);
    try_create("nb_message_zero", "QP_SRC", 32, 0, SOURCE, FIFO, INVALID_CONFIG);
    try_create("nb_message_negative", "QP_SRC", 32, -4, SOURCE, FIFO, INVALID_CONFIG);
    try_create("direction_differs", "QP_SRC", 32, 4, DESTINATION, FIFO, INVALID_CONFIG);
    try_create("direction_invalid", "QP_SRC", 32, 4, (PORT_DIRECTION_TYPE)7, FIFO, INVALID_CONFIG);
    try_create("discipline_invalid", "QP_SRC", 32, 4, SOURCE, (QUEUING_DISCIPLINE_TYPE)5,
               INVALID_PARAM);
    try_create("discipline_negative", "QP_SRC", 32, 4, SOURCE, (QUEUING_DISCIPLINE_TYPE)-1,
               INVALID_PARAM);

    QUEUING_PORT_ID_TYPE src = UNTOUCHED, dst = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_QUEUING_PORT("QP_SRC", 32, 4, SOURCE, FIFO, &src, &rc);
    check_rc("source_fifo", NO_ERROR, rc);
    check_true("source_fifo.id_written", src != UNTOUCHED);
    CREATE_QUEUING_PORT("QP_DST", 32, 6, DESTINATION, PRIORITY, &dst, &rc);
    check_rc("destination_priority", NO_ERROR, rc);
    check_true("destination_priority.id_written", dst != UNTOUCHED);
    check_true("ids_distinct", src != dst);

    try_create("already_created", "QP_SRC", 32, 4, SOURCE, FIFO, NO_ACTION);
    try_create("already_created.destination", "QP_DST", 32, 6, DESTINATION, PRIORITY, NO_ACTION);

    /* The port is usable under the identifier it got. */
    APEX_BYTE msg[32] = "created";
    SEND_QUEUING_MESSAGE(src, msg, sizeof msg, 0, &rc);
    check_rc("source.usable", NO_ERROR, rc);

    start_new_process("in_normal", in_normal, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
