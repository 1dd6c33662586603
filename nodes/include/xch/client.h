/* SPDX-License-Identifier: Apache-2.0 */
/* The io partition's side of the cross-channel link (xch/proto.h) to the node's DDS agent.
 *
 * Runs inside a sandboxed system partition: no threads, no signals, no allocation, no DDS.
 * The only system calls are socket, connect, sendto (send), recvfrom (recv), poll,
 * clock_gettime and close, all in the system partitions' seccomp allow-list
 * (ske/abi/src/sandbox_policy.c). Every function returns 0 (or a count) on success and a
 * negative errno value on failure; a failed connection stays failed until closed. */
#ifndef XCH_CLIENT_H
#define XCH_CLIENT_H

#include <stddef.h>
#include <stdint.h>

#include "xch/proto.h"

/* How long xch_client_connect waits for WELCOME: the agent answers only once it has found
 * the other nodes' agents on DDS (its startup timeout is 20 s by default). */
#define XCH_CLIENT_CONNECT_TIMEOUT_MS 30000
/* Default for xch_client_t.timeout_ms: how long an exchange waits for its AGREED. */
#define XCH_CLIENT_EXCHANGE_TIMEOUT_MS 10000

typedef struct {
    int fd;             /* -1 when not connected */
    uint32_t node;      /* this node, 1..XCH_MAX_NODES */
    uint32_t nodes;     /* number of nodes in the system (from WELCOME) */
    int timeout_ms;     /* exchange timeout; < 0 waits for ever */
    uint64_t stale;     /* AGREED of an earlier frame dropped while waiting for a later one */
    uint64_t rejected;  /* datagrams from the agent that were not a valid AGREED */
} xch_client_t;

/* Connects to the agent listening at `path`, sends HELLO for `node` and waits for WELCOME.
 * err gets one line on failure. Returns 0, -ENAMETOOLONG, -EINVAL, -ETIMEDOUT, -EPROTO (the
 * peer did not answer with a WELCOME), or the errno of a socket call. */
int xch_client_connect(xch_client_t *c, const char *path, unsigned node, char *err,
                       size_t errlen);

/* Sends this node's INPUTS for `frame` (mine->wait_mask: the nodes to wait for) and blocks
 * until the agent's AGREED for that frame, which it copies to *out. Returns 0, -ETIMEDOUT
 * after c->timeout_ms, -ESHUTDOWN if the agent closed the connection, -ENOTCONN, or the errno
 * of a socket call. */
int xch_client_exchange(xch_client_t *c, uint32_t frame, int64_t t_ns,
                        const struct xch_inputs *mine, struct xch_agreed *out);

/* Sends one datagram of `type` (XCH_HEALTH, XCH_TELEMETRY, XCH_MISSION, or XCH_INPUTS for a
 * caller that collects the AGREED itself with xch_client_await) without waiting for an
 * answer. `len` must be the type's payload size. Returns 0, -EINVAL, -ENOTCONN, or the errno of
 * send (-EAGAIN is not possible: the socket blocks). */
int xch_client_send(xch_client_t *c, uint16_t type, uint32_t frame, int64_t t_ns,
                    const void *payload, size_t len);

/* Waits up to timeout_ms (< 0: for ever) for the AGREED of `frame`; earlier frames' AGREED are
 * dropped (counted in c->stale). Returns 0, -ETIMEDOUT, -ESHUTDOWN, -ENOTCONN or an errno. */
int xch_client_await(xch_client_t *c, uint32_t frame, struct xch_agreed *out, int timeout_ms);

/* The payload size of a datagram type, or 0 for HELLO/WELCOME and -1 for an unknown type. */
long xch_payload_size(unsigned type);

void xch_client_close(xch_client_t *c);

#endif
