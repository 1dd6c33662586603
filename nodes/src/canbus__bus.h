/* SPDX-License-Identifier: Apache-2.0 */
/* The ima-canbus process: options, clients, the bus and its entry points (bus_server.c,
 * bus_loop.c; canbus__server.h for what its files share), JSON output helpers (bus_json.c). */
#ifndef CANBUS__BUS_H
#define CANBUS__BUS_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/types.h>

#include "canbus/proto.h"
#include "canbus__wire.h"

/* A growable byte buffer for JSON lines. */
typedef struct canbus_sbuf {
    char *p;
    size_t n, cap;
    bool oom;
} canbus_sbuf_t;

void canbus_sb_reserve(canbus_sbuf_t *s, size_t more);
void canbus_sb_mem(canbus_sbuf_t *s, const char *p, size_t n);
void canbus_sb_str(canbus_sbuf_t *s, const char *p);
void canbus_sb_i64(canbus_sbuf_t *s, int64_t v);
void canbus_sb_u64(canbus_sbuf_t *s, uint64_t v);
void canbus_sb_hex(canbus_sbuf_t *s, const uint8_t *p, size_t n);
/* A JSON string literal, quotes included, of the first n bytes of p (stops at NUL). */
void canbus_sb_json_str(canbus_sbuf_t *s, const char *p, size_t n);
void canbus_sb_free(canbus_sbuf_t *s);

typedef struct canbus_cli_fault {
    canbus_fault_t fault;
    char target_name[CANBUS_NAME_LEN + 1];
} canbus_cli_fault_t;

/* --kill-node / --hang-node: at the first quantum starting at or after t_ns, every client
 * of `node` gets `sig` (SIGKILL: the processor dies; SIGSTOP: it hangs, its processes alive
 * but frozen) and is dropped: the processor stops at a deterministic instant, with every
 * window before it finished (its SKE had sent DONE). */
typedef struct canbus_kill {
    uint32_t node;
    int64_t t_ns;
    int sig;
    bool done;
} canbus_kill_t;

/* --client NAME:ROLES:NODE: a client the launcher expects. Once any is declared, a hello must
 * match its declaration (roles and node), and a client of another name joins listen-only. */
typedef struct canbus_decl {
    char name[CANBUS_NAME_LEN];
    uint16_t roles;
    uint32_t node;
    pid_t pid; /* its node's process (a PROCESS record on the control channel), 0 not yet */
} canbus_decl_t;

typedef struct canbus_opts {
    const char *socket_path;
    uint32_t bitrate;
    int64_t quantum_ns;
    int lockstep_clients;
    int64_t end_ns; /* -1: none */
    bool realtime;
    double pace; /* --pace: emulated seconds per wall second (0: as fast as possible) */
    int control_fd; /* --control-fd: the launcher's channel (FAULT, STOP), -1 for none */
    const char *trace_path;
    const char *stats_path;
    int max_clients;
    bool quiet;
    int max_rejects;        /* a client rejected more often than this is disconnected */
    int64_t send_timeout_ns; /* how long a non-lockstep client may stall its output */
    size_t client_buffer;   /* bytes the bus queues for a client before it waits for it */
    bool recover;           /* clients recover from bus-off after 128 x 11 bits */
    uint32_t gap_bits;      /* idle bits added after each frame (0: the formula's 3-bit IFS) */
    canbus_cli_fault_t *faults;
    size_t n_faults;
    canbus_kill_t *kills;
    size_t n_kills;
    /* --client-order: the client named order[k] gets index k, whenever it joins; others get
     * the indices after. Clients that join in the same quantum in a racy order (each node's
     * io partition) so get the same indices in every run. */
    char **order;
    size_t n_order;
    canbus_decl_t *decls;
    size_t n_decls;
} canbus_opts_t;

typedef struct canbus_client {
    int fd;
    int index; /* -1 until welcomed */
    pid_t pid; /* peer process (SO_PEERCRED), 0 if unknown */
    uint16_t roles;
    uint32_t node;
    char name[CANBUS_NAME_LEN + 1];
    canbus_sbuf_t jname; /* the name as a JSON string */
    bool control;     /* the launcher's control channel, not a client of the socket */
    bool listen_only; /* undeclared: receives frames, anything it sends is refused */
    uint64_t refused_types[8]; /* records refused by policy, by record type (0: others) */
    bool member;      /* takes part in the current quantum */
    bool member_next; /* joined as LOCKSTEP after the start: takes part from the next one */
    bool done;        /* sent DONE for the current quantum */
    int64_t need_ns;  /* its last DONE's aux: no TICK needed while the grant would be <= it */
    uint64_t ticks, ticks_skipped; /* quanta it was granted, and those it did not need */
    bool skip;                     /* not granted the current quantum */
    bool gone;
    const char *leave_reason;
    uint64_t tx, rx, rejected, clamped, overflow;
    uint8_t *q; /* output queue: datagrams as [uint32 length][bytes] */
    size_t q_head, q_len, q_cap;
    int64_t q_progress_wall; /* last time the queue moved */
    canbus_sbuf_t staged;    /* trace lines of this quantum, written in index order */
    bool more;               /* the last read stopped at its bound: datagrams may be left */
} canbus_client_t;

typedef struct canbus_bus {
    canbus_opts_t o;
    canbus_wire_t wire;
    int listen_fd;
    FILE *trace;
    canbus_client_t **live; /* connected, including those before their hello */
    size_t n_live, cap_live;
    canbus_client_t *by_index[CANBUS_WIRE_MAX_CLIENTS];
    int next_index;
    bool started;
    int64_t t;      /* start of the current quantum */
    int64_t t_next; /* end of the current quantum (the TICK's t_ns) */
    int64_t epoch_wall;
    int64_t release_late_ns;   /* realtime: how late the current quantum was released */
    int64_t late_max_ns;       /* realtime: the latest release */
    uint64_t quanta_late;      /* realtime: quanta released more than 1 ms late */
    int64_t start_wall, end_wall;
    bool stopping;
    uint32_t stop_reason;
    canbus_sbuf_t staged;  /* trace lines not tied to a client (bad hellos) */
    canbus_sbuf_t line;    /* scratch */
    struct canbus_rec *out; /* delivery batch */
    size_t out_cap;
    uint8_t *rxbuf;
    uint64_t quanta, rejected, bad_hellos, late_joins, full, send_timeouts, garbage_kicks;
    uint64_t faults_armed;
    uint64_t refused_users; /* connections of another user, closed at once */
    uint64_t refused_hellos, refused_records; /* by the admission policy (bus_admit.c) */
    canbus_sbuf_t refused;  /* the statistics' `refusals` entries of refused hellos */
    size_t n_refused;
    canbus_sbuf_t stopped_by; /* who stopped the run, a JSON string; empty: nobody did */
    struct canbus_client *control; /* the launcher's control channel, or NULL */
    bool trace_error;
} canbus_bus_t;

extern volatile sig_atomic_t canbus_signalled;

int canbus_bus_open(canbus_bus_t *b, const canbus_opts_t *o);
/* Runs to the end; returns 0, or a negative errno on a failure of the bus itself. */
int canbus_bus_run(canbus_bus_t *b);
int canbus_bus_write_stats(canbus_bus_t *b, const char *path);
void canbus_bus_close(canbus_bus_t *b);

#endif
