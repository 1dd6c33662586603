/* SPDX-License-Identifier: Apache-2.0 */
/* The launcher's control channel (--control-fd): one end of a socketpair the bus inherits,
 * never a path, so that only the process that started the bus can arm faults (FAULT records),
 * end the run with stopped_by "launcher" (STOP) or name the process of a node (PROCESS). It is kept in the live list like a client
 * without an index: polled and read with the others, delivered nothing but the final STOP. */
#include "canbus__server.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>

#define LAUNCHER "\"launcher\""

int canbus__control_open(canbus_bus_t *b)
{
    int fd = b->o.control_fd, type = 0;
    socklen_t len = sizeof type;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISSOCK(st.st_mode) ||
        getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_SEQPACKET)
        return -ENOTSOCK;
    int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0 || fcntl(fd, F_SETFD, FD_CLOEXEC))
        return -errno;
    canbus_client_t *c = calloc(1, sizeof *c);
    b->live = calloc(16, sizeof *b->live);
    if (!c || !b->live) {
        free(c);
        return -ENOMEM;
    }
    b->cap_live = 16;
    c->fd = fd;
    c->index = -1;
    c->control = true;
    strcpy(c->name, "launcher");
    canbus_sb_str(&c->jname, LAUNCHER);
    b->live[b->n_live++] = c; /* first: read before any client in the same poll */
    b->control = c;
    return 0;
}

static void control_reject(canbus_bus_t *b, const char *reason)
{
    b->rejected++;
    canbus__line_head(&b->staged, b->t, "reject");
    canbus_sb_str(&b->staged, ",\"name\":" LAUNCHER ",\"reason\":\"");
    canbus_sb_str(&b->staged, reason);
    canbus_sb_str(&b->staged, "\"}\n");
}

static void arm_fault(canbus_bus_t *b, const struct canbus_rec *r)
{
    canbus_fault_t f;
    if (canbus_fault_from_rec(r, &f)) {
        control_reject(b, "bad_fault");
        return;
    }
    /* Faults armed by records are named in the order they came: rec1, rec2, ... */
    snprintf(f.fid, sizeof f.fid, "rec%" PRIu64, b->faults_armed + 1);
    if (canbus_wire_add_fault(&b->wire, &f)) {
        control_reject(b, "bad_fault");
        return;
    }
    b->faults_armed++;
    canbus_sbuf_t *s = &b->staged;
    canbus__line_head(s, b->t, "fault_armed");
    canbus_sb_str(s, ",\"fid\":");
    canbus_sb_json_str(s, f.fid, sizeof f.fid);
    canbus_sb_str(s, ",\"class\":\"");
    canbus_sb_str(s, canbus_fault_class_name(f.kind));
    canbus_sb_str(s, "\",\"target\":");
    canbus_sb_u64(s, f.target);
    canbus_sb_str(s, ",\"match_id\":");
    canbus_sb_u64(s, f.match_id);
    canbus_sb_str(s, ",\"from_ns\":");
    canbus_sb_i64(s, f.from_ns);
    canbus_sb_str(s, ",\"until_ns\":");
    canbus_sb_i64(s, f.until_ns == INT64_MAX ? -1 : f.until_ns);
    canbus_sb_str(s, ",\"by\":" LAUNCHER "}\n");
}

void canbus__stop_by(canbus_bus_t *b, canbus_client_t *c)
{
    if (b->stopping)
        return;
    b->stopping = true;
    b->stop_reason = CANBUS_STOP_REQUESTED;
    canbus_sb_mem(&b->stopped_by, c->jname.p, c->jname.n);
    canbus_sbuf_t *s = c->control ? &b->staged : &c->staged;
    canbus__line_head(s, b->t, "stop_request");
    if (c->control)
        canbus_sb_str(s, ",\"by\":" LAUNCHER);
    else
        canbus__sb_client(b, s, "by", (uint8_t)c->index);
    canbus_sb_str(s, "}\n");
    canbus__info(b, "%s asked to stop", c->name);
}

void canbus__handle_control(canbus_bus_t *b, canbus_client_t *c, const uint8_t *p, size_t n)
{
    if (n % sizeof(struct canbus_rec)) {
        control_reject(b, "size");
        return;
    }
    for (size_t off = 0; off < n; off += sizeof(struct canbus_rec)) {
        struct canbus_rec r;
        memcpy(&r, p + off, sizeof r);
        switch (r.type) {
        case CANBUS_MSG_STOP: canbus__stop_by(b, c); break;
        case CANBUS_MSG_FAULT: arm_fault(b, &r); break;
        case CANBUS_MSG_PROCESS:
            if (r.t_ns <= 1 || r.t_ns > INT32_MAX || !canbus__declare_process(b, r.id, (pid_t)r.t_ns))
                control_reject(b, "bad_process");
            break;
        default: control_reject(b, "type"); break;
        }
    }
}
