/* SPDX-License-Identifier: Apache-2.0 */
/* PERIODIC_WAIT (ARINC 653 Part 1, 3.4.2): NO_ERROR for a periodic process, which is then
 * released at successive release points exactly PERIOD apart (seen in GET_TIME) with
 * DEADLINE_TIME = release + TIME_CAPACITY; INVALID_MODE for an aperiodic process and for the
 * initialisation process. The partition period is 10 ms and its window covers 0-15 ms of a
 * 20 ms major frame, so that some release points fall inside a window. */
#include "apex_check.h"

#define RELEASES 6

static PROCESS_ID_TYPE ids[2];

static void record_releases(int which, const char *name, SYSTEM_TIME_TYPE period)
{
    SYSTEM_TIME_TYPE release[RELEASES], deadline[RELEASES];
    int errors = 0;
    for (int k = 0; k < RELEASES; k++) {
        RETURN_CODE_TYPE rc;
        PROCESS_STATUS_TYPE st;
        release[k] = now_ns();
        GET_PROCESS_STATUS(ids[which], &st, &rc);
        deadline[k] = st.DEADLINE_TIME;
        if (k < RELEASES - 1) {
            PERIODIC_WAIT(&rc);
            errors += rc != NO_ERROR;
        }
    }
    char n[64];
    snprintf(n, sizeof n, "%s.errors", name);
    check_int(n, 0, errors);
    snprintf(n, sizeof n, "%s.first_release", name);
    check_int(n, 0, release[0]);
    for (int k = 1; k < RELEASES; k++) {
        snprintf(n, sizeof n, "%s.release_interval.%d", name, k);
        check_int(n, period, release[k] - release[k - 1]);
    }
    for (int k = 0; k < RELEASES; k++) {
        snprintf(n, sizeof n, "%s.deadline.%d", name, k);
        check_int(n, release[k] + period / 2, deadline[k]);
    }
}

static void p10(void) { record_releases(0, "p10", 10 * MS); }
static void p20(void) { record_releases(1, "p20", 20 * MS); }

static void aperiodic(void)
{
    RETURN_CODE_TYPE rc;
    PERIODIC_WAIT(&rc);
    check_rc("aperiodic", INVALID_MODE, rc);
}

static PROCESS_ID_TYPE periodic(const char *name, void (*entry)(void), PRIORITY_TYPE priority,
                                SYSTEM_TIME_TYPE period)
{
    PROCESS_ATTRIBUTE_TYPE a = process_attributes(name, entry, priority, period, period / 2);
    PROCESS_ID_TYPE id = NULL_PROCESS_ID;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &id, &rc);
    setup_rc(name, rc);
    START(id, &rc);
    setup_rc("START", rc);
    return id;
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    PERIODIC_WAIT(&rc);
    check_rc("init", INVALID_MODE, rc);
    ids[0] = periodic("p10", p10, 20, 10 * MS);
    ids[1] = periodic("p20", p20, 10, 20 * MS);
    start_new_process("aperiodic", aperiodic, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
