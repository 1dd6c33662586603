/* SPDX-License-Identifier: Apache-2.0 */
/* The virtual CAN bus wire protocol: what a client and the bus process (ima-canbus) exchange
 * over one Unix-domain SOCK_SEQPACKET connection. Every participant of a flight speaks it: the
 * world, each node's SKE (time only), each node's io partition (frames only) and tools such as
 * the python-can interface. The Python mirror is python/ima/canbus/proto.py; a test checks
 * that both agree on every size and constant.
 *
 * Connection
 *   1. The client sends one struct canbus_hello datagram.
 *   2. The bus answers with one struct canbus_welcome datagram, or with a single STOP record
 *      whose `id` is a CANBUS_STOP_* reason, and closes. A bus started by the launcher knows
 *      the clients of the run (ima-canbus --client): a hello naming one of them must ask for
 *      its roles and node; a name already connected is refused (STOP_REFUSED); a client of
 *      another name is welcomed LISTEN-ONLY (welcome.flags): it receives the frames, and
 *      every record it sends is refused. Names are 1..31 printable ASCII characters and a NUL.
 *   3. From then on every datagram, either way, is an array of 32-byte struct canbus_rec
 *      (at most CANBUS_MAX_RECS of them). A datagram whose size is not a multiple of 32, a
 *      record of unknown type or a frame with len > 8 is rejected and counted by the bus.
 *
 * Lockstep (emulated time; deterministic)
 *   Bus time is cut into quanta of Q ns (welcome.quantum_ns). For the quantum [T, T+Q):
 *   a. The bus sends every CAN client, in one datagram, the FRAME records of all frames whose
 *      transmission ended at or before T and that it has not delivered yet, in the order they
 *      were on the bus (t_ns = end of frame, aux = start of frame, src = sender's client
 *      index); then it sends TICK(t_ns = T+Q, aux = T) to every LOCKSTEP client that has not
 *      said it has nothing to do in [T, T+Q) (below).
 *   b. A LOCKSTEP client advances its own time to T+Q (exclusive): it may send FRAME records
 *      stamped with their request times (any time >= T; frames stamped past T+Q simply wait
 *      for their time), then it sends DONE(t_ns = T+Q). Frames and the DONE may share a
 *      datagram (frames first).
 *   c. When every LOCKSTEP client has sent DONE(T+Q), the bus reads every socket a poll shows
 *      readable, dry (a client that wrote a frame before its node's DONE was sent has it
 *      queued by then: AF_UNIX queues at send time), then simulates the wire through
 *      [T, T+Q): whenever the bus is
 *      idle, the pending frames requested at or before that instant arbitrate and the lowest
 *      identifier wins (ties: lower client index, then request order); a frame occupies the
 *      wire for its worst-case-stuffed length (canbus_frame_bits() below).
 *   So a frame sent in one quantum reaches its receivers at the start of a later quantum, at
 *   an instant that depends only on the inputs: same inputs, same trace.
 *   Frames from clients without the LOCKSTEP role (tools) are stamped by the bus with the
 *   start of the quantum in which it reads them.
 *   A node whose SKE is a LOCKSTEP client runs a window starting at s only once it holds a
 *   TICK with t_ns > s; before a window starting at or after the granted time it sends DONE
 *   with aux = s: the bus grants it no quantum [T, T+Q) with T+Q <= s (it counts as done
 *   in those), so a node is woken only for the quanta in which a window of it starts (of
 *   a system partition: the others run ahead, ske/src/supervisor.c). The world does the
 *   same with its next task's instant. A CAN client granted no quantum still
 *   gets the frames delivered at its start, before its next TICK (the first quantum start at
 *   or after a frame's end on the wire is the one that delivered it). The quanta, the
 *   frames' delivery and the wire are the same for every client either way.
 *
 * Real time (--realtime on the bus): the same exchange, but the bus sends the TICK for [T, T+Q)
 * no earlier than epoch + T on CLOCK_MONOTONIC.
 *
 * End: at welcome.end_ns (or when a LOCKSTEP client sends STOP, e.g. the world after a crash,
 * or the launcher does on its control channel) the bus sends STOP to every client and closes.
 * A LOCKSTEP client that disconnects leaves the lockstep (a dead node does not stop the others).
 *
 * Control channel (ima-canbus --control-fd N): the launcher's end of a socketpair the bus
 * inherits, never reachable by a path. It carries the same 32-byte records, of three types
 * only: FAULT (arm a bus fault), STOP (end the run, stopped_by "launcher") and PROCESS (the
 * process of a node, whose declared clients must be it or its children: without it a
 * declared client is refused). A FAULT or PROCESS record, or a STOP from a client without the
 * LOCKSTEP role, on the public socket is refused and counted.
 */
#ifndef CANBUS_PROTO_H
#define CANBUS_PROTO_H

#include <stdint.h>

#define CANBUS_MAGIC 0x424e4143u /* "CANB" as little-endian bytes */
#define CANBUS_VERSION 1
#define CANBUS_MAX_RECS 2048     /* records per datagram */
#define CANBUS_NAME_LEN 32

/* Roles a client asks for (canbus_hello.roles). */
#define CANBUS_ROLE_CAN 0x1      /* sends and receives frames */
#define CANBUS_ROLE_LOCKSTEP 0x2 /* takes part in the quanta: answers every TICK with a DONE */
#define CANBUS_ROLE_OWN 0x4      /* also receives its own frames (loggers, python-can) */

struct canbus_hello {
    uint32_t magic;   /* CANBUS_MAGIC */
    uint16_t version; /* CANBUS_VERSION */
    uint16_t roles;   /* CANBUS_ROLE_* */
    char name[CANBUS_NAME_LEN]; /* NUL-padded, e.g. "world", "node1", "node1/io", "logger" */
    uint32_t node;    /* node (redundancy channel) the client belongs to, 0 for none */
    uint32_t reserved;
};

#define CANBUS_WELCOME_REALTIME 0x1
#define CANBUS_WELCOME_LISTEN_ONLY 0x2 /* an undeclared client: whatever it sends is refused */

struct canbus_welcome {
    uint32_t magic;
    uint16_t version;
    uint16_t client;   /* this client's index, as in FRAME.src and the bus trace */
    uint32_t bitrate;  /* bit/s */
    uint32_t flags;    /* CANBUS_WELCOME_* */
    int64_t quantum_ns;
    int64_t t_ns;      /* bus time when the client joined (0 before the start) */
    int64_t end_ns;    /* end of the run, or -1 for none */
    int64_t reserved;
};

enum canbus_rec_type {
    CANBUS_MSG_FRAME = 1, /* a CAN data frame, either way */
    CANBUS_MSG_TICK = 2,  /* bus -> LOCKSTEP client: advance to t_ns; aux = start of the quantum;
                             a --realtime bus: data = how late it released the quantum on its
                             wall clock (int64 ns, little-endian), else zeros */
    CANBUS_MSG_DONE = 3,  /* LOCKSTEP client -> bus: finished everything before t_ns; aux > t_ns:
                             nothing to do before aux (no TICK wanted up to it), else 0 */
    CANBUS_MSG_STOP = 4,  /* bus -> client: the run ends at t_ns; id = CANBUS_STOP_* reason. LOCKSTEP
                             client or control channel -> bus: end the run */
    CANBUS_MSG_ERROR = 5, /* bus -> CAN clients: an error frame on the wire (id = the frame's
                             identifier, t_ns = when, data[0] = sender, data[1] = its state) */
    CANBUS_MSG_FAULT = 6, /* control channel -> bus: arm a bus fault (nodes/README.md) */
    CANBUS_MSG_PROCESS = 7, /* control channel -> bus: id = a node (0: the world), t_ns = the
                               pid of its process (a SKE, the world): its declared clients
                               must be that process or a child of it (its partitions) */
};

/* ERROR record, in full (bus -> every CAN client, delivered like a frame, in wire order):
 *   id = identifier of the failed frame (0xFFFFFFFF for a state change without one), flags
 *   and len = that frame's, src = data[0] = its sender's client index (0xFF: the bus's own
 *   babbler), t_ns = when the wire is free again, aux = start of the failed frame,
 *   data[1] = the sender's enum canbus_err_state after it, data[2] = 1 if an error frame was
 *   on the wire, 0 for a state change alone (a forced bus-off, a recovery to ACTIVE),
 *   data[3..4] = the sender's transmit error counter, little-endian.
 *
 * FAULT record (control channel -> bus), arms a fault in the bus; kinds in `flags`:
 *   1 drop, 2 corrupt, 3 delay, 4 babble, 5 bus_off, 6 duplicate, 7 transceiver_cut,
 *   8 rx_drop (faultinject/can/canbus__fault.h).
 *   id      identifier to match, 0xFFFFFFFF for any (not used by babble and bus_off)
 *   data[0] target client index, 0xFF for any
 *   t_ns    start of the active window; aux = its end (exclusive), aux <= 0 for none.
 *           drop and delay match on a frame's request time, corrupt on its start on the
 *           wire, babble sends while the window is open, bus_off acts once at t_ns.
 *   drop, corrupt, duplicate, rx_drop: data[1..2] = how many frames at most, little-endian,
 *            0 for no limit (rx_drop: data[0] is the receiver that misses them)
 *   transceiver_cut: data[0] = the client cut off (not 0xFF), id unused
 *   delay:   data[1..4] = delay in microseconds, little-endian, > 0
 *   babble:  data[1..4] = identifier, little-endian, bit 31 set for 29-bit; data[5] = len;
 *            data[6..7] = how many frames at most, 0 for no limit. The target (0xFF: the bus
 *            itself) sends back-to-back frames whenever the wire is idle.
 *   bus_off: data[1] bit 0 = recover after 128 x 11 bit times.
 * A bad FAULT record is rejected and counted like any malformed record. */

/* FRAME flags */
#define CANBUS_FRAME_EFF 0x1 /* 29-bit identifier (ARINC 825 uses these) */
#define CANBUS_FRAME_RTR 0x2 /* remote frame */

enum canbus_stop_reason {
    CANBUS_STOP_END = 0,        /* end of the run */
    CANBUS_STOP_REQUESTED = 1,  /* a client asked for it */
    CANBUS_STOP_BAD_HELLO = 2,  /* wrong magic, version, roles or name */
    CANBUS_STOP_LATE_JOIN = 3,  /* LOCKSTEP client after the start */
    CANBUS_STOP_FULL = 4,       /* too many clients */
    CANBUS_STOP_SIGNAL = 5,     /* the bus process was interrupted */
    CANBUS_STOP_REFUSED = 6,    /* not as the launcher declared it, or its name is taken */
};

/* Error state of a CAN controller (ERROR record data[1]) */
enum canbus_err_state { CANBUS_ERR_ACTIVE = 0, CANBUS_ERR_PASSIVE = 1, CANBUS_ERR_BUS_OFF = 2 };

struct canbus_rec {
    uint8_t type;  /* enum canbus_rec_type */
    uint8_t flags; /* FRAME: CANBUS_FRAME_* */
    uint8_t len;   /* FRAME: data bytes, 0..8 */
    uint8_t src;   /* bus -> client FRAME/ERROR: sender's client index */
    uint32_t id;   /* FRAME: identifier; STOP: reason */
    int64_t t_ns;  /* FRAME client->bus: request time; bus->client: end of frame.
                      TICK / DONE: the time granted / reached. */
    int64_t aux;   /* FRAME bus->client: start of frame; TICK: start of the quantum */
    uint8_t data[8];
};

_Static_assert(sizeof(struct canbus_hello) == 48, "hello is 48 bytes on the wire");
_Static_assert(sizeof(struct canbus_welcome) == 48, "welcome is 48 bytes on the wire");
_Static_assert(sizeof(struct canbus_rec) == 32, "a record is 32 bytes on the wire");

/* Worst-case bit count of a data frame with `len` data bytes, stuff bits included
 * (Davis et al., Controller Area Network schedulability analysis: refuted, revisited and
 * revised, Real-Time Systems 35, 2007, §3): g + 8s + 13 + floor((g + 8s - 1) / 4), g = 34
 * (11-bit) or 54 (29-bit). */
static inline uint32_t canbus_frame_bits(int extended, uint32_t len)
{
    uint32_t g = extended ? 54u : 34u;
    return g + 8u * len + 13u + (g + 8u * len - 1u) / 4u;
}

#endif
