/* SPDX-License-Identifier: Apache-2.0 */
/* CREATE_BUFFER (ARINC 653 Part 1, 3.7.2.1). Scenario "create": every return code but the
 * limit on the number of buffers, during initialisation and in NORMAL mode. Scenario
 * "limits": MAX_NUMBER_OF_BUFFERS buffers, then INVALID_CONFIG. */
#include "apex_check.h"

static void try_create(const char *check, const char *name, MESSAGE_SIZE_TYPE size,
                       MESSAGE_RANGE_TYPE nb, QUEUING_DISCIPLINE_TYPE discipline,
                       RETURN_CODE_TYPE expect)
{
    BUFFER_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    CREATE_BUFFER(name, size, nb, discipline, &id, &rc);
    check_rc(check, expect, rc);
    char n[64];
    snprintf(n, sizeof n, "%s.id", check);
    if (expect != NO_ERROR) {
        check_int(n, UNTOUCHED, id);
        return;
    }
    BUFFER_ID_TYPE by_name = UNTOUCHED;
    GET_BUFFER_ID(name, &by_name, &rc);
    setup_rc("GET_BUFFER_ID", rc);
    check_int(n, by_name, id); /* the identifier GET_BUFFER_ID gives */
}

static void late(void)
{
    try_create("normal.new", "LATE", 8, 1, FIFO, INVALID_MODE);
    try_create("normal.existing", "B1", 8, 1, FIFO, NO_ACTION);
}

static void create(void)
{
    try_create("init.created", "B1", 16, 4, FIFO, NO_ERROR);
    try_create("init.same_name", "B1", 8, 2, PRIORITY, NO_ACTION);
    try_create("init.size_zero", "B2", 0, 4, FIFO, INVALID_PARAM);
    try_create("init.size_negative", "B2", -1, 4, FIFO, INVALID_PARAM);
    try_create("init.size_over_limit", "B2", SYSTEM_LIMIT_MESSAGE_SIZE + 1, 4, FIFO, INVALID_PARAM);
    try_create("init.nb_zero", "B2", 8, 0, FIFO, INVALID_PARAM);
    try_create("init.nb_negative", "B2", 8, -1, FIFO, INVALID_PARAM);
    try_create("init.nb_over_limit", "B2", 8, SYSTEM_LIMIT_NUMBER_OF_MESSAGES + 1, FIFO,
               INVALID_PARAM);
    try_create("init.discipline", "B2", 8, 4, (QUEUING_DISCIPLINE_TYPE)2, INVALID_PARAM);
    try_create("init.empty_name", "", 8, 4, FIFO, INVALID_PARAM);
    /* 17 messages of 1 MiB: more than the partition's 16 MiB of message storage. */
    try_create("init.storage", "BIG", SYSTEM_LIMIT_MESSAGE_SIZE, 17, FIFO, INVALID_CONFIG);
    try_create("init.priority", "B2", SYSTEM_LIMIT_MESSAGE_SIZE, 1, PRIORITY, NO_ERROR);

    /* A name filling NAME_TYPE needs no terminator. */
    NAME_TYPE full;
    memcpy(full, "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123", MAX_NAME_LENGTH);
    try_create("init.full_length_name", full, 8, 1, FIFO, NO_ERROR);

    BUFFER_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    BUFFER_ID_TYPE id;
    GET_BUFFER_ID("B1", &id, &rc);
    setup_rc("GET_BUFFER_ID", rc);
    GET_BUFFER_STATUS(id, &st, &rc);
    setup_rc("GET_BUFFER_STATUS", rc);
    check_int("init.created.max_message_size", 16, st.MAX_MESSAGE_SIZE);
    check_int("init.created.max_nb_message", 4, st.MAX_NB_MESSAGE);
    check_int("init.created.nb_message", 0, st.NB_MESSAGE);

    start_new_process("late", late, 10, INFINITE_TIME_VALUE);
    enter_normal();
}

static void limits(void)
{
    int created = 0;
    for (int i = 0; i < MAX_NUMBER_OF_BUFFERS; i++) {
        char name[16];
        snprintf(name, sizeof name, "L%d", i);
        BUFFER_ID_TYPE id;
        RETURN_CODE_TYPE rc;
        CREATE_BUFFER(name, 4, 1, FIFO, &id, &rc);
        created += rc == NO_ERROR && id == i + 1;
    }
    check_int("limits.created", MAX_NUMBER_OF_BUFFERS, created);
    try_create("limits.one_more", "MORE", 4, 1, FIFO, INVALID_CONFIG);
    try_create("limits.existing_name", "L0", 4, 1, FIFO, INVALID_CONFIG);
    enter_normal();
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "create") == 0)
        create();
    else if (strcmp(scenario, "limits") == 0)
        limits();
    else
        report("SETUP unknown scenario '%s'", scenario);
    return 1;
}
