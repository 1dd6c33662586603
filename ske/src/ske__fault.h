/* SPDX-License-Identifier: Apache-2.0 */
/* What the SKE keeps of the faults injected into its module (--fault), of its test switches
 * (--test-switch) and of the port hashes (--trace-port-hashes): the types the supervisor's
 * state holds. The functions are in ske__supervisor.h, with the rest of the supervisor. */
#ifndef SKE__FAULT_H
#define SKE__FAULT_H

#include <stdbool.h>
#include <stdint.h>

#include "fi/spec.h"
#include "ske/config.h"

#define SKE_MAX_FAULTS 64 /* --fault options */
#define SKE_MAX_SWITCHES 16 /* --test-switch options */
/* The classes the SKE commits itself (not the partition's fault hook). */
#define SKE_FAULT_MODULE_RESET SKE_FAULT_CLASSES
#define SKE_FAULT_DISK_FULL (SKE_FAULT_CLASSES + 1)

/* One injected fault and what happened to it so far. */
typedef struct {
    fi_spec_t spec;
    int cls; /* ske_fault_class_t, SKE_FAULT_MODULE_RESET or SKE_FAULT_DISK_FULL */
    int partition; /* index; -1 for a module reset */
    int slot; /* in the partition's control block */
    int port; /* index in the partition's ports, -1: none */
    char process[SKE_NAME_MAX]; /* "": whichever process runs */
    char target[2 * SKE_NAME_MAX + 2]; /* the trace's `target` */
    int64_t value_ns; /* cpu_overrun: CPU to spin; memory_exhaustion: the partition's limit */
    /* Bookkeeping, kept across restarts of the partition: the last spell the fault was
     * applied or refused in (-1: none), and whether a state fault is applied now. */
    int64_t done_spell;
    bool active;
} ske_fault_t;

typedef struct {
    int n;
    ske_fault_t f[SKE_MAX_FAULTS];
} ske_faults_t;

/* One corrupt-port test switch: at `t_ns` the SKE flips the bytes of a source port's latest
 * message, as if someone other than its writer had written it. */
typedef struct {
    int partition;
    int port;
    int64_t t_ns;
    bool done;
} ske_corrupt_switch_t;

typedef struct {
    int n; /* as given, for the trace */
    const char *given[SKE_MAX_SWITCHES];
    bool eat_next_window; /* overrun-eats-next-window */
    bool every_quantum;   /* every-quantum: no window runs ahead of the bus (supervisor.c) */
    int8_t hm_action[SKE_MAX_PARTITIONS]; /* hm-action: hm_action_t per partition, -1: none */
    int n_corrupt;
    ske_corrupt_switch_t corrupt[SKE_MAX_SWITCHES];
} ske_switches_t;

/* The port hashes of one partition's window: what its source ports held when it got the
 * CPU, and what its queuing source ports sent. */
typedef struct {
    uint32_t seq[SKE_MAX_PORTS]; /* sampling: the latest sequence number at the grant */
    uint64_t qhash[SKE_MAX_PORTS]; /* queuing: FNV-1a over the messages sent in the window */
    uint64_t qbytes[SKE_MAX_PORTS];
    uint32_t qcount[SKE_MAX_PORTS];
} ske_port_hashes_t;

/* FNV-1a, 64 bits, continued from h (start with SKE_FNV_OFFSET). */
#define SKE_FNV_OFFSET 0xcbf29ce484222325ULL
uint64_t ske_fnv1a64(uint64_t h, const void *data, size_t len);

#endif /* SKE__FAULT_H */
