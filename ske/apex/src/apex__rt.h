/* SPDX-License-Identifier: Apache-2.0 */
/* The APEX run-time inside one partition: its view of the control block, its ARINC
 * processes and their deterministic scheduler. Private to the APEX library. */
#ifndef APEX__RT_H
#define APEX__RT_H

#include <signal.h>
#include <string.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <ucontext.h>

#include "ARINC653.h"
#include "ske_abi.h"

typedef enum {
    WAIT_NONE,
    WAIT_DELAY, /* TIMED_WAIT */
    WAIT_PERIOD, /* PERIODIC_WAIT, or a periodic process waiting for its first release */
    WAIT_QRECV, /* RECEIVE_QUEUING_MESSAGE on an empty queue */
    WAIT_QSEND, /* SEND_QUEUING_MESSAGE on a full queue */
    WAIT_SUSPEND, /* SUSPEND_SELF */
    WAIT_BUF_SEND, /* SEND_BUFFER on a full buffer */
    WAIT_BUF_RECV, /* RECEIVE_BUFFER on an empty buffer */
    WAIT_BB_READ, /* READ_BLACKBOARD on an empty blackboard */
    WAIT_SEM, /* WAIT_SEMAPHORE at value 0 */
    WAIT_EVT, /* WAIT_EVENT on an event that is DOWN */
} apex_wait_t;

typedef struct {
    PROCESS_ATTRIBUTE_TYPE attr;
    PROCESS_ID_TYPE id;
    PROCESS_STATE_TYPE state;
    PRIORITY_TYPE cur_prio;
    int64_t deadline_time; /* INFINITE_TIME_VALUE: none */
    int64_t next_release; /* periodic: the next release point */
    int64_t wake_at; /* INT64_MAX: no time-out */
    apex_wait_t wait;
    int wait_port; /* port index for queuing waits */
    uint64_t wait_order; /* FIFO order among processes waiting on the same port */
    RETURN_CODE_TYPE wait_rc;
    uint64_t ready_order; /* FIFO order within a priority */
    bool start_pending; /* START called before NORMAL mode */
    int64_t start_delay; /* DELAYED_START called before NORMAL mode */
    bool suspended; /* SUSPENDed by another process: WAITING until RESUME, its own wait or not */
    int wait_obj; /* buffer, blackboard, semaphore or event index of those waits */
    /* Queuing wait arguments. */
    const APEX_BYTE *q_msg;
    MESSAGE_SIZE_TYPE q_len;
    APEX_BYTE *q_buf;
    MESSAGE_SIZE_TYPE *q_len_out;
    bool deadline_missed; /* reported for the current release already */
    ucontext_t ctx;
    void *stack_map;
    size_t stack_map_size;
} apex_proc_t;

/* One error waiting for the error handler (GET_ERROR_STATUS). */
typedef struct {
    ERROR_CODE_TYPE code;
    PROCESS_ID_TYPE failed;
    SYSTEM_ADDRESS_TYPE address;
    MESSAGE_SIZE_TYPE len;
    APEX_BYTE message[MAX_ERROR_MESSAGE_SIZE];
} apex_error_t;

#define APEX_ERROR_QUEUE 32

typedef struct {
    bool created;
    void *mem;
    size_t map_size;
    QUEUING_DISCIPLINE_TYPE discipline;
    VALIDITY_TYPE last_validity;
    bool validity_known;
    uint32_t read_seq; /* sampling: sequence number of the last message read here, 0: none */
    /* An injected output fault (fault.c): what WRITE_SAMPLING_MESSAGE does instead. */
    uint8_t out_fault; /* APEX_OUT_* */
    APEX_BYTE *fault_buf; /* corrupt: the copy it corrupts, max_size bytes */
} apex_port_t;

enum { APEX_OUT_NORMAL = 0, APEX_OUT_CORRUPT = 1, APEX_OUT_STUCK = 2 };

typedef struct {
    ske_ctl_t *ctl;
    bool realtime;
    uint32_t seen_grant;
    int64_t now; /* partition time, ns */
    int64_t win_start, win_end;
    OPERATING_MODE_TYPE mode;
    int n_procs;
    apex_proc_t procs[MAX_NUMBER_OF_PROCESSES];
    apex_proc_t *current; /* NULL while the initialisation (main) process runs */
    ucontext_t sched_ctx;
    uint64_t order;
    LOCK_LEVEL_TYPE lock_level; /* LOCK_PREEMPTION depth: while > 0 only lock_owner runs */
    apex_proc_t *lock_owner;
    apex_port_t ports[SKE_MAX_PORTS];
    /* Health monitoring: the error handler (above every process's priority) and the errors
     * it has yet to read. */
    bool has_eh;
    apex_proc_t eh;
    apex_error_t errors[APEX_ERROR_QUEUE];
    uint32_t err_head, err_tail;
    uint32_t errors_lost;
    /* Injected faults (fault.c): the partition time from which the hook has work to do at a
     * service call; INT64_MAX when none. */
    int64_t fault_due;
} apex_rt_t;

/* t + d for d ≥ 0, or false when the sum passes the end of the 64-bit clock (the standard's
 * "out of range ... e.g. calculation causes overflow of underlying clock"). */
static inline bool apex__time_add(int64_t t, int64_t d, int64_t *out)
{
    if (d > 0 && t > INT64_MAX - d)
        return false;
    *out = t + d;
    return true;
}

/* The partition's one run-time: the APEX interface has no context argument. */
extern apex_rt_t apex__rt;

/* Brings the partition's view of time and window up to date; called at every service. */
void apex__sync(void);
/* Partition time now. */
int64_t apex__now(void);
/* Takes a new grant if the SKE gave one (after an overrun) and, in real time, reads the
 * clock: the time of apex__sync without its scheduling. */
void apex__refresh_time(void);
/* Sends a trace event to the SKE. */
void apex__event(uint32_t kind, int32_t a, int32_t b, const void *text, uint32_t len);
/* Room left in the event ring for this window. */
uint32_t apex__event_room(void);
/* Blocks the current process (its wait fields set by the caller) until the scheduler makes
 * it ready again; returns its wait result. */
RETURN_CODE_TYPE apex__block(apex_proc_t *p);
/* Lets a higher-priority ready process run now (preemption at a service call). */
void apex__preempt_check(void);
/* Marks a process ready, at the back of its priority's FIFO. */
void apex__make_ready(apex_proc_t *p);
/* Releases a process DELAYED_STARTed before NORMAL mode, as NORMAL mode begins at `now`
 * with the partition's first period start at `first_release` (process.c). */
void apex__release_delayed(apex_proc_t *p, int64_t now, int64_t first_release);
/* Enters NORMAL mode from the initialisation process: never returns. */
void apex__enter_normal(void) __attribute__((noreturn));
/* Hands the CPU back to the SKE until the next window. */
void apex__yield_cpu(void);
/* The first partition period start at or after t. */
int64_t apex__next_period_start(int64_t t);
/* Index of a created port of the given kind from an APEX identifier, or -1. */
int apex__port_index(APEX_INTEGER id, uint32_t kind);
/* Index of a configured port by APEX name (NAME_TYPE need not be NUL-terminated). */
int apex__port_by_name(const char *name, uint32_t kind);
/* Maps every port of the partition and closes their descriptors (at attach). */
void apex__ports_attach(void);
/* Marks configured port k created; false if it could not be mapped at attach. */
bool apex__port_map(int k);
/* Whether the current process may wait: not the initialisation process, not the error
 * handler, not while preemption is locked (ARINC 653 Part 1: blocking services return
 * INVALID_MODE for all three). */
bool apex__may_block(void);
/* Brackets a copy from or to memory the caller named: a fault inside is an APEX service
 * given an invalid address, an ILLEGAL_REQUEST rather than a MEMORY_VIOLATION. */
extern volatile sig_atomic_t apex__in_user_copy; /* read by the fault handler (hm.c) */
static inline void apex__user_copy(bool on) { apex__in_user_copy = on; }
/* The caller gave an address the service cannot use where it can return no error code (a
 * null or unwritable RETURN_CODE), or one that faulted: an ILLEGAL_REQUEST for the health
 * monitor, the same path as a fault inside apex__user_copy. The caller does not go on. */
_Noreturn void apex__invalid_address(const void *address);

/* The addresses a caller gives a service (apex__user.h, inline: every service call checks
 * some). Every service starts with apex__enter: it brings time up to date and checks
 * RETURN_CODE. The others check an address: a null one, or one that cannot be read (or
 * written, for an output), is an ILLEGAL_REQUEST, as when a message copy faults. A check
 * that fails does not return, so a service needs no path for it. apex__check_addr checks a
 * message address for null only: its copy is bracketed by apex__user_copy. */
#include "apex__user.h"

/* Sampling ports (sampling.c), shared with the Part 2 extensions (sampling_ext.c). VALID when
 * a message stamped `stamp` is at most port k's refresh period old now. */
VALIDITY_TYPE apex__sampling_validity(int k, int64_t stamp);
/* Copies destination port k's latest message into the caller's buffer; false when none was
 * ever written. The message counts as read (READ_UPDATED_SAMPLING_MESSAGE), its validity is
 * the port's LAST_MSG_VALIDITY, and a change of validity goes to the trace. */
bool apex__sampling_take(int k, APEX_BYTE *buf, MESSAGE_SIZE_TYPE *len, int64_t *stamp);

/* Health monitoring hooks of the run-time (hm.c). */
void apex__hm_init(void);
void apex__hm_check_deadlines(void);
/* Completes port waits whose condition now holds (scheduler side). */
void apex__service_port_waiters(void);
/* Injected faults (fault.c): arms them from the control block at attach; the hook run at a
 * service call once rt->fault_due has come; and the write of a sampling port under an
 * output fault (true: done, false: write normally). */
void apex__faults_init(void);
#ifdef IMA_COVERAGE
/* Coverage builds only (coverage.c): writes the gcov counters on SKE_COVERAGE_SIGNAL. */
void apex__coverage_init(void);
#endif
void apex__fault_point(void);
bool apex__fault_write(int k, const APEX_BYTE *msg, MESSAGE_SIZE_TYPE len);
/* Messages waiting in a queuing port, and whether any process waits on it. */
uint32_t apex__queue_count(int k);
int apex__queue_waiters(int k);

#endif /* APEX__RT_H */
