/* SPDX-License-Identifier: Apache-2.0 */
/* The agent's view of the other participants: which node each remote writer speaks for (the
 * DDS partition it writes in), the samples refused because their key names another node, and
 * the participants of the domain that are no node's agent (docs/security.md).
 *
 * Node K's agent publishes in the DDS partition "nodeK" and reads in every node's: a reader
 * tells which node a writer publishes for by its partition, never by what it writes (a key,
 * USER_DATA). With DDS Security on, the run's permissions let only node K's identity write
 * in "nodeK" (python/ima/dds/security.py). */
#include <ctype.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "agent__agent.h"

agent_writer_t *agent_writer_find(agent_t *a, int topic, dds_instance_handle_t h)
{
    for (int i = 0; i < a->n_writers; i++)
        if (a->writers[i].handle == h && a->writers[i].topic == topic)
            return &a->writers[i];
    return NULL;
}

static agent_writer_t *writer_add(agent_t *a, int topic, dds_instance_handle_t h)
{
    agent_writer_t *w = agent_writer_find(a, topic, h);
    if (w)
        return w;
    if (a->n_writers == AGENT_MAX_WRITERS) {
        /* forget an unmatched one that refused nothing (the others are for the report) */
        for (int i = 0; i < a->n_writers; i++)
            if (!a->writers[i].matched && !a->writers[i].refused) {
                a->writers[i] = a->writers[--a->n_writers];
                break;
            }
        if (a->n_writers == AGENT_MAX_WRITERS)
            return NULL;
    }
    w = &a->writers[a->n_writers++];
    *w = (agent_writer_t){.handle = h, .topic = topic};
    return w;
}

/* The node whose partition ("nodeK", and no other) a matched writer writes in; 0 if none. */
static unsigned partition_node(agent_t *a, const dds_qos_t *q, char *name, size_t len)
{
    uint32_t n = 0;
    char **ps = NULL;
    unsigned node = 0;
    name[0] = 0;
    if (q && dds_qget_partition(q, &n, &ps)) {
        if (n == 1 && ps[0]) {
            unsigned k;
            char extra;
            if (sscanf(ps[0], AGENT_PARTITION_FMT "%c", &k, &extra) == 1 && k >= 1 && k <= a->o.nodes)
                node = k;
            /* kept for the report, in JSON-safe characters */
            snprintf(name, len, "%s", ps[0]);
            for (char *c = name; *c; c++)
                if (!(isalnum((unsigned char)*c) || strchr("_-.*?", *c)))
                    *c = '?';
        }
        for (uint32_t i = 0; i < n; i++)
            dds_free(ps[i]);
        dds_free(ps);
    }
    return node;
}

/* The writer of handle on topic, looked up once while it is matched; NULL if unknown. */
agent_writer_t *agent_writer_of(agent_t *a, int topic, dds_instance_handle_t h)
{
    agent_writer_t *w = agent_writer_find(a, topic, h);
    if (w && w->known)
        return w;
    dds_builtintopic_endpoint_t *ep = dds_get_matched_publication_data(a->rd[topic], h);
    if (!ep)
        return w;
    if (!w)
        w = writer_add(a, topic, h);
    if (w) {
        w->known = true;
        w->node = partition_node(a, ep->qos, w->partition, sizeof w->partition);
        memcpy(&w->participant, &ep->participant_key, sizeof w->participant);
    }
    dds_builtintopic_free_endpoint(ep);
    return w;
}

/* Whether node k has a writer of topic matched (alive, if `alive`) other than `except`. */
bool agent_node_has_writer(agent_t *a, int topic, unsigned k, bool alive,
                            const agent_writer_t *except)
{
    for (int i = 0; i < a->n_writers; i++) {
        const agent_writer_t *w = &a->writers[i];
        if (w != except && w->topic == topic && w->node == k && w->matched &&
            (!alive || w->alive))
            return true;
    }
    return false;
}

/* Whether a sample keyed as node k comes from a writer in node k's partition. If not it is
 * refused: counted on its writer (reported in the statistics) and traced at its first. */
bool agent_from_node(agent_t *a, int t, dds_instance_handle_t h, unsigned k)
{
    agent_writer_t *w = agent_writer_of(a, t, h);
    if (w && w->node && w->node == k)
        return true;
    a->refused_samples++;
    if (!w)
        return false; /* forgotten (the table is full of refusing writers): counted only */
    w->claimed = k;
    if (w->refused++ == 0 && agent_trace_begin(a, "dds_refused")) {
        fprintf(a->trace, ",\"topic\":\"%s\",\"partition\":\"%s\",\"claimed_node\":%u",
                agent_topic_name[t], w->partition, k);
        agent_trace_end(a);
    }
    return false;
}

/* Whether a participant is this node's or another node's agent: one of its writers is in a
 * node's partition and had nothing refused. */
static bool is_agent(const agent_t *a, const dds_guid_t *g, bool *refused)
{
    bool agent = false;
    *refused = false;
    for (int i = 0; i < a->n_writers; i++) {
        const agent_writer_t *w = &a->writers[i];
        if (memcmp(&w->participant, g, sizeof *g) != 0)
            continue;
        if (w->refused)
            *refused = true;
        else if (w->node)
            agent = true;
    }
    return agent && !*refused;
}

static void json_safe(char *dst, size_t len, const char *src)
{
    snprintf(dst, len, "%s", src ? src : "");
    for (char *c = dst; *c; c++)
        if (!(isalnum((unsigned char)*c) || strchr("_-./ ", *c)))
            *c = '?';
}

void agent_dds_census(agent_t *a)
{
    if (a->rd_participants <= 0)
        return;
    dds_guid_t own;
    if (dds_get_guid(a->pp, &own) != DDS_RETCODE_OK)
        memset(&own, 0, sizeof own);
    void *ptrs[64] = {NULL};
    dds_sample_info_t si[64];
    int32_t n = dds_read(a->rd_participants, ptrs, si, 64, 64);
    for (int32_t i = 0; i < n; i++) {
        const dds_builtintopic_participant_t *p = ptrs[i];
        bool refused;
        if (!si[i].valid_data || !memcmp(&p->key, &own, sizeof own) ||
            is_agent(a, &p->key, &refused) || a->n_foreign == AGENT_MAX_FOREIGN)
            continue;
        agent_foreign_t *f = &a->foreign[a->n_foreign++];
        memset(f, 0, sizeof *f);
        f->guid = p->key;
        f->refused = refused;
        char *v = NULL;
        if (p->qos && dds_qget_prop(p->qos, "__ProcessName", &v)) {
            json_safe(f->process, sizeof f->process, v);
            dds_free(v);
        }
        if (p->qos && dds_qget_prop(p->qos, "__Pid", &v)) {
            f->pid = strtol(v, NULL, 10);
            dds_free(v);
        }
    }
    if (n > 0)
        dds_return_loan(a->rd_participants, ptrs, n);
}
