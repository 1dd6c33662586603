/* SPDX-License-Identifier: Apache-2.0 */
/* Intra-partition communication (ARINC 653 Part 1, 2.3.5 and 3.7): the partition's buffers,
 * blackboards, semaphores and events, and what their services share: names, message
 * storage and the queues of processes waiting on one object. Private to the APEX library. */
#ifndef APEX__INTRA_H
#define APEX__INTRA_H

#include "apex__rt.h"

/* Message storage of all the partition's buffers and blackboards together; a creation past
 * it returns INVALID_CONFIG ("insufficient storage capacity"). */
#define APEX_INTRA_STORAGE_MAX (16u * 1024u * 1024u)

typedef struct {
    NAME_TYPE name;
    MESSAGE_SIZE_TYPE max_size;
    MESSAGE_RANGE_TYPE max_nb;
    QUEUING_DISCIPLINE_TYPE discipline;
    MESSAGE_RANGE_TYPE head, count; /* ring of max_nb slots of max_size bytes */
    MESSAGE_SIZE_TYPE *lens;
    APEX_BYTE *data;
} apex_buffer_t;

typedef struct {
    NAME_TYPE name;
    MESSAGE_SIZE_TYPE max_size;
    EMPTY_INDICATOR_TYPE empty;
    MESSAGE_SIZE_TYPE len;
    APEX_BYTE *data;
} apex_blackboard_t;

typedef struct {
    NAME_TYPE name;
    SEMAPHORE_VALUE_TYPE value, max;
    QUEUING_DISCIPLINE_TYPE discipline;
} apex_semaphore_t;

typedef struct {
    NAME_TYPE name;
    EVENT_STATE_TYPE state;
} apex_event_t;

typedef struct {
    int n_buffers, n_blackboards, n_semaphores, n_events;
    size_t storage_used;
    apex_buffer_t buffers[MAX_NUMBER_OF_BUFFERS];
    apex_blackboard_t blackboards[MAX_NUMBER_OF_BLACKBOARDS];
    apex_semaphore_t semaphores[MAX_NUMBER_OF_SEMAPHORES];
    apex_event_t events[MAX_NUMBER_OF_EVENTS];
} apex_intra_t;

/* The partition's objects: like apex__rt, one per partition (the APEX has no context
 * argument). Identifiers are 1, 2, ... in creation order, per kind of object. */
extern apex_intra_t apex__intra;

/* A name as CREATE_* takes it: not null, 1 to MAX_NAME_LENGTH characters (a NAME_TYPE needs
 * no NUL). */
bool apex__name_valid(const char *name);
/* Names compare on at most MAX_NAME_LENGTH characters. */
bool apex__name_equal(const char *a, const char *b);
/* Index of the object called `name` among n objects of `stride` bytes, each starting with
 * its NAME_TYPE name (buffers, blackboards, semaphores, events), or -1. */
int apex__find_named(const void *objects, size_t stride, int n, const char *name);
void apex__name_copy(NAME_TYPE dst, const char *src);

/* Copies a message from or to memory the caller named (a bad address there is the caller's
 * illegal request, not a fault of the library). */
void apex__copy_message(void *dst, const void *src, size_t n);
/* n bytes of zeroed message storage, or NULL when the partition's storage is used up. */
void *apex__intra_alloc(size_t n);

/* The absolute time-out of a TIME_OUT parameter (INT64_MAX: none), or false when TIME_OUT is
 * out of range: below INFINITE_TIME_VALUE, or ending past the end of the clock. */
bool apex__time_out(SYSTEM_TIME_TYPE time_out, int64_t *until);

/* The waiting queue of one object, kept as the processes' own wait fields: the process to
 * serve next (FIFO: the longest waiting; PRIORITY: the highest current priority, the longest
 * waiting among equals), or NULL. */
apex_proc_t *apex__waiter_next(apex_wait_t kind, int obj, QUEUING_DISCIPLINE_TYPE discipline);
int apex__waiter_count(apex_wait_t kind, int obj);
/* Blocks the current process (apex__may_block() holds) on object obj until its wait ends or
 * `until`; returns the wait's result (TIMED_OUT on time-out). */
RETURN_CODE_TYPE apex__wait_on(apex_wait_t kind, int obj, int64_t until);
/* Ends p's wait with rc: ready, or still WAITING if it is suspended. */
void apex__wait_done(apex_proc_t *p, RETURN_CODE_TYPE rc);

#endif /* APEX__INTRA_H */
