/* SPDX-License-Identifier: Apache-2.0 */
/* What every APEX conformance partition shares: each check becomes one trace line
 * "CHECK <name> expect=<value> got=<value>" (REPORT_APPLICATION_MESSAGE), which the pytest
 * beside the partition reads back from the SKE's trace. "expect=*" means the partition cannot
 * know the value (it comes from the module configuration): the pytest's table says it. */
#ifndef APEX_CHECK_H
#define APEX_CHECK_H

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "ARINC653.h"

#define MS 1000000LL /* SYSTEM_TIME_TYPE is in nanoseconds */

/* A value no APEX call returns: shows whether an output parameter was written. */
#define UNTOUCHED 0x5A5A5A5A

static inline void report(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline void report(const char *fmt, ...)
{
    char buf[MAX_ERROR_MESSAGE_SIZE + 1];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if (n > MAX_ERROR_MESSAGE_SIZE)
        n = MAX_ERROR_MESSAGE_SIZE; /* the pytest then sees a malformed line and fails */
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)buf, n, &rc);
}

/* Names as the standard spells them; an unknown value prints as its number. */
static inline const char *enum_name(const char *const *names, int count, long long v)
{
    static char other[4][24];
    static int next;
    if (v >= 0 && v < count)
        return names[v];
    char *s = other[next++ % 4];
    snprintf(s, sizeof other[0], "%lld", v);
    return s;
}

static inline const char *rc_name(RETURN_CODE_TYPE rc)
{
    static const char *const names[] = {"NO_ERROR",       "NO_ACTION",    "NOT_AVAILABLE",
                                        "INVALID_PARAM",  "INVALID_CONFIG", "INVALID_MODE",
                                        "TIMED_OUT"};
    return enum_name(names, 7, rc);
}

static inline const char *mode_name(OPERATING_MODE_TYPE m)
{
    static const char *const names[] = {"IDLE", "COLD_START", "WARM_START", "NORMAL"};
    return enum_name(names, 4, m);
}

static inline const char *start_condition_name(START_CONDITION_TYPE c)
{
    static const char *const names[] = {"NORMAL_START", "PARTITION_RESTART", "HM_MODULE_RESTART",
                                        "HM_PARTITION_RESTART"};
    return enum_name(names, 4, c);
}

static inline const char *state_name(PROCESS_STATE_TYPE s)
{
    static const char *const names[] = {"DORMANT", "READY", "RUNNING", "WAITING", "FAULTED"};
    return enum_name(names, 5, s);
}

static inline const char *validity_name(VALIDITY_TYPE v)
{
    static const char *const names[] = {"INVALID", "VALID"};
    return enum_name(names, 2, v);
}

static inline const char *direction_name(PORT_DIRECTION_TYPE d)
{
    static const char *const names[] = {"SOURCE", "DESTINATION"};
    return enum_name(names, 2, d);
}

static inline const char *deadline_name(DEADLINE_TYPE d)
{
    static const char *const names[] = {"SOFT", "HARD"};
    return enum_name(names, 2, d);
}

static inline const char *empty_indicator_name(EMPTY_INDICATOR_TYPE e)
{
    static const char *const names[] = {"EMPTY", "OCCUPIED"};
    return enum_name(names, 2, e);
}

static inline const char *updated_name(UPDATED_TYPE u)
{
    static const char *const names[] = {"EMPTY_PORT", "CONSUMED_MESSAGE", "NEW_MESSAGE"};
    return enum_name(names, 3, u);
}

static inline const char *age_name(AGE_TYPE a)
{
    static const char *const names[] = {"STALE", "FRESH"};
    return enum_name(names, 2, a);
}

static inline const char *event_state_name(EVENT_STATE_TYPE s)
{
    static const char *const names[] = {"DOWN", "UP"};
    return enum_name(names, 2, s);
}

static inline void check_str(const char *name, const char *expect, const char *got)
{
    report("CHECK %s expect=%s got=%s", name, expect, got);
}

static inline void check_rc(const char *name, RETURN_CODE_TYPE expect, RETURN_CODE_TYPE got)
{
    check_str(name, rc_name(expect), rc_name(got));
}

static inline void check_int(const char *name, long long expect, long long got)
{
    report("CHECK %s expect=%lld got=%lld", name, expect, got);
}

static inline void check_true(const char *name, bool got)
{
    check_str(name, "yes", got ? "yes" : "no");
}

/* A value fixed by the module configuration: the pytest holds the expected value. */
static inline void observe_int(const char *name, long long got)
{
    report("CHECK %s expect=* got=%lld", name, got);
}

/* A message as a check value: up to its first NUL, blanks and unprintable bytes as '.'. */
static inline const char *message_text(const APEX_BYTE *msg, MESSAGE_SIZE_TYPE len)
{
    static char text[2][40];
    static int next;
    char *s = text[next++ % 2];
    int n = 0;
    for (; n < len && n < (int)sizeof text[0] - 1 && msg[n]; n++)
        s[n] = msg[n] > ' ' && msg[n] < 127 ? (char)msg[n] : '.';
    s[n] = '\0';
    return n ? s : "(empty)";
}

/* Set-up steps are not checks, but a failed one is reported so that the pytest says why
 * checks are missing. */
static inline void setup_rc(const char *what, RETURN_CODE_TYPE rc)
{
    if (rc != NO_ERROR)
        report("SETUP %s failed: %s", what, rc_name(rc));
}

static inline PROCESS_ATTRIBUTE_TYPE process_attributes(const char *name, void (*entry)(void),
                                                        PRIORITY_TYPE priority,
                                                        SYSTEM_TIME_TYPE period,
                                                        SYSTEM_TIME_TYPE time_capacity)
{
    PROCESS_ATTRIBUTE_TYPE a;
    memset(&a, 0, sizeof a);
    a.PERIOD = period;
    a.TIME_CAPACITY = time_capacity;
    a.ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)entry;
    a.STACK_SIZE = 65536;
    a.BASE_PRIORITY = priority;
    a.DEADLINE = SOFT;
    memcpy(a.NAME, name, strnlen(name, sizeof a.NAME)); /* NAME_TYPE needs no terminator */
    return a;
}

/* Creates a process (set-up step); an aperiodic one with no time capacity unless the period
 * is finite, in which case the time capacity is the period. */
static inline PROCESS_ID_TYPE new_process(const char *name, void (*entry)(void),
                                          PRIORITY_TYPE priority, SYSTEM_TIME_TYPE period)
{
    PROCESS_ATTRIBUTE_TYPE a = process_attributes(name, entry, priority, period, period);
    PROCESS_ID_TYPE id = NULL_PROCESS_ID;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &id, &rc);
    setup_rc(name, rc);
    return id;
}

static inline PROCESS_ID_TYPE start_new_process(const char *name, void (*entry)(void),
                                                PRIORITY_TYPE priority, SYSTEM_TIME_TYPE period)
{
    PROCESS_ID_TYPE id = new_process(name, entry, priority, period);
    RETURN_CODE_TYPE rc;
    START(id, &rc);
    setup_rc("START", rc);
    return id;
}

static inline SYSTEM_TIME_TYPE now_ns(void)
{
    SYSTEM_TIME_TYPE t = -1;
    RETURN_CODE_TYPE rc;
    GET_TIME(&t, &rc);
    setup_rc("GET_TIME", rc);
    return t;
}

/* The state of a process by identifier, as its name (a set-up step). */
static inline const char *process_state_name(PROCESS_ID_TYPE id)
{
    PROCESS_STATUS_TYPE st;
    memset(&st, 0x5A, sizeof st);
    RETURN_CODE_TYPE rc;
    GET_PROCESS_STATUS(id, &st, &rc);
    setup_rc("GET_PROCESS_STATUS", rc);
    return state_name(st.PROCESS_STATE);
}

/* What happened in which order, as processes record it: "a,b,c" (trail_add, then a check
 * on trail; trail_reset starts again). */
static char trail[256] __attribute__((unused));

static inline void trail_reset(void) { trail[0] = '\0'; }

static inline void trail_add(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline void trail_add(const char *fmt, ...)
{
    size_t n = strlen(trail);
    if (n && n < sizeof trail - 1)
        trail[n++] = ',';
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(trail + n, sizeof trail - n, fmt, ap);
    va_end(ap);
}

/* Ends the initialisation process; reports if SET_PARTITION_MODE ever returns. */
static inline void enter_normal(void)
{
    RETURN_CODE_TYPE rc;
    SET_PARTITION_MODE(NORMAL, &rc);
    report("SETUP SET_PARTITION_MODE(NORMAL) returned %s", rc_name(rc));
}

#endif /* APEX_CHECK_H */
