/* SPDX-License-Identifier: Apache-2.0 */
/* The bus process's private interface between its files: connections (bus_conn.c), protocol
 * handling (bus_proto.c), the quantum loop (bus_loop.c), trace (bus_trace.c), set-up and
 * statistics (bus_server.c). Each is passed the bus, none keeps state of its own. */
#ifndef CANBUS__SERVER_H
#define CANBUS__SERVER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "canbus__bus.h"

#define RXBUF_SIZE (CANBUS_MAX_RECS * sizeof(struct canbus_rec) + 64)
#define RX_BATCH 8 /* datagrams read by one call (canbus__read_client()); rxbuf holds as many */

/* ---- bus_trace.c: trace lines and messages ---------------------------------------------- */

/* A line on stderr, unless quiet. */
void canbus__info(const canbus_bus_t *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* Starts a trace line: every line starts alike. */
void canbus__line_head(canbus_sbuf_t *s, int64_t t_ns, const char *kind);
/* Writes the buffer to the trace (a failed write is remembered) and empties it. */
void canbus__trace_write(canbus_bus_t *b, canbus_sbuf_t *s);
const char *canbus__stop_name(uint32_t reason);
/* The name of a fault-confinement state (active, passive, bus_off). */
const char *canbus__state_name(unsigned st);
/* ,"KEY":NAME,"client":INDEX for a client index. */
void canbus__sb_client(canbus_bus_t *b, canbus_sbuf_t *s, const char *key, uint8_t index);
void canbus__staged_reject(canbus_bus_t *b, canbus_client_t *c, const char *reason);
/* The trace lines of the read phase, in client order. */
void canbus__flush_staged(canbus_bus_t *b);
/* A `fault` line (fid, class, target, state, detail) of the bus's fault i into s. */
void canbus__sb_fault(canbus_bus_t *b, canbus_sbuf_t *s, int64_t t_ns, size_t i, uint8_t state,
                      const char *detail);
/* The wire's events since the last call, into the trace. */
int canbus__write_wire_trace(canbus_bus_t *b);

/* ---- bus_conn.c: connections ------------------------------------------------------------ */

int64_t canbus__wall_ns(void);
void canbus__client_leave(canbus_bus_t *b, canbus_client_t *c, const char *reason);
/* Bytes queued for the client. */
size_t canbus__queued(const canbus_client_t *c);
/* Sends what is queued for the client, as far as its socket takes it. */
void canbus__flush_queue(canbus_bus_t *b, canbus_client_t *c);
void canbus__client_send(canbus_bus_t *b, canbus_client_t *c, const void *p, size_t n);
void canbus__send_stop(canbus_bus_t *b, canbus_client_t *c, uint32_t reason);
/* One poll over everything, waiting at most timeout_ns (< 0: no limit). */
void canbus__service(canbus_bus_t *b, int64_t timeout_ns);
/* Accepts and reads everything pending, without waiting. */
void canbus__read_all(canbus_bus_t *b);
/* Reads what one client has sent, without waiting. */
void canbus__read_client(canbus_bus_t *b, canbus_client_t *c);

/* ---- bus_proto.c: protocol handling ----------------------------------------------------- */

/* LOCKSTEP clients taking part in this quantum or the next. */
int canbus__members_count(const canbus_bus_t *b);
/* A client's datagram that breaks the protocol: counted, traced, and the client dropped when
 * it does so too often. */
void canbus__reject(canbus_bus_t *b, canbus_client_t *c, const char *reason);
/* The first datagram of a connection. */
void canbus__handle_hello(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n);
/* A datagram of records from a welcomed client. */
void canbus__handle_records(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n);

/* ---- bus_admit.c: who may join, what a client may send ----------------------------------- */

/* NULL: the hello is admitted (c->listen_only set for an undeclared client); else why it is
 * refused, and with which STOP reason. */
const char *canbus__admit(canbus_bus_t *b, canbus_client_t *c, const struct canbus_hello *h,
                          uint32_t *stop_reason);
/* PROCESS: the process of `node` (its declared clients: it or its children); false if no
 * client of that node is declared. */
bool canbus__declare_process(canbus_bus_t *b, uint32_t node, pid_t pid);
/* A refused hello, into the statistics' `refusals` list. */
void canbus__note_refused_hello(canbus_bus_t *b, const canbus_client_t *c, const char *why);
/* A record the client may not send: not acted on, counted by type, rejected. */
void canbus__refuse_record(canbus_bus_t *b, canbus_client_t *c, uint8_t type, const char *why);
/* The statistics' `refusals` array: refused hellos, then every client that sent records it
 * may not. */
void canbus__sb_refused(canbus_bus_t *b, canbus_sbuf_t *s);

/* ---- bus_control.c: the launcher's control channel ------------------------------------ */

/* Takes --control-fd into the live list; a negative errno if it is not a SEQPACKET socket. */
int canbus__control_open(canbus_bus_t *b);
/* A datagram on the control channel: STOP and FAULT records. */
void canbus__handle_control(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n);
/* Ends the run at the request of c (a LOCKSTEP client or the launcher). */
void canbus__stop_by(canbus_bus_t *b, canbus_client_t *c);

#endif /* CANBUS__SERVER_H */
