/* SPDX-License-Identifier: Apache-2.0 */
/* Who may join the bus and what a client may send: hellos checked against the clients the
 * launcher declared (--client), undeclared clients admitted listen-only, records a client may
 * not send refused, and the statistics' `refusals` list that names them all. A process of the
 * run's own user reaches the public socket (the python-can tools do): it can listen, not act. */
#include "canbus__server.h"

#include <inttypes.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>

#include "peer/parent.h"

#define REFUSED_LISTED_MAX 64 /* refused hellos listed one by one; later ones only counted */
#define PROCESS_WAIT_NS 2000000000LL /* how long a declared hello waits for its node's pid */

/* A name is 1..31 printable ASCII characters and its NUL: it goes into traces and summaries. */
static bool name_ok(const char *name)
{
    const char *end = memchr(name, '\0', CANBUS_NAME_LEN);
    if (!end || end == name)
        return false;
    for (const char *p = name; p < end; p++)
        if (*p < 0x20 || *p > 0x7E)
            return false;
    return true;
}

static canbus_decl_t *declared(const canbus_bus_t *b, const char *name)
{
    for (size_t i = 0; i < b->o.n_decls; i++)
        if (strcmp(b->o.decls[i].name, name) == 0)
            return &b->o.decls[i];
    return NULL;
}

static bool node_exists(const canbus_bus_t *b, uint32_t node)
{
    if (node == 0)
        return true;
    for (size_t i = 0; i < b->o.n_decls; i++)
        if (b->o.decls[i].node == node)
            return true;
    return false;
}

/* The welcomed client of that name still connected. One whose process has died (an io
 * partition restarted by its SKE) may not have been read to its end yet: it is read now, so
 * that its successor is not taken for a second client of the same name. */
static canbus_client_t *live_named(canbus_bus_t *b, const char *name)
{
    for (size_t i = 0; i < b->n_live; i++) {
        canbus_client_t *c = b->live[i];
        if (c->gone || c->index < 0 || strcmp(c->name, name) != 0)
            continue;
        canbus__read_client(b, c);
        if (!c->gone)
            return c;
    }
    return NULL;
}

bool canbus__declare_process(canbus_bus_t *b, uint32_t node, pid_t pid)
{
    bool any = false;
    for (size_t i = 0; i < b->o.n_decls; i++)
        if (b->o.decls[i].node == node) {
            b->o.decls[i].pid = pid;
            any = true;
        }
    return any;
}

/* The launcher names a node's process as soon as it has started it, but the process may say
 * hello first: the control channel is read until the name comes, for a bounded time (this
 * happens before the start, while the launcher starts the nodes and the world). */
static void await_process(canbus_bus_t *b, const canbus_decl_t *d)
{
    int64_t end = canbus__wall_ns() + PROCESS_WAIT_NS;
    for (int64_t now; !d->pid && b->control && !b->control->gone &&
                      (now = canbus__wall_ns()) < end;) {
        struct pollfd p = {.fd = b->control->fd, .events = POLLIN};
        if (poll(&p, 1, (int)((end - now) / 1000000) + 1) > 0)
            canbus__read_client(b, b->control);
    }
}

/* A declared client of a node whose process the launcher named must be that process or one of
 * its children (a SKE's partitions): a same-user process cannot take a declared name. */
static const char *check_process(canbus_bus_t *b, const canbus_client_t *c,
                                 const canbus_decl_t *d)
{
    if (!b->control)
        return NULL; /* started by hand: nobody names the processes */
    await_process(b, d);
    if (!d->pid)
        return "unknown_process";
    char comm[64];
    if (c->pid == d->pid || (c->pid > 0 && peer_parent(c->pid, comm, sizeof comm) == d->pid))
        return NULL;
    return "not_its_process";
}

const char *canbus__admit(canbus_bus_t *b, canbus_client_t *c, const struct canbus_hello *h,
                          uint32_t *stop_reason)
{
    *stop_reason = CANBUS_STOP_BAD_HELLO;
    if (!name_ok(h->name))
        return "bad_name";
    *stop_reason = CANBUS_STOP_REFUSED;
    if (live_named(b, c->name))
        return "duplicate_name";
    if (b->o.n_decls == 0)
        return NULL; /* a bus started by hand: everyone is trusted as before */
    const canbus_decl_t *d = declared(b, c->name);
    if (d)
        return d->roles != h->roles || d->node != h->node ? "not_as_declared"
                                                          : check_process(b, c, d);
    if (h->roles & CANBUS_ROLE_LOCKSTEP)
        return "undeclared_lockstep"; /* it would hold up, or take part in, the quanta */
    if (!node_exists(b, h->node))
        return "unknown_node";
    c->listen_only = true;
    return NULL;
}

/* {"what":"can_client","detail":TEXT} into s, after a comma unless it is the first. */
static void sb_entry(canbus_sbuf_t *s, bool first, const char *detail)
{
    if (!first)
        canbus_sb_str(s, ",");
    canbus_sb_str(s, "{\"what\":\"can_client\",\"detail\":");
    canbus_sb_json_str(s, detail, strlen(detail));
    canbus_sb_str(s, "}");
}

void canbus__note_refused_hello(canbus_bus_t *b, const canbus_client_t *c, const char *why)
{
    if (b->n_refused++ >= REFUSED_LISTED_MAX)
        return;
    char detail[160];
    snprintf(detail, sizeof detail, "hello of '%s' (pid %ld) refused: %s", c->name,
             (long)c->pid, why);
    sb_entry(&b->refused, b->n_refused == 1, detail);
}

void canbus__refuse_record(canbus_bus_t *b, canbus_client_t *c, uint8_t type, const char *why)
{
    c->refused_types[type < 8 ? type : 0]++;
    b->refused_records++;
    canbus__reject(b, c, why);
}

static const char *const type_names[8] = {"other", "FRAME", "TICK",  "DONE",
                                          "STOP",  "ERROR", "FAULT", "PROCESS"};

/* "'NAME' (client K, listen-only, pid P): refused 3 FRAME, 1 STOP", or "" when it sent
 * nothing it may not. */
static void client_detail(const canbus_client_t *c, char *out, size_t len)
{
    out[0] = '\0';
    int n = snprintf(out, len, "'%s' (client %d%s, pid %ld): refused", c->name, c->index,
                     c->listen_only ? ", listen-only" : "", (long)c->pid);
    const char *sep = " ";
    bool any = false;
    for (int t = 1; t <= 8 && n > 0 && (size_t)n < len; t++) {
        uint64_t k = c->refused_types[t % 8]; /* 0, others, last */
        if (!k)
            continue;
        n += snprintf(out + n, len - (size_t)n, "%s%" PRIu64 " %s", sep, k, type_names[t % 8]);
        sep = ", ";
        any = true;
    }
    if (!any)
        out[0] = '\0';
}

void canbus__sb_refused(canbus_bus_t *b, canbus_sbuf_t *s)
{
    canbus_sb_str(s, "[");
    bool first = b->refused.n == 0;
    if (!first)
        canbus_sb_mem(s, b->refused.p, b->refused.n);
    char detail[256];
    if (b->n_refused > REFUSED_LISTED_MAX) {
        snprintf(detail, sizeof detail, "%zu more refused hellos", b->n_refused - REFUSED_LISTED_MAX);
        sb_entry(s, first, detail);
        first = false;
    }
    for (int i = 0; i < b->next_index; i++) {
        const canbus_client_t *c = b->by_index[i];
        if (!c)
            continue;
        client_detail(c, detail, sizeof detail);
        if (detail[0]) {
            sb_entry(s, first, detail);
            first = false;
        }
    }
    canbus_sb_str(s, "]");
}
