/* SPDX-License-Identifier: Apache-2.0 */
/* The CAN wire model of ima-canbus: arbitration, bit timing, error frames, fault confinement
 * and injected faults, in integer bit units with no sockets, so a unit test can drive it. */
#ifndef CANBUS__WIRE_H
#define CANBUS__WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "canbus/proto.h"
#include "canbus__fault.h"

/* Client indices 0..CANBUS_WIRE_MAX_CLIENTS-1 (CANBUS_ANY, CANBUS_NOBODY: canbus__fault.h). */
#define CANBUS_WIRE_MAX_CLIENTS 250
_Static_assert(CANBUS_FAULT_MAX_INDEX == CANBUS_WIRE_MAX_CLIENTS - 1,
               "a fault may name every client index and no other");

/* Bits that follow the CRC delimiter in canbus_frame_bits(): ACK slot and delimiter are
 * before the error, EOF (7) and the interframe space (3) are not sent by a failed frame. */
#define CANBUS_EOF_IFS_BITS 10u
#define CANBUS_IFS_BITS 3u
/* Error frame: 6-bit error flag, up to 6 bits of other nodes' flags superposed, 8-bit
 * delimiter (ISO 11898-1 §10.4.4): 14..20 bits. We always take the worst case. */
#define CANBUS_ERROR_FRAME_BITS 20u
/* Bus-off recovery: 128 occurrences of 11 consecutive recessive bits (ISO 11898-1 §12.1.4),
 * modelled as that many bit times after the bus-off, whatever the traffic. */
#define CANBUS_RECOVERY_BITS (128u * 11u)

/* A frame waiting for the wire. */
typedef struct canbus_wire_frame {
    int64_t req_ns;  /* request time */
    uint64_t req_bit;
    uint64_t seq;    /* arrival order */
    uint32_t key;    /* arbitration key, canbus_wire_arb_key() */
    uint32_t id;
    uint8_t flags;   /* CANBUS_FRAME_* */
    uint8_t len;
    uint8_t client;  /* sender */
    uint8_t delayed; /* a delay fault has moved it already */
    uint8_t data[8];
} canbus_wire_frame_t;

enum canbus_ev_kind {
    CANBUS_EV_TX = 1,      /* a frame went through: delivered to receivers */
    CANBUS_EV_ERROR = 2,   /* a corrupted transmission and its error frame */
    CANBUS_EV_BUS_OFF = 3, /* the sender (client) entered bus-off */
    CANBUS_EV_BUS_ON = 4,  /* the client recovered from bus-off */
    CANBUS_EV_DROP = 5,    /* a frame was discarded before the wire (fault or bus-off) */
    CANBUS_EV_FAULT = 6,   /* a fault applied, cleared or refused (canbus__fault.h) */
    CANBUS_EV_RX_DROP = 7, /* the TX (or ERROR) event before was not delivered to client `to` */
};

enum canbus_drop_reason { CANBUS_DROP_FAULT = 1, CANBUS_DROP_BUS_OFF = 2 };

/* TX reason: the frame is a duplicate (can_duplicate). */
#define CANBUS_TX_DUPLICATE 1

/* What happened on the wire, in wire order; end_ns never decreases along the list (but for
 * a FAULT event that clears a spell: it is stamped with the spell's end). RX_DROP events
 * follow the TX or ERROR event they are about (FAULT events may come between). FAULT: reason = enum canbus_fault_state, id and client
 * = the frame it acted on (CANBUS_ANY_ID: none), data[0..3] = what it did in the spell (a
 * count, little-endian) when it clears. */
typedef struct canbus_wire_ev {
    uint8_t kind;   /* enum canbus_ev_kind */
    uint8_t client; /* sender (CANBUS_ANY: the babbler) */
    uint8_t state;  /* sender's enum canbus_err_state after the event */
    uint8_t reason; /* DROP: enum canbus_drop_reason; BUS_OFF: 1 if forced by a fault; TX:
                       CANBUS_TX_DUPLICATE; FAULT: enum canbus_fault_state */
    uint16_t tec;   /* sender's transmit error counter after the event */
    uint8_t flags;
    uint8_t len;
    uint32_t id;
    uint16_t fault; /* the fault that caused it (index + 1), 0 for none */
    uint8_t to;     /* RX_DROP: the receiver that misses the frame (CANBUS_ANY: every one) */
    int64_t start_ns; /* TX/ERROR: start of frame */
    int64_t end_ns;   /* TX/ERROR: when the wire is free again (interframe space included) */
    uint8_t data[8];
} canbus_wire_ev_t;

typedef struct canbus_wire_ctl {
    uint16_t tec, rec;
    bool attached; /* a receiver (CAN role, connected) */
    bool bus_off;
    bool recover;  /* armed to recover from bus-off */
    uint64_t recover_bit;
    uint32_t pending; /* frames waiting for the wire */
    uint64_t tx_ok, tx_err, dropped, bus_off_events;
} canbus_wire_ctl_t;

typedef struct canbus_wire_heap {
    canbus_wire_frame_t *v;
    size_t n, cap;
} canbus_wire_heap_t;

typedef struct canbus_wire {
    uint32_t bitrate;
    uint32_t gap_bits; /* idle bits added after every frame, beyond its interframe space */
    uint64_t free_bit; /* first bit at which the wire is idle */
    uint64_t seq;
    canbus_wire_heap_t future; /* by request bit */
    canbus_wire_heap_t ready;  /* by arbitration key, client, seq */
    canbus_wire_ctl_t ctl[CANBUS_WIRE_MAX_CLIENTS];
    uint16_t n_ctl;     /* highest client index seen + 1 */
    uint16_t n_bus_off; /* clients in bus-off now */
    uint8_t receivers[CANBUS_WIRE_MAX_CLIENTS];
    size_t n_receivers;
    canbus_fault_t *faults;
    size_t n_faults, cap_faults;
    /* can_duplicate: the copy that goes on the wire right after its original */
    canbus_wire_frame_t dup;
    bool dup_pending;
    uint16_t dup_fault;
    /* Events: ev[ev_head..n_ev) not consumed yet, ev[ev_mark..n_ev) not seen yet; the caller
     * moves both forward, the wire moves the list down when it needs room. */
    canbus_wire_ev_t *ev;
    size_t ev_head, ev_mark, n_ev, cap_ev;
    uint64_t *win_busy; /* busy bits per 1 s window of bus time */
    size_t n_win;
    uint64_t frames, frame_bits, busy_bits, error_frames, bus_off_events, dropped;
    uint64_t babble_count, duplicated, rx_dropped;
} canbus_wire_t;

/* Frames a client may have waiting for the wire (a controller's transmit queue). */
#define CANBUS_WIRE_MAX_PENDING 65536u

#define CANBUS_WIRE_EFULL (-105)
#define CANBUS_WIRE_ENOMEM (-12)
#define CANBUS_WIRE_EINVAL (-22)

int canbus_wire_init(canbus_wire_t *w, uint32_t bitrate, uint32_t gap_bits);
void canbus_wire_fini(canbus_wire_t *w);

/* Bit k of the wire starts at floor(k * 1e9 / bitrate) ns; a frame requested at t ns may
 * start at the first bit boundary at or after t. */
uint64_t canbus_wire_bit_ceil(const canbus_wire_t *w, int64_t ns);
int64_t canbus_wire_bit_ns(const canbus_wire_t *w, uint64_t bit);

/* The order in which identifiers win arbitration: the bits as the wire carries them (base 11
 * bits, then RTR or SRR, IDE, extension 18 bits, RTR), dominant 0 first. */
uint32_t canbus_wire_arb_key(uint32_t id, uint8_t flags);

/* Bits a data or remote frame holds the wire, interframe space included. */
uint32_t canbus_wire_frame_bits(uint8_t flags, uint8_t len);

void canbus_wire_attach(canbus_wire_t *w, uint8_t client, bool attached);
void canbus_wire_arm_recovery(canbus_wire_t *w, uint8_t client, bool recover);
int canbus_wire_submit(canbus_wire_t *w, int64_t req_ns, uint32_t id, uint8_t flags,
                       uint8_t len, const uint8_t *data, uint8_t client);
int canbus_wire_add_fault(canbus_wire_t *w, const canbus_fault_t *f);

/* Simulates the wire at every bit boundary before until_ns; a frame that starts before
 * until_ns may end after it. Appends to the event list. */
int canbus_wire_run(canbus_wire_t *w, int64_t until_ns);

enum canbus_err_state canbus_wire_state(const canbus_wire_t *w, uint8_t client);

/* Load over [0, elapsed_ns): overall and the highest of the complete 1 s windows (the
 * overall load when no window is complete). */
void canbus_wire_load(const canbus_wire_t *w, int64_t elapsed_ns, double *overall,
                      double *max_1s);

/* ---- for the fault injector (faultinject/can/fault_wire.c) ------------------------------ */

/* A new event at the end of the list (zeroed), or NULL without memory. */
canbus_wire_ev_t *canbus__wire_ev(canbus_wire_t *w);
/* Discards a frame before the wire at at_ns (a DROP event; fault: index + 1, or 0). */
void canbus__wire_drop(canbus_wire_t *w, const canbus_wire_frame_t *f, int64_t at_ns,
                       uint16_t fault);
/* Puts a client bus-off at bit at_bit (forced: by a fault), or back on. */
void canbus__wire_bus_off(canbus_wire_t *w, uint8_t client, uint64_t at_bit, bool forced);
void canbus__wire_bus_on(canbus_wire_t *w, uint8_t client, uint64_t at_bit);
/* Queues a frame again for its (new) request time. */
int canbus__wire_requeue(canbus_wire_t *w, const canbus_wire_frame_t *f);

#endif
