/* SPDX-License-Identifier: Apache-2.0 */
/* The CAN bus's fault injector, compiled into the bus's library (canbus_core): faults from
 * the command line (the common grammar of fi/spec.h, and the bus's older KIND:KEY=VALUE
 * forms) and from FAULT records (proto.h), their spells in bus time, and the hooks through
 * which the wire model (nodes/src/canbus__wire.h) applies them and records what they did.
 *
 * Classes (faultinject/README.md has the full grammar):
 *   can_drop         frames matching id/client never reach the wire   (older form: drop)
 *   can_corrupt      each matching transmission fails with an error frame     (corrupt)
 *   can_delay        matching frames are requested delay=TIME later            (delay)
 *   babbling_idiot   a client, or the bus itself, floods the wire              (babble)
 *   can_bus_off      a client's controller goes bus-off                       (bus_off)
 *   can_duplicate    a matching frame goes on the wire twice, back to back
 *   transceiver_cut  a client sends nothing and receives nothing
 *   rx_drop          matching frames are not delivered to one client
 * Frames are matched on their request time (drop, delay), or on the start of their
 * transmission (the others). */
#ifndef CANBUS__FAULT_H
#define CANBUS__FAULT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "canbus/proto.h"

/* Client indices are below 250: CANBUS_ANY means every client (as a sender: the bus's own
 * babbler), CANBUS_NOBODY a target named but not joined yet. */
#define CANBUS_ANY 0xFFu
#define CANBUS_NOBODY 0xFEu
#define CANBUS_ANY_ID 0xFFFFFFFFu
#define CANBUS_FAULT_MAX_INDEX 249 /* the highest client index a fault may name */
#define CANBUS_FAULT_EINVAL (-22)

enum canbus_fault_kind {
    CANBUS_FAULT_DROP = 1,
    CANBUS_FAULT_CORRUPT = 2,
    CANBUS_FAULT_DELAY = 3,
    CANBUS_FAULT_BABBLE = 4,
    CANBUS_FAULT_BUS_OFF = 5,
    CANBUS_FAULT_DUPLICATE = 6,
    CANBUS_FAULT_CUT = 7,
    CANBUS_FAULT_RX_DROP = 8,
};
#define CANBUS_FAULT_KINDS 8

/* What a fault trace event says of it (the `state` of a `fault` line). */
enum canbus_fault_state { CANBUS_FAULT_APPLIED = 1, CANBUS_FAULT_CLEARED = 2, CANBUS_FAULT_REFUSED = 3 };

#define CANBUS_FID_MAX 16 /* a fault id with its NUL (FI_ID_MAX) */

typedef struct canbus_fault {
    uint8_t kind;      /* enum canbus_fault_kind */
    uint8_t target;    /* client index, CANBUS_ANY or CANBUS_NOBODY */
    uint32_t match_id; /* identifier to match, CANBUS_ANY_ID for any */
    /* Spells, as fi/spec.h: [from, until) when period is 0; else [from + k period,
     * from + k period + on) before until. */
    int64_t from_ns;
    int64_t until_ns;  /* INT64_MAX when open-ended */
    int64_t period_ns;
    int64_t on_ns;
    uint32_t limit;    /* frames at most over the run, 0 = no limit */
    uint32_t used;     /* frames it has hit */
    int64_t delay_ns;  /* can_delay */
    uint32_t babble_id;   /* babbling_idiot: identifier */
    uint8_t babble_flags; /* babbling_idiot: CANBUS_FRAME_* */
    uint8_t babble_len;   /* babbling_idiot: data bytes */
    bool recover;         /* can_bus_off: the client recovers after CANBUS_RECOVERY_BITS */
    char fid[CANBUS_FID_MAX]; /* as the fault trace events name it; "" until assigned */
    /* Bookkeeping, reset by canbus_wire_add_fault(). */
    int64_t spell;        /* the spell it has acted in and not been cleared of, -1: none */
    int64_t last_spell;   /* the last spell it acted in, -1: none */
    uint32_t spell_hits;  /* what it did in that spell */
    int64_t forced_spell; /* can_bus_off: the spell whose bus-off it forced, -1: none */
} canbus_fault_t;

/* ---- parsing (fault_parse.c) ------------------------------------------------------------ */

/* Parses one --fault SPEC: CLASS:fid=ID,at=TIME[,until][,period,on][,KEY=VALUE...] with the
 * classes above, or an older KIND:KEY=VALUE,... (drop, corrupt, delay, babble, bus_off; `fid`
 * and `at`/`from` optional, fid left empty for the caller to assign). A target given by name
 * is returned in target_name (empty for an index or any) and f->target is CANBUS_NOBODY. */
int canbus_fault_parse(const char *spec, canbus_fault_t *f, char *target_name,
                       size_t name_size, char *err, size_t err_size);
/* Decodes a FAULT record (proto.h); fid left empty. */
int canbus_fault_from_rec(const struct canbus_rec *r, canbus_fault_t *f);
/* "can_drop", "can_corrupt", ... */
const char *canbus_fault_class_name(uint8_t kind);

/* ---- spells (fault_spell.c) ------------------------------------------------------------- */

/* The spell active at t (k >= 0), or -1. */
int64_t canbus_fault_spell(const canbus_fault_t *f, int64_t t_ns);
/* When spell k ends (INT64_MAX: never). */
int64_t canbus_fault_spell_end(const canbus_fault_t *f, int64_t k);
/* The first spell start or end after t, INT64_MAX if none. */
int64_t canbus_fault_next_edge(const canbus_fault_t *f, int64_t t_ns);
/* Does a frame of `client` with identifier id, at time t, fall under the fault? (target,
 * identifier, spell, limit) */
bool canbus_fault_matches(const canbus_fault_t *f, uint8_t client, uint32_t id, int64_t t_ns);
/* The first fault of `kind` the frame falls under, or NULL. */
canbus_fault_t *canbus_fault_find(canbus_fault_t *v, size_t n, uint8_t kind, uint8_t client,
                                  uint32_t id, int64_t t_ns);

/* The fault acted at t. What it means for its trace events, in order: `cleared` (a spell it
 * acted in is over: *cleared_spell) and `applied` (this is the first thing it does in its
 * spell). */
typedef struct {
    bool cleared, applied;
    int64_t cleared_spell;
    uint32_t cleared_hits;
} canbus_fault_note_t;
canbus_fault_note_t canbus_fault_hit(canbus_fault_t *f, int64_t t_ns);
/* The spell the fault acted in ends by t: true once, with when it ended and what it did. */
bool canbus_fault_spell_over(canbus_fault_t *f, int64_t t_ns, int64_t *end_ns, uint32_t *hits);

/* ---- applying them on the wire (fault_wire.c) ------------------------------------------- */

struct canbus_wire;
struct canbus_wire_frame;

/* What becomes of a frame leaving the request queue at bit b. */
enum canbus_release { CANBUS_RELEASE_PASS, CANBUS_RELEASE_DROPPED, CANBUS_RELEASE_DELAYED };
int canbus__fault_release(struct canbus_wire *w, struct canbus_wire_frame *f, uint64_t b,
                          enum canbus_release *what);
/* Forced bus-offs due at bit b, and their ends. */
int canbus__fault_due(struct canbus_wire *w, uint64_t b);
/* The earliest bit after b at which a fault needs the wire model's attention. */
uint64_t canbus__fault_wake(const struct canbus_wire *w, uint64_t b);
/* The babble frame competing at bit b, if any (the lowest key of the active babblers). */
canbus_fault_t *canbus__fault_babbler(struct canbus_wire *w, uint64_t b,
                                      struct canbus_wire_frame *out);
/* A babble frame of fault bf goes on the wire at bit b. */
int canbus__fault_babbled(struct canbus_wire *w, canbus_fault_t *bf, uint64_t b);
/* The transceiver_cut fault that keeps f, about to start at start_ns, off the wire:
 * *fault = its index + 1, or 0 when the frame goes. */
int canbus__fault_cut(struct canbus_wire *w, const struct canbus_wire_frame *f, int64_t start_ns,
                      uint16_t *fault);
/* The can_corrupt fault that makes a transmission of f starting at start_ns fail: *fault =
 * its index + 1, or 0. */
int canbus__fault_corrupt(struct canbus_wire *w, const struct canbus_wire_frame *f,
                          int64_t start_ns, uint16_t *fault);
/* After the transmission recorded at event ev_index (a frame, or an error frame): the
 * receivers that miss it (rx_drop: frames only; transceiver_cut) and, for a frame when
 * `may_duplicate`, a duplicate to send next. */
int canbus__fault_after_tx(struct canbus_wire *w, size_t ev_index, bool may_duplicate);
/* Clears the spells that ended by t_ns (trace events). */
int canbus__fault_close_spells(struct canbus_wire *w, int64_t t_ns);

#endif
