/* SPDX-License-Identifier: Apache-2.0 */
/* The DDS agent's fault injector, its pure part: the faults of its command line and what they
 * do to this node's publications of one major frame. No DDS, no sockets (unit-tested alone).
 *
 *     dds_drop:fid=ID,at=TIME[,until][,period,on]
 *         this node's cross-channel inputs and node health of the frames in the spell are not
 *         published
 *     dds_delay:fid=ID,at=TIME[,until][,period,on],frames=N
 *         they are published N major frames late (when io hands over frame F + N)
 *
 * The spell is in emulated time; a frame is in it when its start (the t_ns of io's datagram,
 * at frame F's start) is. So the faults act on whole frames, the same ones in every run. */
#ifndef AGENT__FAULT_H
#define AGENT__FAULT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fi/spec.h"

#define DDS_FAULT_MAX 8
#define DDS_DELAY_MAX_FRAMES 50 /* well inside the agreement's ring of frames */

typedef enum { DDS_FAULT_DROP = 1, DDS_FAULT_DELAY = 2 } dds_fault_kind_t;

typedef struct {
    fi_spec_t spec;
    dds_fault_kind_t kind;
    uint32_t frames;     /* dds_delay: how many frames late */
    int64_t spell;       /* the spell it acts in, -1: none */
    int64_t last_spell;  /* the last spell it acted in, -1: none */
    uint32_t spell_frames; /* frames it acted on in that spell */
    uint64_t total_frames;
} dds_fault_t;

typedef struct {
    dds_fault_t f[DDS_FAULT_MAX];
    size_t n;
    bool have_frame;
    uint32_t frame; /* the frame last decided (one decision per frame) */
    int action;     /* its decision: enum dds_fault_action */
    uint32_t delay_frames;
} dds_faults_t;

enum dds_fault_action { DDS_PUBLISH = 0, DDS_WITHHOLD = 1, DDS_DELAY = 2 };

/* A trace event due: fault f applied (at the frame's start) or cleared (at its spell's end). */
typedef struct {
    size_t fault;
    bool applied; /* else cleared */
    int64_t t_ns;
    uint32_t frames; /* cleared: frames it acted on in the spell */
} dds_fault_note_t;

/* Parses one --fault SPEC into set. 0, or -1 with one line in err. */
int dds_fault_add(dds_faults_t *set, const char *text, char *err, size_t errlen);
const char *dds_fault_class(const dds_fault_t *f); /* "dds_drop", "dds_delay" */

/* What this node's samples of frame `frame` (starting at t_ns) become: DDS_PUBLISH, or
 * DDS_WITHHOLD (dropped), or DDS_DELAY by *delay_frames. The first call for a frame decides
 * and writes the trace events due into notes (at most 2 per fault); later calls for the same
 * frame repeat the decision with no events. */
int dds_fault_frame(dds_faults_t *set, uint32_t frame, int64_t t_ns, uint32_t *delay_frames,
                    dds_fault_note_t *notes, size_t *n_notes);

#endif
