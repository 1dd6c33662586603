/* SPDX-License-Identifier: Apache-2.0 */
/* Null and invalid addresses given to APEX services, table-driven. Partition "faults": every
 * pointer parameter of every service null in turn (all others valid), a null RETURN_CODE for
 * every service, and unreadable or unwritable addresses for some are the caller's
 * ILLEGAL_REQUEST for the health monitor (here handled at process level by the error handler),
 * with no output written, never a MEMORY_VIOLATION of the library. Partition "nulls": the few
 * documented exceptions, where a null is not an address the service uses, return their code. */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE sp_src, sp_dst;
static QUEUING_PORT_ID_TYPE qp_src, qp_dst;
static BUFFER_ID_TYPE buf_id;
static BLACKBOARD_ID_TYPE bb_id;
static SEMAPHORE_ID_TYPE sem_id;
static EVENT_ID_TYPE evt_id;
static PROCESS_ID_TYPE proc_id;

static APEX_BYTE msg[16] = "hello";
static MESSAGE_SIZE_TYPE len;
static VALIDITY_TYPE validity;
static UPDATED_TYPE updated;
static SYSTEM_TIME_TYPE t;
static LOCK_LEVEL_TYPE level;
static PROCESS_ATTRIBUTE_TYPE attr;
static PROCESS_ATTRIBUTE_TYPE attr_no_entry;
static APEX_INTEGER id_out;

static void worker(void) {}
static void handler(void);

/* ---- null pointers ----------------------------------------------------------------------- */

/* A null pointer is an address the service cannot use: the caller's ILLEGAL_REQUEST for the
 * health monitor, as an unusable address is (run by the victim of partition "faults"). */
#define ILLEGAL ((RETURN_CODE_TYPE)-1)

/* X(check name, expected return code or ILLEGAL, the call with rc as its RETURN_CODE). The
 * return codes are the documented exceptions, where the null is not an address the service
 * uses: a message of length 0 is not read; an entry point is a value, checked as such. */
#define NULL_CASES(X)                                                                          \
    X(GET_PARTITION_STATUS__PARTITION_STATUS, ILLEGAL, GET_PARTITION_STATUS(NULL, &rc))  \
    X(CREATE_PROCESS__ATTRIBUTES, ILLEGAL, CREATE_PROCESS(NULL, &id_out, &rc))          \
    X(CREATE_PROCESS__PROCESS_ID, ILLEGAL, CREATE_PROCESS(&attr, NULL, &rc))            \
    X(CREATE_PROCESS__ENTRY_POINT, INVALID_PARAM, CREATE_PROCESS(&attr_no_entry, &id_out, &rc)) \
    X(LOCK_PREEMPTION__LOCK_LEVEL, ILLEGAL, LOCK_PREEMPTION(NULL, &rc))                 \
    X(UNLOCK_PREEMPTION__LOCK_LEVEL, ILLEGAL, UNLOCK_PREEMPTION(NULL, &rc))             \
    X(GET_MY_ID__PROCESS_ID, ILLEGAL, GET_MY_ID(NULL, &rc))                             \
    X(GET_PROCESS_ID__PROCESS_NAME, ILLEGAL, GET_PROCESS_ID(NULL, &id_out, &rc))        \
    X(GET_PROCESS_ID__PROCESS_ID, ILLEGAL, GET_PROCESS_ID("worker", NULL, &rc))         \
    X(GET_PROCESS_STATUS__PROCESS_STATUS, ILLEGAL, GET_PROCESS_STATUS(proc_id, NULL, &rc)) \
    X(GET_TIME__SYSTEM_TIME, ILLEGAL, GET_TIME(NULL, &rc))                              \
    X(CREATE_SAMPLING_PORT__SAMPLING_PORT_NAME, ILLEGAL,                                 \
      CREATE_SAMPLING_PORT(NULL, 16, SOURCE, 20 * MS, &id_out, &rc))                           \
    X(CREATE_SAMPLING_PORT__SAMPLING_PORT_ID, ILLEGAL,                                   \
      CREATE_SAMPLING_PORT("SP_UNUSED", 16, SOURCE, 20 * MS, NULL, &rc))                       \
    X(WRITE_SAMPLING_MESSAGE__MESSAGE_ADDR, ILLEGAL,                                     \
      WRITE_SAMPLING_MESSAGE(sp_src, NULL, 4, &rc))                                            \
    X(READ_SAMPLING_MESSAGE__MESSAGE_ADDR, ILLEGAL,                                      \
      READ_SAMPLING_MESSAGE(sp_dst, NULL, &len, &validity, &rc))                               \
    X(READ_SAMPLING_MESSAGE__LENGTH, ILLEGAL,                                            \
      READ_SAMPLING_MESSAGE(sp_dst, msg, NULL, &validity, &rc))                                \
    X(READ_SAMPLING_MESSAGE__VALIDITY, ILLEGAL,                                          \
      READ_SAMPLING_MESSAGE(sp_dst, msg, &len, NULL, &rc))                                     \
    X(GET_SAMPLING_PORT_ID__SAMPLING_PORT_NAME, ILLEGAL,                                 \
      GET_SAMPLING_PORT_ID(NULL, &id_out, &rc))                                                \
    X(GET_SAMPLING_PORT_ID__SAMPLING_PORT_ID, ILLEGAL,                                   \
      GET_SAMPLING_PORT_ID("SP_SRC", NULL, &rc))                                               \
    X(GET_SAMPLING_PORT_STATUS__SAMPLING_PORT_STATUS, ILLEGAL,                           \
      GET_SAMPLING_PORT_STATUS(sp_src, NULL, &rc))                                             \
    X(READ_UPDATED_SAMPLING_MESSAGE__MESSAGE_ADDR, ILLEGAL,                              \
      READ_UPDATED_SAMPLING_MESSAGE(sp_dst, NULL, &len, &updated, &rc))                        \
    X(READ_UPDATED_SAMPLING_MESSAGE__LENGTH, ILLEGAL,                                    \
      READ_UPDATED_SAMPLING_MESSAGE(sp_dst, msg, NULL, &updated, &rc))                         \
    X(READ_UPDATED_SAMPLING_MESSAGE__UPDATED, ILLEGAL,                                   \
      READ_UPDATED_SAMPLING_MESSAGE(sp_dst, msg, &len, NULL, &rc))                             \
    X(GET_SAMPLING_PORT_CURRENT_STATUS__SAMPLING_PORT_CURRENT_STATUS, ILLEGAL,           \
      GET_SAMPLING_PORT_CURRENT_STATUS(sp_dst, NULL, &rc))                                     \
    X(READ_SAMPLING_MESSAGE_CONDITIONAL__MESSAGE_ADDR, ILLEGAL,                          \
      READ_SAMPLING_MESSAGE_CONDITIONAL(sp_dst, 0, NULL, &len, &t, &rc))                       \
    X(READ_SAMPLING_MESSAGE_CONDITIONAL__LENGTH, ILLEGAL,                                \
      READ_SAMPLING_MESSAGE_CONDITIONAL(sp_dst, 0, msg, NULL, &t, &rc))                        \
    X(READ_SAMPLING_MESSAGE_CONDITIONAL__TIME_STAMP, ILLEGAL,                            \
      READ_SAMPLING_MESSAGE_CONDITIONAL(sp_dst, 0, msg, &len, NULL, &rc))                      \
    X(CREATE_QUEUING_PORT__QUEUING_PORT_NAME, ILLEGAL,                                   \
      CREATE_QUEUING_PORT(NULL, 16, 4, SOURCE, FIFO, &id_out, &rc))                            \
    X(CREATE_QUEUING_PORT__QUEUING_PORT_ID, ILLEGAL,                                     \
      CREATE_QUEUING_PORT("QP_UNUSED", 16, 4, SOURCE, FIFO, NULL, &rc))                        \
    X(SEND_QUEUING_MESSAGE__MESSAGE_ADDR, ILLEGAL,                                       \
      SEND_QUEUING_MESSAGE(qp_src, NULL, 4, 0, &rc))                                           \
    X(RECEIVE_QUEUING_MESSAGE__MESSAGE_ADDR, ILLEGAL,                                    \
      RECEIVE_QUEUING_MESSAGE(qp_dst, 0, NULL, &len, &rc))                                     \
    X(RECEIVE_QUEUING_MESSAGE__LENGTH, ILLEGAL,                                          \
      RECEIVE_QUEUING_MESSAGE(qp_dst, 0, msg, NULL, &rc))                                      \
    X(GET_QUEUING_PORT_ID__QUEUING_PORT_NAME, ILLEGAL,                                   \
      GET_QUEUING_PORT_ID(NULL, &id_out, &rc))                                                 \
    X(GET_QUEUING_PORT_ID__QUEUING_PORT_ID, ILLEGAL,                                     \
      GET_QUEUING_PORT_ID("QP_SRC", NULL, &rc))                                                \
    X(GET_QUEUING_PORT_STATUS__QUEUING_PORT_STATUS, ILLEGAL,                             \
      GET_QUEUING_PORT_STATUS(qp_src, NULL, &rc))                                              \
    X(CREATE_BUFFER__BUFFER_NAME, ILLEGAL, CREATE_BUFFER(NULL, 16, 4, FIFO, &id_out, &rc)) \
    X(CREATE_BUFFER__BUFFER_ID, ILLEGAL, CREATE_BUFFER("B2", 16, 4, FIFO, NULL, &rc))   \
    X(SEND_BUFFER__MESSAGE_ADDR, ILLEGAL, SEND_BUFFER(buf_id, NULL, 4, 0, &rc))         \
    X(RECEIVE_BUFFER__MESSAGE_ADDR, ILLEGAL, RECEIVE_BUFFER(buf_id, 0, NULL, &len, &rc)) \
    X(RECEIVE_BUFFER__LENGTH, ILLEGAL, RECEIVE_BUFFER(buf_id, 0, msg, NULL, &rc))       \
    X(GET_BUFFER_ID__BUFFER_NAME, ILLEGAL, GET_BUFFER_ID(NULL, &id_out, &rc))           \
    X(GET_BUFFER_ID__BUFFER_ID, ILLEGAL, GET_BUFFER_ID("BUF", NULL, &rc))               \
    X(GET_BUFFER_STATUS__BUFFER_STATUS, ILLEGAL, GET_BUFFER_STATUS(buf_id, NULL, &rc))  \
    X(CREATE_BLACKBOARD__BLACKBOARD_NAME, ILLEGAL,                                       \
      CREATE_BLACKBOARD(NULL, 16, &id_out, &rc))                                               \
    X(CREATE_BLACKBOARD__BLACKBOARD_ID, ILLEGAL, CREATE_BLACKBOARD("BB2", 16, NULL, &rc)) \
    X(DISPLAY_BLACKBOARD__MESSAGE_ADDR, ILLEGAL, DISPLAY_BLACKBOARD(bb_id, NULL, 4, &rc)) \
    X(READ_BLACKBOARD__MESSAGE_ADDR, ILLEGAL, READ_BLACKBOARD(bb_id, 0, NULL, &len, &rc)) \
    X(READ_BLACKBOARD__LENGTH, ILLEGAL, READ_BLACKBOARD(bb_id, 0, msg, NULL, &rc))      \
    X(GET_BLACKBOARD_ID__BLACKBOARD_NAME, ILLEGAL, GET_BLACKBOARD_ID(NULL, &id_out, &rc)) \
    X(GET_BLACKBOARD_ID__BLACKBOARD_ID, ILLEGAL, GET_BLACKBOARD_ID("BB", NULL, &rc))    \
    X(GET_BLACKBOARD_STATUS__BLACKBOARD_STATUS, ILLEGAL,                                 \
      GET_BLACKBOARD_STATUS(bb_id, NULL, &rc))                                                 \
    X(CREATE_SEMAPHORE__SEMAPHORE_NAME, ILLEGAL,                                         \
      CREATE_SEMAPHORE(NULL, 0, 1, FIFO, &id_out, &rc))                                        \
    X(CREATE_SEMAPHORE__SEMAPHORE_ID, ILLEGAL,                                           \
      CREATE_SEMAPHORE("S2", 0, 1, FIFO, NULL, &rc))                                           \
    X(GET_SEMAPHORE_ID__SEMAPHORE_NAME, ILLEGAL, GET_SEMAPHORE_ID(NULL, &id_out, &rc))  \
    X(GET_SEMAPHORE_ID__SEMAPHORE_ID, ILLEGAL, GET_SEMAPHORE_ID("SEM", NULL, &rc))      \
    X(GET_SEMAPHORE_STATUS__SEMAPHORE_STATUS, ILLEGAL,                                   \
      GET_SEMAPHORE_STATUS(sem_id, NULL, &rc))                                                 \
    X(CREATE_EVENT__EVENT_NAME, ILLEGAL, CREATE_EVENT(NULL, &id_out, &rc))              \
    X(CREATE_EVENT__EVENT_ID, ILLEGAL, CREATE_EVENT("E2", NULL, &rc))                   \
    X(GET_EVENT_ID__EVENT_NAME, ILLEGAL, GET_EVENT_ID(NULL, &id_out, &rc))              \
    X(GET_EVENT_ID__EVENT_ID, ILLEGAL, GET_EVENT_ID("EVT", NULL, &rc))                  \
    X(GET_EVENT_STATUS__EVENT_STATUS, ILLEGAL, GET_EVENT_STATUS(evt_id, NULL, &rc))     \
    X(REPORT_APPLICATION_MESSAGE__MESSAGE_ADDR, ILLEGAL,                                 \
      REPORT_APPLICATION_MESSAGE(NULL, 4, &rc))                                                \
    X(REPORT_APPLICATION_MESSAGE__MESSAGE_ADDR_LENGTH_0, NO_ERROR,                             \
      REPORT_APPLICATION_MESSAGE(NULL, 0, &rc))                                                \
    X(CREATE_ERROR_HANDLER__ENTRY_POINT, INVALID_CONFIG, CREATE_ERROR_HANDLER(NULL, 65536, &rc)) \
    X(GET_ERROR_STATUS__ERROR_STATUS, ILLEGAL, GET_ERROR_STATUS(NULL, &rc))             \
    X(RAISE_APPLICATION_ERROR__MESSAGE_ADDR, ILLEGAL,                                    \
      RAISE_APPLICATION_ERROR(APPLICATION_ERROR, NULL, 4, &rc))                                \
    X(GET_MODULE_SCHEDULE_STATUS__SCHEDULE_STATUS, ILLEGAL,                              \
      GET_MODULE_SCHEDULE_STATUS(NULL, &rc))                                                   \
    X(GET_MODULE_SCHEDULE_ID__SCHEDULE_NAME, ILLEGAL,                                    \
      GET_MODULE_SCHEDULE_ID(NULL, &id_out, &rc))                                              \
    X(GET_MODULE_SCHEDULE_ID__SCHEDULE_ID, ILLEGAL, GET_MODULE_SCHEDULE_ID("main", NULL, &rc))

#define DEFINE_CALL(name, expect, call)                                                        \
    static RETURN_CODE_TYPE name(void)                                                         \
    {                                                                                          \
        RETURN_CODE_TYPE rc = (RETURN_CODE_TYPE)UNTOUCHED;                                     \
        call;                                                                                  \
        return rc;                                                                             \
    }
NULL_CASES(DEFINE_CALL)

static const struct {
    const char *name;
    RETURN_CODE_TYPE expect;
    RETURN_CODE_TYPE (*call)(void);
} null_cases[] = {
#define NULL_ROW(name, expect, call) {#name, expect, name},
    NULL_CASES(NULL_ROW)
};

/* "SERVICE__PARAMETER" as "SERVICE.PARAMETER". */
static const char *check_name(const char *prefix, const char *id)
{
    static char n[96];
    snprintf(n, sizeof n, "%s%s", prefix, id);
    char *sep = strstr(n, "__");
    if (sep) {
        *sep = '.';
        memmove(sep + 1, sep + 2, strlen(sep + 2) + 1);
    }
    return n;
}

/* Every output a null case could have written still holds what the set-up put there. */
static bool outputs_untouched(void)
{
    return len == UNTOUCHED && validity == (VALIDITY_TYPE)UNTOUCHED &&
           updated == (UPDATED_TYPE)UNTOUCHED && t == UNTOUCHED && level == UNTOUCHED &&
           id_out == UNTOUCHED && strcmp((const char *)msg, "hello") == 0;
}

#define N_NULLS (sizeof null_cases / sizeof null_cases[0])

static void reset_outputs(void)
{
    len = UNTOUCHED;
    validity = (VALIDITY_TYPE)UNTOUCHED;
    updated = (UPDATED_TYPE)UNTOUCHED;
    t = UNTOUCHED;
    level = UNTOUCHED;
    id_out = UNTOUCHED;
}

/* The exceptions, which return: their return code, and no output written. */
static void run_null_exceptions(void)
{
    for (size_t i = 0; i < N_NULLS; i++) {
        if (null_cases[i].expect == ILLEGAL)
            continue;
        reset_outputs();
        RETURN_CODE_TYPE rc = null_cases[i].call();
        check_rc(check_name("", null_cases[i].name), null_cases[i].expect, rc);
        check_true(check_name("untouched.", null_cases[i].name), outputs_untouched());
    }
}

/* ---- a null RETURN_CODE, unusable addresses: ILLEGAL_REQUEST --------------------------- */

static const RETURN_CODE_TYPE read_only_rc = NO_ERROR; /* in read-only memory */
static const SAMPLING_PORT_CURRENT_STATUS_TYPE read_only_status;
static ERROR_STATUS_TYPE error_status;
static PARTITION_STATUS_TYPE partition_status;
static PROCESS_STATUS_TYPE process_status;
static SAMPLING_PORT_STATUS_TYPE sp_status;
static SAMPLING_PORT_CURRENT_STATUS_TYPE sp_current;
static QUEUING_PORT_STATUS_TYPE qp_status;
static BUFFER_STATUS_TYPE buf_status;
static BLACKBOARD_STATUS_TYPE bb_status;
static SEMAPHORE_STATUS_TYPE sem_status;
static EVENT_STATUS_TYPE evt_status;
static SCHEDULE_STATUS_TYPE schedule_status;
#define BAD(type) ((type)(uintptr_t)16) /* an address no partition maps */

/* X(check name, the call). Every argument but the one under test is harmless: an unknown
 * identifier, a zero time-out, so that a call that went on anyway would change nothing. */
#define FAULT_CASES(X)                                                                         \
    X(GET_PARTITION_STATUS, GET_PARTITION_STATUS(&partition_status, NULL))                     \
    X(SET_PARTITION_MODE, SET_PARTITION_MODE(NORMAL, NULL))                                    \
    X(CREATE_PROCESS, CREATE_PROCESS(&attr, &id_out, NULL))                                    \
    X(START, START(0, NULL))                                                                   \
    X(STOP, STOP(0, NULL))                                                                     \
    X(SUSPEND_SELF, SUSPEND_SELF(0, NULL))                                                     \
    X(SUSPEND, SUSPEND(0, NULL))                                                               \
    X(RESUME, RESUME(0, NULL))                                                                 \
    X(SET_PRIORITY, SET_PRIORITY(0, 10, NULL))                                                 \
    X(DELAYED_START, DELAYED_START(0, 0, NULL))                                                \
    X(LOCK_PREEMPTION, LOCK_PREEMPTION(&level, NULL))                                          \
    X(UNLOCK_PREEMPTION, UNLOCK_PREEMPTION(&level, NULL))                                      \
    X(GET_MY_ID, GET_MY_ID(&id_out, NULL))                                                     \
    X(GET_PROCESS_ID, GET_PROCESS_ID("worker", &id_out, NULL))                                 \
    X(GET_PROCESS_STATUS, GET_PROCESS_STATUS(proc_id, &process_status, NULL))                  \
    X(TIMED_WAIT, TIMED_WAIT(0, NULL))                                                         \
    X(PERIODIC_WAIT, PERIODIC_WAIT(NULL))                                                      \
    X(GET_TIME, GET_TIME(&t, NULL))                                                            \
    X(REPLENISH, REPLENISH(0, NULL))                                                           \
    X(CREATE_SAMPLING_PORT, CREATE_SAMPLING_PORT("SP_SRC", 16, SOURCE, 20 * MS, &id_out, NULL)) \
    X(WRITE_SAMPLING_MESSAGE, WRITE_SAMPLING_MESSAGE(0, msg, 4, NULL))                         \
    X(READ_SAMPLING_MESSAGE, READ_SAMPLING_MESSAGE(sp_dst, msg, &len, &validity, NULL))        \
    X(GET_SAMPLING_PORT_ID, GET_SAMPLING_PORT_ID("SP_SRC", &id_out, NULL))                     \
    X(GET_SAMPLING_PORT_STATUS, GET_SAMPLING_PORT_STATUS(sp_src, &sp_status, NULL))            \
    X(READ_UPDATED_SAMPLING_MESSAGE,                                                           \
      READ_UPDATED_SAMPLING_MESSAGE(sp_dst, msg, &len, &updated, NULL))                        \
    X(GET_SAMPLING_PORT_CURRENT_STATUS,                                                        \
      GET_SAMPLING_PORT_CURRENT_STATUS(sp_dst, &sp_current, NULL))                             \
    X(READ_SAMPLING_MESSAGE_CONDITIONAL,                                                       \
      READ_SAMPLING_MESSAGE_CONDITIONAL(sp_dst, 0, msg, &len, &t, NULL))                       \
    X(CREATE_QUEUING_PORT, CREATE_QUEUING_PORT("QP_SRC", 16, 4, SOURCE, FIFO, &id_out, NULL))  \
    X(SEND_QUEUING_MESSAGE, SEND_QUEUING_MESSAGE(0, msg, 4, 0, NULL))                          \
    X(RECEIVE_QUEUING_MESSAGE, RECEIVE_QUEUING_MESSAGE(qp_dst, 0, msg, &len, NULL))            \
    X(GET_QUEUING_PORT_ID, GET_QUEUING_PORT_ID("QP_SRC", &id_out, NULL))                       \
    X(GET_QUEUING_PORT_STATUS, GET_QUEUING_PORT_STATUS(qp_src, &qp_status, NULL))              \
    X(CLEAR_QUEUING_PORT, CLEAR_QUEUING_PORT(qp_dst, NULL))                                    \
    X(CREATE_BUFFER, CREATE_BUFFER("BUF", 16, 4, FIFO, &id_out, NULL))                         \
    X(SEND_BUFFER, SEND_BUFFER(0, msg, 4, 0, NULL))                                            \
    X(RECEIVE_BUFFER, RECEIVE_BUFFER(buf_id, 0, msg, &len, NULL))                              \
    X(GET_BUFFER_ID, GET_BUFFER_ID("BUF", &id_out, NULL))                                      \
    X(GET_BUFFER_STATUS, GET_BUFFER_STATUS(buf_id, &buf_status, NULL))                         \
    X(CREATE_BLACKBOARD, CREATE_BLACKBOARD("BB", 16, &id_out, NULL))                           \
    X(DISPLAY_BLACKBOARD, DISPLAY_BLACKBOARD(0, msg, 4, NULL))                                 \
    X(READ_BLACKBOARD, READ_BLACKBOARD(bb_id, 0, msg, &len, NULL))                             \
    X(CLEAR_BLACKBOARD, CLEAR_BLACKBOARD(0, NULL))                                             \
    X(GET_BLACKBOARD_ID, GET_BLACKBOARD_ID("BB", &id_out, NULL))                               \
    X(GET_BLACKBOARD_STATUS, GET_BLACKBOARD_STATUS(bb_id, &bb_status, NULL))                   \
    X(CREATE_SEMAPHORE, CREATE_SEMAPHORE("SEM", 0, 1, FIFO, &id_out, NULL))                    \
    X(WAIT_SEMAPHORE, WAIT_SEMAPHORE(0, 0, NULL))                                              \
    X(SIGNAL_SEMAPHORE, SIGNAL_SEMAPHORE(0, NULL))                                             \
    X(GET_SEMAPHORE_ID, GET_SEMAPHORE_ID("SEM", &id_out, NULL))                                \
    X(GET_SEMAPHORE_STATUS, GET_SEMAPHORE_STATUS(sem_id, &sem_status, NULL))                   \
    X(CREATE_EVENT, CREATE_EVENT("EVT", &id_out, NULL))                                        \
    X(SET_EVENT, SET_EVENT(0, NULL))                                                           \
    X(RESET_EVENT, RESET_EVENT(0, NULL))                                                       \
    X(WAIT_EVENT, WAIT_EVENT(0, 0, NULL))                                                      \
    X(GET_EVENT_ID, GET_EVENT_ID("EVT", &id_out, NULL))                                        \
    X(GET_EVENT_STATUS, GET_EVENT_STATUS(evt_id, &evt_status, NULL))                           \
    X(REPORT_APPLICATION_MESSAGE, REPORT_APPLICATION_MESSAGE(msg, 0, NULL))                    \
    X(CREATE_ERROR_HANDLER, CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)handler, 65536, NULL))   \
    X(GET_ERROR_STATUS, GET_ERROR_STATUS(&error_status, NULL))                                 \
    X(RAISE_APPLICATION_ERROR, RAISE_APPLICATION_ERROR((ERROR_CODE_TYPE)99, msg, 4, NULL))     \
    X(SET_MODULE_SCHEDULE, SET_MODULE_SCHEDULE(0, NULL))                                       \
    X(GET_MODULE_SCHEDULE_STATUS, GET_MODULE_SCHEDULE_STATUS(&schedule_status, NULL))          \
    X(GET_MODULE_SCHEDULE_ID, GET_MODULE_SCHEDULE_ID("main", &id_out, NULL))                   \
    X(bad.RETURN_CODE_read_only, GET_TIME(&t, (RETURN_CODE_TYPE *)(uintptr_t)&read_only_rc))   \
    X(bad.GET_TIME.SYSTEM_TIME, GET_TIME(BAD(SYSTEM_TIME_TYPE *), &rc))                        \
    X(bad.GET_PARTITION_STATUS.PARTITION_STATUS,                                               \
      GET_PARTITION_STATUS(BAD(PARTITION_STATUS_TYPE *), &rc))                                 \
    X(bad.CREATE_PROCESS.ATTRIBUTES, CREATE_PROCESS(BAD(PROCESS_ATTRIBUTE_TYPE *), &id_out, &rc)) \
    X(bad.GET_PROCESS_ID.PROCESS_NAME, GET_PROCESS_ID(BAD(const char *), &id_out, &rc))        \
    X(bad.READ_SAMPLING_MESSAGE.LENGTH,                                                        \
      READ_SAMPLING_MESSAGE(sp_dst, msg, BAD(MESSAGE_SIZE_TYPE *), &validity, &rc))            \
    X(bad.GET_SAMPLING_PORT_CURRENT_STATUS.read_only,                                          \
      GET_SAMPLING_PORT_CURRENT_STATUS(                                                        \
          sp_dst, (SAMPLING_PORT_CURRENT_STATUS_TYPE *)(uintptr_t)&read_only_status, &rc))     \
    X(bad.SEND_BUFFER.MESSAGE_ADDR, SEND_BUFFER(buf_id, BAD(MESSAGE_ADDR_TYPE), 4, 0, &rc))

#define FAULT_ROW(name, call) #name,
static const char *const fault_names[] = {FAULT_CASES(FAULT_ROW)};
#define N_FAULTS (sizeof fault_names / sizeof fault_names[0])

/* The victim's cases: the fault cases, then the null pointers that are ILLEGAL_REQUESTs. */
static size_t illegal_nulls[N_NULLS];
static size_t n_illegal_nulls;
static size_t fault_case;
static PROCESS_ID_TYPE victim_id;

/* The check name of case i: "rc_null.SERVICE" / "bad.*" or "null.SERVICE.PARAMETER". */
static const char *case_name(size_t i)
{
    if (i < N_FAULTS)
        return check_name("rc_null.", fault_names[i]);
    return check_name("null.", null_cases[illegal_nulls[i - N_FAULTS]].name);
}

static void run_fault_case(size_t i)
{
    RETURN_CODE_TYPE rc;
    size_t k = 0;
#define FAULT_CALL(name, call)                                                                 \
    if (k++ == i) {                                                                            \
        call;                                                                                  \
        return;                                                                                \
    }
    FAULT_CASES(FAULT_CALL)
    (void)rc;
}

/* Runs one case; it should never come back from the call. */
static void victim(void)
{
    reset_outputs();
    if (fault_case < N_FAULTS)
        run_fault_case(fault_case);
    else
        (void)null_cases[illegal_nulls[fault_case - N_FAULTS]].call();
    check_str(case_name(fault_case), "ILLEGAL_REQUEST", "returned");
}

static const char *error_name(ERROR_CODE_TYPE e)
{
    static const char *const names[] = {"DEADLINE_MISSED", "APPLICATION_ERROR", "NUMERIC_ERROR",
                                        "ILLEGAL_REQUEST", "STACK_OVERFLOW", "MEMORY_VIOLATION",
                                        "HARDWARE_FAULT", "POWER_FAIL"};
    return enum_name(names, 8, e);
}

/* The error handler: what the health monitor made of the victim's call. */
static void handler(void)
{
    RETURN_CODE_TYPE rc;
    for (;;) {
        GET_ERROR_STATUS(&error_status, &rc);
        if (rc != NO_ERROR)
            return;
        const char *got = error_status.FAILED_PROCESS_ID == victim_id
                              ? error_name(error_status.ERROR_CODE)
                              : "another_process";
        check_str(case_name(fault_case), "ILLEGAL_REQUEST", got);
        if (fault_case >= N_FAULTS)
            check_true(check_name("untouched.", null_cases[illegal_nulls[fault_case - N_FAULTS]].name),
                       outputs_untouched());
        if (fault_case == 0) {
            static const char expected[] = "APEX service given an invalid address ((nil))";
            check_true("rc_null.message", error_status.LENGTH == (int)strlen(expected) &&
                                              memcmp(error_status.MESSAGE, expected,
                                                     strlen(expected)) == 0);
        }
    }
}

/* Starts the victim on the next cases, a few per period so that the trace keeps every event
 * (each case is a process start, an HM event and a check). */
static void driver(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        size_t cases = N_FAULTS + n_illegal_nulls;
        for (int n = 0; n < 8 && fault_case < cases; n++) {
            START(victim_id, &rc); /* the victim preempts the driver at once */
            setup_rc("START victim", rc);
            fault_case++;
        }
        if (fault_case == cases)
            check_int("rc_null.cases_run", (long long)cases, (long long)fault_case);
        PERIODIC_WAIT(&rc);
        if (fault_case == cases)
            STOP_SELF();
    }
}

/* ---- set-up ---------------------------------------------------------------------------- */

static void create_objects(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_SRC", 16, SOURCE, 20 * MS, &sp_src, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_SRC", rc);
    CREATE_SAMPLING_PORT("SP_DST", 16, DESTINATION, 20 * MS, &sp_dst, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_DST", rc);
    CREATE_QUEUING_PORT("QP_SRC", 16, 4, SOURCE, FIFO, &qp_src, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_SRC", rc);
    CREATE_QUEUING_PORT("QP_DST", 16, 4, DESTINATION, FIFO, &qp_dst, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_DST", rc);
    CREATE_BUFFER("BUF", 16, 4, FIFO, &buf_id, &rc);
    setup_rc("CREATE_BUFFER", rc);
    CREATE_BLACKBOARD("BB", 16, &bb_id, &rc);
    setup_rc("CREATE_BLACKBOARD", rc);
    CREATE_SEMAPHORE("SEM", 0, 1, FIFO, &sem_id, &rc);
    setup_rc("CREATE_SEMAPHORE", rc);
    CREATE_EVENT("EVT", &evt_id, &rc);
    setup_rc("CREATE_EVENT", rc);
    attr = process_attributes("worker", worker, 5, INFINITE_TIME_VALUE, INFINITE_TIME_VALUE);
    attr_no_entry =
        process_attributes("no_entry", NULL, 5, INFINITE_TIME_VALUE, INFINITE_TIME_VALUE);
    proc_id = new_process("worker", worker, 5, INFINITE_TIME_VALUE);
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    create_objects();
    for (size_t i = 0; i < N_NULLS; i++)
        if (null_cases[i].expect == ILLEGAL)
            illegal_nulls[n_illegal_nulls++] = i;
    if (strcmp(scenario, "nulls") == 0) {
        run_null_exceptions();
    } else if (strcmp(scenario, "faults") == 0) {
        RETURN_CODE_TYPE rc;
        CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)handler, 65536, &rc);
        setup_rc("CREATE_ERROR_HANDLER", rc);
        victim_id = new_process("victim", victim, 20, INFINITE_TIME_VALUE);
        start_new_process("driver", driver, 10, 20 * MS);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    enter_normal();
    return 1;
}
