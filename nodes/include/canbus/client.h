/* SPDX-License-Identifier: Apache-2.0 */
/* C client of the virtual CAN bus (proto.h): used by a node's SKE to take part in the
 * lockstep and by the io partition to send and receive frames. No allocation, no threads, no
 * signals: it runs inside a sandboxed partition. */
#ifndef CANBUS_CLIENT_H
#define CANBUS_CLIENT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "canbus/proto.h"

#define CANBUS_OUT_RECS 256 /* records batched before a send */
#define CANBUS_IN_RECS 4096 /* frames kept until taken */

/* Return codes (negative errno values are also possible for socket errors). */
#define CANBUS_OK 0
#define CANBUS_STOPPED 1 /* the bus sent STOP: the run is over */

typedef struct {
    int fd;
    uint16_t index;      /* our client index on the bus */
    uint32_t bitrate;
    uint32_t flags;      /* CANBUS_WELCOME_* */
    int64_t quantum_ns;
    int64_t end_ns;
    int64_t granted_ns;  /* LOCKSTEP: the bus lets us run up to (excluding) this time */
    bool stopped;
    uint32_t stop_reason;
    uint64_t rejected;   /* records from the bus we could not make sense of */
    bool ticked;         /* LOCKSTEP: a first TICK has come */
    bool waiting;        /* LOCKSTEP: DONE sent, TICK not yet come */
    int64_t wait_from_ns;
    /* LOCKSTEP on a realtime bus: the latest TICK's quantum start, how late the bus released
     * it, and when it came (CLOCK_MONOTONIC): a window at emulated s starts
     * now - tick_mono_ns + tick_late_ns - (s - tick_start_ns) after its wall-clock time. */
    int64_t tick_start_ns, tick_late_ns, tick_mono_ns;
    uint64_t overflowed; /* frames dropped because nobody took them (queue full) */
    /* frames received but not yet taken by canbus_client_recv(): a ring */
    struct canbus_rec in[CANBUS_IN_RECS];
    int in_head, in_count;
    struct canbus_rec rx[CANBUS_MAX_RECS]; /* one datagram */
    struct canbus_rec out[CANBUS_OUT_RECS];
    int out_n;
} canbus_client_t;

/* Connects to the bus at `path` with the given roles and waits for its welcome. err gets one
 * line on failure. Returns CANBUS_OK, or a negative errno. */
int canbus_client_connect(canbus_client_t *c, const char *path, const char *name, uint16_t roles,
                          uint32_t node, char *err, size_t errlen);
/* Queues a data frame requested at t_ns (sent at the next flush or when the batch is full). */
int canbus_client_send(canbus_client_t *c, uint32_t id, bool extended, const uint8_t *data,
                       uint8_t len, int64_t t_ns);
/* Sends what is queued. */
int canbus_client_flush(canbus_client_t *c);
/* Takes the next frame (or ERROR record) the bus delivered, without blocking. Returns 1 with
 * *rec filled, 0 if none is waiting, -ESHUTDOWN once the bus has stopped and nothing is left,
 * or another negative errno. */
int canbus_client_recv(canbus_client_t *c, struct canbus_rec *rec);
/* LOCKSTEP: flushes, reports that everything before granted_ns is done, and waits for the
 * next TICK (frames arriving meanwhile are kept for canbus_client_recv). Returns CANBUS_OK with
 * granted_ns advanced, CANBUS_STOPPED when the run is over, or a negative errno. */
int canbus_client_done_wait(canbus_client_t *c);
/* The same, telling the bus that nothing is to be done before need_ns: the bus grants no
 * quantum ending at or before it (proto.h); 0: every quantum. A CAN client is still sent the
 * frames of the quanta it skips, without a TICK: they wait in its receive queue (which keeps
 * the newest CANBUS_IN_RECS), so a client that must see every frame asks for every quantum. */
int canbus_client_done_wait_for(canbus_client_t *c, int64_t need_ns);
/* Asks the bus to end the run for everyone. */
int canbus_client_request_stop(canbus_client_t *c);
void canbus_client_close(canbus_client_t *c);

#endif
