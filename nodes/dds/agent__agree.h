/* SPDX-License-Identifier: Apache-2.0 */
/* The agent's agreement on cross-channel inputs: which nodes' INPUTS of a frame go into AGREED.
 *
 * No DDS and no sockets here (unit-tested alone): the agent stores every sample it receives,
 * tells this module which nodes are dead or withdrawn, and asks which nodes a frame still
 * waits for. The answer depends only on what was published, never on when it arrived:
 *  - a node is waited for when it is in the request's wait mask, is not this node, is alive
 *    on DDS (not latched dead), is not withdrawn (below), and may still publish the frame
 *    (its newest frame is older: DDS delivers one writer's samples in order, so a node whose
 *    newest frame is later skipped this one);
 *  - AGREED holds this node's inputs and those of the wait-mask nodes that published the
 *    frame and are not withdrawn from it. Nodes outside the wait mask are left out even when
 *    their sample is there, so that the content never depends on whether an unawaited sample
 *    happened to arrive in time.
 *
 * Withdrawal: when a node's io link drops, its agent disposes its inputs instance. From then
 * on the node is neither waited for nor included, up to and including the first frame it
 * publishes again (its io's first frame after reconnecting): whether the others received
 * that first sample before answering the same frame is a matter of timing, so it counts for
 * nobody. From the next frame on it is waited for as before. The others would otherwise wait
 * for frames a node whose io is down can never publish, and in lockstep emulated time a
 * blocked io stalls its whole node.
 *
 * Lost frames: an agent whose publications a fault keeps back (dds_drop, dds_delay) in
 * emulated time publishes, in place of the frame's inputs, a mark that they are lost (a
 * sample whose wait_mask has AGREE_LOST_MARK set, and nothing else): the frame is then
 * published without inputs, so it is neither waited for nor included, exactly as a real-time
 * agent would answer after its time-out, but without the timing. In emulated time nothing
 * else could end the wait: the nodes run in lockstep, and the node whose sample is late
 * cannot reach a later frame while the others wait. The real sample of a frame marked lost
 * (the late one of dds_delay) is stale, whenever it comes. */
#ifndef AGENT__AGREE_H
#define AGENT__AGREE_H

#include <stdbool.h>
#include <stdint.h>

#include "xch/proto.h"

#define AGREE_RING 64 /* frames kept per node: samples more than this behind are stale */
#define AGREE_LOST_MARK 0x80000000u /* in a published wait_mask: this frame's inputs are lost */

typedef struct {
    bool used;
    bool lost; /* published as lost: no inputs */
    uint32_t frame;
    int64_t t_ns;
    struct xch_inputs in;
} agree_slot_t;

typedef struct {
    agree_slot_t ring[AGREE_RING];
    bool have_newest;
    uint32_t newest;  /* the latest frame this node published */
    bool dead;        /* lost on DDS: never waited for again in this run */
    bool withdrawn;   /* its io link went down (instance disposed): see above */
    bool resumed;     /* withdrawn, and it has published again since, from resume_frame */
    uint32_t resume_frame;
} agree_peer_t;

typedef struct {
    unsigned self, nodes;
    agree_peer_t peer[XCH_MAX_NODES];
    bool answered;
    uint32_t last_answered; /* the latest frame an AGREED was built for */
    uint64_t stored, stale, lost;
} agree_t;

void agree_init(agree_t *a, unsigned self, unsigned nodes);

/* Stores node's inputs for frame. Returns true if stored; false if stale (a frame already
 * answered, or older than what its ring slot holds) or the node is out of range. This node's
 * own inputs are always stored. Even a stale sample counts as the node's newest frame and
 * as its resumption after a withdrawal: it shows how far the node has got. */
bool agree_store(agree_t *a, unsigned node, uint32_t frame, int64_t t_ns,
                 const struct xch_inputs *in);

/* Stores node's mark that its inputs of frame are lost (see above), with the same rules as
 * agree_store(). */
bool agree_store_lost(agree_t *a, unsigned node, uint32_t frame, int64_t t_ns);

/* The bits of wait_mask restricted to the system's other nodes. */
uint32_t agree_mask(const agree_t *a, uint32_t wait_mask);

/* The nodes (bit k-1 = node k) that frame still waits for, given the request's wait mask. */
uint32_t agree_missing(const agree_t *a, uint32_t frame, uint32_t wait_mask);

/* Fills the AGREED of frame (see above) and records it as answered. */
void agree_build(agree_t *a, uint32_t frame, uint32_t wait_mask, struct xch_agreed *out);

void agree_set_dead(agree_t *a, unsigned node);
void agree_set_withdrawn(agree_t *a, unsigned node);

#endif
