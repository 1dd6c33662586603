/* SPDX-License-Identifier: Apache-2.0 */
/* LOCK_PREEMPTION (ARINC 653 Part 1, 3.3.2): while preemption is locked the caller keeps the
 * CPU, even against a higher-priority process made ready, and every service that would
 * make it wait returns INVALID_MODE; the lock nests up to MAX_LOCK_LEVEL. The partition
 * period is 20 ms; its window is the first 10 ms of it. */
#include "apex_check.h"

static PROCESS_ID_TYPE high_id;
static SEMAPHORE_ID_TYPE sem;
static BUFFER_ID_TYPE buf;
static BLACKBOARD_ID_TYPE board;
static EVENT_ID_TYPE ev;

static LOCK_LEVEL_TYPE partition_lock_level(void)
{
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    setup_rc("GET_PARTITION_STATUS", rc);
    return st.LOCK_LEVEL;
}

static void high(void) { trail_add("high"); }

static void low(void)
{
    RETURN_CODE_TYPE rc;
    LOCK_LEVEL_TYPE level = UNTOUCHED;
    LOCK_PREEMPTION(&level, &rc);
    check_rc("normal.lock", NO_ERROR, rc);
    check_int("normal.lock.level", 1, level);
    check_int("normal.lock.partition_status", 1, partition_lock_level());

    START(high_id, &rc);
    check_rc("normal.start_higher", NO_ERROR, rc);
    check_str("normal.start_higher.not_run", "", trail);

    /* Services that would wait. */
    SYSTEM_TIME_TYPE t0 = now_ns();
    TIMED_WAIT(1 * MS, &rc);
    check_rc("normal.timed_wait", INVALID_MODE, rc);
    TIMED_WAIT(0, &rc);
    check_rc("normal.timed_wait_zero", INVALID_MODE, rc);
    SUSPEND_SELF(1 * MS, &rc);
    check_rc("normal.suspend_self", INVALID_MODE, rc);
    WAIT_SEMAPHORE(sem, 1 * MS, &rc);
    check_rc("normal.wait_semaphore", INVALID_MODE, rc);
    WAIT_SEMAPHORE(sem, 0, &rc); /* no wait asked: the usual answer */
    check_rc("normal.wait_semaphore_no_wait", NOT_AVAILABLE, rc);
    APEX_BYTE msg[8];
    MESSAGE_SIZE_TYPE len;
    RECEIVE_BUFFER(buf, INFINITE_TIME_VALUE, msg, &len, &rc);
    check_rc("normal.receive_buffer", INVALID_MODE, rc);
    READ_BLACKBOARD(board, 1 * MS, msg, &len, &rc);
    check_rc("normal.read_blackboard", INVALID_MODE, rc);
    WAIT_EVENT(ev, 1 * MS, &rc);
    check_rc("normal.wait_event", INVALID_MODE, rc);
    check_int("normal.no_time_passed", 0, now_ns() - t0);

    for (int k = 2; k <= MAX_LOCK_LEVEL; k++) {
        LOCK_PREEMPTION(&level, &rc);
        setup_rc("LOCK_PREEMPTION", rc);
    }
    check_int("normal.nested.level", MAX_LOCK_LEVEL, level);
    level = UNTOUCHED;
    LOCK_PREEMPTION(&level, &rc);
    check_rc("normal.max_lock_level", INVALID_CONFIG, rc);
    check_int("normal.max_lock_level.untouched", UNTOUCHED, level);

    for (int k = MAX_LOCK_LEVEL; k > 1; k--) {
        UNLOCK_PREEMPTION(&level, &rc);
        setup_rc("UNLOCK_PREEMPTION", rc);
    }
    check_str("normal.level_1.not_run", "", trail);
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);
    trail_add("low");
    check_str("normal.unlocked.order", "high,low", trail);
    check_int("normal.unlocked.partition_status", 0, partition_lock_level());
}

static void cyclic(void)
{
    RETURN_CODE_TYPE rc;
    LOCK_LEVEL_TYPE level;
    LOCK_PREEMPTION(&level, &rc);
    setup_rc("LOCK_PREEMPTION", rc);
    PERIODIC_WAIT(&rc);
    check_rc("periodic.periodic_wait", INVALID_MODE, rc);
    UNLOCK_PREEMPTION(&level, &rc);
    setup_rc("UNLOCK_PREEMPTION", rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    LOCK_LEVEL_TYPE level = UNTOUCHED;
    LOCK_PREEMPTION(&level, &rc);
    check_rc("init.no_action", NO_ACTION, rc);
    check_int("init.no_action.untouched", UNTOUCHED, level);
    check_int("init.partition_status", 0, partition_lock_level());

    CREATE_SEMAPHORE("SEM", 0, 1, FIFO, &sem, &rc);
    setup_rc("CREATE_SEMAPHORE", rc);
    CREATE_BUFFER("BUF", 8, 1, FIFO, &buf, &rc);
    setup_rc("CREATE_BUFFER", rc);
    CREATE_BLACKBOARD("BOARD", 8, &board, &rc);
    setup_rc("CREATE_BLACKBOARD", rc);
    CREATE_EVENT("EV", &ev, &rc);
    setup_rc("CREATE_EVENT", rc);
    start_new_process("low", low, 5, INFINITE_TIME_VALUE);
    start_new_process("cyclic", cyclic, 3, 20 * MS);
    high_id = new_process("high", high, 20, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
