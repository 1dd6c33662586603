/* SPDX-License-Identifier: Apache-2.0 */
/* Health monitoring inside a partition (ARINC 653 Part 1, 2.4 and 3.10): faults caught as
 * signals, process deadlines, the error handler process, and the services
 * CREATE_ERROR_HANDLER, GET_ERROR_STATUS, RAISE_APPLICATION_ERROR. Errors at partition or
 * module level are posted to the SKE, which acts on them when the partition gives the CPU
 * back. */
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <ucontext.h>
#include <unistd.h>

#include "apex__rt.h"
#include "hm/hm.h"

#define ALT_STACK_SIZE (64u * 1024u)
#define GUARD_SIZE 4096u /* as process.c maps it under each stack */
#define EH_STACK_MIN (64u * 1024u)
#define EH_STACK_MAX (64u * 1024u * 1024u)
#define EH_PRIORITY (MAX_PRIORITY_VALUE + 1) /* above every process */

volatile sig_atomic_t apex__in_user_copy;

/* The lowest address of the initialisation process's stack (the main thread's). */
static uintptr_t main_stack_lo;

static hm_state_t current_state(void)
{
    const apex_rt_t *rt = &apex__rt;
    if (rt->mode != NORMAL)
        return HM_STATE_PARTITION_INIT;
    if (rt->current == &rt->eh)
        return HM_STATE_ERROR_HANDLER;
    return HM_STATE_PROCESS;
}

/* The health monitor's decision, from the partition's copy of the System HM table: only
 * whether the error handler takes the error matters here, the SKE decides the rest. */
static hm_decision_t decide(const apex_proc_t *failed, hm_state_t st, hm_error_t err, bool fatal)
{
    const apex_rt_t *rt = &apex__rt;
    _Static_assert(sizeof rt->ctl->hm_level == sizeof ((hm_system_table_t *)0)->level,
                   "the control block's HM table has the health monitor's shape");
    hm_system_table_t sys;
    memcpy(sys.level, rt->ctl->hm_level, sizeof sys.level);
    memset(sys.module_action, HM_ACT_IGNORE, sizeof sys.module_action);
    hm_origin_t origin = !failed             ? HM_ORIGIN_PARTITION
                         : failed == &rt->eh ? HM_ORIGIN_ERROR_HANDLER
                                             : HM_ORIGIN_PROCESS;
    return hm_decide(&sys, NULL, st, err, origin, rt->has_eh, fatal && !failed);
}

/* ---- the error handler -------------------------------------------------------------- */

static void eh_trampoline(void)
{
    ((void (*)(void))apex__rt.eh.attr.ENTRY_POINT)();
    STOP_SELF(); /* returning from the handler ends it until the next error */
}

/* Makes the error handler ready, from its entry point if it is not already running. */
static void eh_activate(void)
{
    apex_rt_t *rt = &apex__rt;
    apex_proc_t *eh = &rt->eh;
    if (eh->state != DORMANT)
        return; /* ready or running: it will read the new error with GET_ERROR_STATUS */
    getcontext(&eh->ctx);
    sigemptyset(&eh->ctx.uc_sigmask); /* we may be in a fault handler, with its signal blocked */
    eh->ctx.uc_stack.ss_sp = (char *)eh->stack_map + GUARD_SIZE;
    eh->ctx.uc_stack.ss_size = eh->stack_map_size - GUARD_SIZE;
    eh->ctx.uc_link = NULL;
    makecontext(&eh->ctx, eh_trampoline, 0);
    apex__make_ready(eh);
}

static void enqueue(hm_error_t err, PROCESS_ID_TYPE failed, uintptr_t address, const char *msg,
                    size_t len)
{
    apex_rt_t *rt = &apex__rt;
    if (rt->err_head - rt->err_tail >= APEX_ERROR_QUEUE) {
        rt->errors_lost++; /* the oldest are kept: they explain what followed */
        return;
    }
    apex_error_t *e = &rt->errors[rt->err_head++ % APEX_ERROR_QUEUE];
    e->code = (ERROR_CODE_TYPE)hm_apex_error_code(err);
    e->failed = failed;
    e->address = (SYSTEM_ADDRESS_TYPE)address;
    e->len = (MESSAGE_SIZE_TYPE)(len < MAX_ERROR_MESSAGE_SIZE ? len : MAX_ERROR_MESSAGE_SIZE);
    memcpy(e->message, msg, (size_t)e->len);
}

/* The trace record of a process-level error: process name, then the message. */
static void trace_process_level(hm_error_t err, const apex_proc_t *p, const char *msg, size_t len)
{
    char text[SKE_EVENT_TEXT];
    memset(text, 0, SKE_NAME_MAX);
    memcpy(text, p->attr.NAME, strnlen(p->attr.NAME, MAX_NAME_LENGTH));
    size_t n = len < SKE_EVENT_TEXT - SKE_NAME_MAX ? len : SKE_EVENT_TEXT - SKE_NAME_MAX;
    memcpy(text + SKE_NAME_MAX, msg, n);
    apex__event(SKE_EV_HM, (int32_t)err, p->id, text, (uint32_t)(SKE_NAME_MAX + n));
}

/* Posts an error for the SKE and waits until it has decided (it finds the level in its own
 * copy of the tables); if it idles or restarts the partition, this process never runs again. */
static void post_and_wait(hm_error_t err, hm_state_t st, const apex_proc_t *p,
                          const char *msg, size_t len, bool fatal)
{
    ske_ctl_t *c = apex__rt.ctl;
    c->hm_error = err;
    c->hm_state = st;
    c->hm_fatal = fatal;
    c->hm_process = p ? p->id : 0;
    memset(c->hm_process_name, 0, sizeof c->hm_process_name);
    if (p)
        memcpy(c->hm_process_name, p->attr.NAME, strnlen(p->attr.NAME, MAX_NAME_LENGTH));
    c->hm_len = (uint32_t)(len < SKE_EVENT_TEXT ? len : SKE_EVENT_TEXT);
    memcpy(c->hm_message, msg, c->hm_len);
    c->hm_t_ns = apex__now();
    uint32_t seq = atomic_load(&c->hm_seq) + 1;
    atomic_store(&c->hm_seq, seq);
    while (atomic_load(&c->hm_ack) != seq)
        apex__yield_cpu();
}

/* An error of `failed` (NULL: the initialisation process) detected while in state `st`, after
 * which it goes on: a missed deadline, an application error. */
static void raise_error(apex_proc_t *failed, hm_state_t st, hm_error_t err, const char *msg,
                        size_t len)
{
    if (decide(failed, st, err, false).level == HM_LEVEL_PROCESS) {
        /* Process level: the error handler takes it (ARINC 653 Part 1, 2.4.2.3). */
        enqueue(err, failed->id, 0, msg, len);
        trace_process_level(err, failed, msg, len);
        eh_activate();
        if (apex__rt.current == failed)
            apex__preempt_check(); /* the handler runs before the failed process goes on */
        return;
    }
    /* Partition or module level: the SKE decides again from its own copy of the tables. */
    post_and_wait(err, st, failed, msg, len, false);
}

/* An error after which the current context cannot go on (a fault signal, an address a
 * service cannot use), detected in state `st`: it stops for good. At process level the error
 * handler takes the error and may START the process again; otherwise the SKE decides. */
static _Noreturn void fail_current(hm_state_t st, hm_error_t err, const char *msg, size_t len,
                                   uintptr_t address)
{
    apex_rt_t *rt = &apex__rt;
    apex_proc_t *failed = rt->current;
    bool process_level = decide(failed, st, err, true).level == HM_LEVEL_PROCESS;
    if (process_level) {
        enqueue(err, failed->id, address, msg, len);
        trace_process_level(err, failed, msg, len);
        eh_activate();
    } else {
        post_and_wait(err, st, failed, msg, len, !failed);
    }
    if (failed) {
        failed->state = DORMANT;
        failed->wait = WAIT_NONE;
        failed->wake_at = INT64_MAX;
        if (process_level || rt->mode == NORMAL) {
            rt->current = NULL;
            setcontext(&rt->sched_ctx);
        }
    }
    for (;;)
        apex__yield_cpu(); /* the initialisation or the scheduler itself failed */
}

/* ---- faults ------------------------------------------------------------------------- */

static bool in_guard(uintptr_t a, const apex_proc_t *p)
{
    uintptr_t lo = (uintptr_t)p->stack_map;
    return p->stack_map && a >= lo && a < lo + GUARD_SIZE;
}

/* A stack overflow is a fault in a stack's guard page, or just below the initialisation
 * process's stack. */
static bool is_stack_overflow(uintptr_t a)
{
    const apex_rt_t *rt = &apex__rt;
    for (int i = 0; i < rt->n_procs; i++)
        if (in_guard(a, &rt->procs[i]))
            return true;
    if (rt->has_eh && in_guard(a, &rt->eh))
        return true;
    return main_stack_lo && a < main_stack_lo && a >= main_stack_lo - 16 * GUARD_SIZE;
}

static void on_fault(int sig, siginfo_t *si, void *uctx)
{
    (void)uctx;
    uintptr_t addr = (uintptr_t)si->si_addr;
    hm_error_t err;
    char msg[96];
    int n;
    switch (sig) {
    case SIGFPE:
        err = HM_ERR_NUMERIC_ERROR;
        n = snprintf(msg, sizeof msg, "SIGFPE (code %d) at %p", si->si_code, si->si_addr);
        break;
    case SIGILL:
        err = HM_ERR_HARDWARE_FAULT;
        n = snprintf(msg, sizeof msg, "SIGILL (code %d) at %p", si->si_code, si->si_addr);
        break;
    case SIGSYS:
        err = HM_ERR_ILLEGAL_REQUEST;
        n = snprintf(msg, sizeof msg, "system call %d denied", si->si_syscall);
        break;
    default: /* SIGSEGV, SIGBUS */
        if (apex__in_user_copy) {
            apex__in_user_copy = 0;
            err = HM_ERR_ILLEGAL_REQUEST;
            n = snprintf(msg, sizeof msg, "APEX service given an invalid address (%p)", si->si_addr);
            break;
        }
        err = is_stack_overflow(addr) ? HM_ERR_STACK_OVERFLOW : HM_ERR_MEMORY_VIOLATION;
        n = snprintf(msg, sizeof msg, "SIG%s at address %p", sig == SIGBUS ? "BUS" : "SEGV",
                     si->si_addr);
        break;
    }
    fail_current(current_state(), err, msg, n > 0 ? (size_t)n : 0, addr);
}

_Noreturn void apex__invalid_address(const void *address)
{
    char msg[96];
    int n = snprintf(msg, sizeof msg, "APEX service given an invalid address (%p)", address);
    fail_current(current_state(), HM_ERR_ILLEGAL_REQUEST, msg, n > 0 ? (size_t)n : 0,
                 (uintptr_t)address);
}

void apex__hm_init(void)
{
    /* Faults are handled on a stack of their own, so that a stack overflow can be. */
    void *alt = mmap(NULL, ALT_STACK_SIZE, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (alt != MAP_FAILED) {
        stack_t ss = {.ss_sp = alt, .ss_size = ALT_STACK_SIZE};
        sigaltstack(&ss, NULL);
    }
    struct sigaction sa = {.sa_sigaction = on_fault, .sa_flags = SA_SIGINFO | SA_ONSTACK};
    sigemptyset(&sa.sa_mask);
    static const int sigs[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGSYS};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
        sigaction(sigs[i], &sa, NULL);
    pthread_attr_t attr;
    if (pthread_getattr_np(pthread_self(), &attr) == 0) {
        void *lo;
        size_t size;
        if (pthread_attr_getstack(&attr, &lo, &size) == 0)
            main_stack_lo = (uintptr_t)lo;
        pthread_attr_destroy(&attr);
    }
}

/* ---- deadlines ---------------------------------------------------------------------- */

/* A process that has not finished its work by its deadline time: DEADLINE_MISSED, once per
 * release (ARINC 653 Part 1, 2.3.2.3). A periodic process waiting for its next release has
 * finished; one waiting for anything else has not. */
void apex__hm_check_deadlines(void)
{
    apex_rt_t *rt = &apex__rt;
    if (rt->mode != NORMAL)
        return;
    int64_t now = apex__now();
    for (int i = 0; i < rt->n_procs; i++) {
        apex_proc_t *p = &rt->procs[i];
        /* A deadline is the time by which the work is done: still at it then, it missed. */
        if (p->deadline_missed || p->deadline_time == INFINITE_TIME_VALUE || p->deadline_time > now)
            continue;
        if (p->state == DORMANT || (p->state == WAITING && p->wait == WAIT_PERIOD))
            continue;
        p->deadline_missed = true;
        char msg[96];
        int n = snprintf(msg, sizeof msg, "deadline %lld ns passed at %lld ns",
                         (long long)p->deadline_time, (long long)now);
        raise_error(p, HM_STATE_PROCESS, HM_ERR_DEADLINE_MISSED, msg, (size_t)n);
    }
}

/* ---- services ----------------------------------------------------------------------- */

void CREATE_ERROR_HANDLER(
    /*in */ SYSTEM_ADDRESS_TYPE ENTRY_POINT,
    /*in */ STACK_SIZE_TYPE STACK_SIZE,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    if (rt->has_eh) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    if (!ENTRY_POINT || STACK_SIZE == 0 || STACK_SIZE > EH_STACK_MAX) {
        *RETURN_CODE = INVALID_CONFIG; /* stack size out of range */
        return;
    }
    if (rt->mode == NORMAL) {
        *RETURN_CODE = INVALID_MODE;
        return;
    }
    size_t stack = STACK_SIZE < EH_STACK_MIN ? EH_STACK_MIN : STACK_SIZE;
    stack = (stack + 4095u) & ~(size_t)4095u;
    size_t map = stack + GUARD_SIZE;
    void *mem = mmap(NULL, map, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_STACK, -1, 0);
    if (mem == MAP_FAILED) {
        *RETURN_CODE = INVALID_CONFIG; /* insufficient storage */
        return;
    }
    mprotect(mem, GUARD_SIZE, PROT_NONE);
    apex_proc_t *eh = &rt->eh;
    memset(eh, 0, sizeof *eh);
    eh->attr.ENTRY_POINT = ENTRY_POINT;
    eh->attr.STACK_SIZE = STACK_SIZE;
    eh->attr.BASE_PRIORITY = EH_PRIORITY;
    eh->attr.PERIOD = INFINITE_TIME_VALUE;
    eh->attr.TIME_CAPACITY = INFINITE_TIME_VALUE;
    memcpy(eh->attr.NAME, "ERROR_HANDLER", sizeof "ERROR_HANDLER");
    eh->id = 0;
    eh->state = DORMANT;
    eh->cur_prio = EH_PRIORITY;
    eh->deadline_time = INFINITE_TIME_VALUE;
    eh->wake_at = INT64_MAX;
    eh->stack_map = mem;
    eh->stack_map_size = map;
    rt->has_eh = true;
    *RETURN_CODE = NO_ERROR;
}

void GET_ERROR_STATUS(
    /*out*/ ERROR_STATUS_TYPE *ERROR_STATUS,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    apex__check_out(ERROR_STATUS, sizeof *ERROR_STATUS);
    if (!rt->has_eh || rt->current != &rt->eh) {
        *RETURN_CODE = INVALID_CONFIG; /* only the error handler may ask */
        return;
    }
    if (rt->err_head == rt->err_tail) {
        *RETURN_CODE = NO_ACTION;
        return;
    }
    const apex_error_t *e = &rt->errors[rt->err_tail++ % APEX_ERROR_QUEUE];
    ERROR_STATUS->ERROR_CODE = e->code;
    ERROR_STATUS->LENGTH = e->len;
    ERROR_STATUS->FAILED_PROCESS_ID = e->failed;
    ERROR_STATUS->FAILED_ADDRESS = e->address;
    memcpy(ERROR_STATUS->MESSAGE, e->message, (size_t)e->len);
    *RETURN_CODE = NO_ERROR;
}

void RAISE_APPLICATION_ERROR(
    /*in */ ERROR_CODE_TYPE ERROR_CODE,
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ ERROR_MESSAGE_SIZE_TYPE LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex_rt_t *rt = &apex__rt;
    apex__enter(RETURN_CODE);
    if (LENGTH < 0 || LENGTH > MAX_ERROR_MESSAGE_SIZE) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (LENGTH > 0)
        apex__check_in(MESSAGE_ADDR, (size_t)LENGTH);
    if (ERROR_CODE != APPLICATION_ERROR) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    /* The caller is told NO_ERROR once the error is dealt with: if the error handler takes
     * it, that is when this process runs again. */
    *RETURN_CODE = NO_ERROR;
    raise_error(rt->current, current_state(), HM_ERR_APPLICATION_ERROR, (const char *)MESSAGE_ADDR,
                (size_t)LENGTH);
}
