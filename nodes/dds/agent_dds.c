/* SPDX-License-Identifier: Apache-2.0 */
/* The DDS side of the agent: participant, topics, QoS, listeners, peers' liveliness, samples. */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <inttypes.h>
#include <net/if.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "agent__agent.h"
#include "rpas.h"

const char *const agent_topic_name[T_COUNT] = {"rpas_CrossChannelInputs", "rpas_NodeHealth",
                                                 "rpas_Telemetry", "rpas_MissionData"};
static const dds_topic_descriptor_t *const topic_desc[T_COUNT] = {
    &rpas_CrossChannelInputs_desc, &rpas_NodeHealth_desc, &rpas_Telemetry_desc,
    &rpas_MissionData_desc};


/* ---- listeners: Cyclone's threads ------------------------------------------------------ */

void agent_wake(agent_t *a)
{
    if (!atomic_exchange(&a->wake_pending, true)) {
        char c = 1;
        if (write(a->wake_wr, &c, 1) < 0) {
            /* the pipe is full: the main thread is awake anyway */
        }
    }
}

static void push_event(agent_t *a, const agent_ev_t *ev)
{
    pthread_mutex_lock(&a->lock);
    if (a->ev_count < AGENT_EV_QUEUE) {
        a->evq[(a->ev_head + a->ev_count) % AGENT_EV_QUEUE] = *ev;
        a->ev_count++;
    } else {
        a->ev_dropped++;
    }
    pthread_mutex_unlock(&a->lock);
    agent_wake(a);
}

static void take_topic(agent_t *a, int t);

/* A peer's inputs: taken here, in Cyclone's receive thread, and the pending request answered
 * at once if they complete it. Other topics are the main thread's. */
static void on_data_available(dds_entity_t rd, void *arg)
{
    (void)rd;
    agent_rd_ctx_t *c = arg;
    agent_t *a = c->agent;
    if (c->topic != T_INPUTS) {
        agent_wake(a);
        return;
    }
    pthread_mutex_lock(&a->state);
    if (a->answer_in_listener) {
        take_topic(a, T_INPUTS);
        agent_io_check_pending(a, false);
    }
    pthread_mutex_unlock(&a->state);
}

/* Cyclone calls this once per match or unmatch (ddsperf relies on the same). */
static void on_subscription_matched(dds_entity_t rd, const dds_subscription_matched_status_t st,
                                    void *arg)
{
    (void)rd;
    agent_rd_ctx_t *c = arg;
    agent_ev_t ev = {.kind = EV_MATCHED, .topic = c->topic, .handle = st.last_publication_handle,
                     .change = st.current_count_change};
    push_event(c->agent, &ev);
}

static void on_liveliness_changed(dds_entity_t rd, const dds_liveliness_changed_status_t st,
                                  void *arg)
{
    (void)rd;
    agent_rd_ctx_t *c = arg;
    agent_ev_t ev = {.kind = EV_LIVELINESS, .topic = c->topic,
                     .handle = st.last_publication_handle, .change = st.alive_count_change,
                     .not_alive_change = st.not_alive_count_change};
    push_event(c->agent, &ev);
}

static void on_deadline_missed(dds_entity_t rd, const dds_requested_deadline_missed_status_t st,
                               void *arg)
{
    (void)rd;
    agent_rd_ctx_t *c = arg;
    agent_ev_t ev = {.kind = EV_DEADLINE, .topic = c->topic, .handle = st.last_instance_handle,
                     .change = st.total_count_change};
    push_event(c->agent, &ev);
}

/* ---- entities -------------------------------------------------------------------------- */

static dds_qos_t *endpoint_qos(const agent_t *a, int topic, bool writer)
{
    dds_qos_t *q = dds_create_qos();
    int32_t depth = topic == T_INPUTS ? 32 : 4;
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
    /* A reader that matches late (an agent slower to start, the listener tool) still gets the
     * writer's last samples, as many as the history holds (Cyclone keeps what the durability
     * service's history says, by default only the last): the first exchange does not depend
     * on discovery order. */
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    if (writer)
        dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, depth, DDS_LENGTH_UNLIMITED,
                                    DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
    dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, a->o.lease_ns);
    if (topic == T_HEALTH)
        dds_qset_deadline(q, a->o.deadline_ns);
    if (writer) {
        /* Deleting a writer (the agent exits or dies) leaves its instance "no writers", which
         * readers take as the node's loss; disposal is kept for "io link down". */
        dds_qset_writer_data_lifecycle(q, false);
    } else {
        dds_qset_ignorelocal(q, DDS_IGNORELOCAL_PARTICIPANT);
    }
    return q;
}

/* The publisher writes in this node's partition, the subscriber reads every node's. */
static int create_pub_sub(agent_t *a)
{
    char own[24], names[XCH_MAX_NODES][24];
    const char *all[XCH_MAX_NODES];
    snprintf(own, sizeof own, AGENT_PARTITION_FMT, a->o.node);
    for (unsigned k = 1; k <= a->o.nodes; k++) {
        snprintf(names[k - 1], sizeof names[k - 1], AGENT_PARTITION_FMT, k);
        all[k - 1] = names[k - 1];
    }
    dds_qos_t *q = dds_create_qos();
    dds_qset_partition1(q, own);
    a->pub = dds_create_publisher(a->pp, q, NULL);
    dds_qset_partition(q, a->o.nodes, all);
    a->sub = dds_create_subscriber(a->pp, q, NULL);
    dds_delete_qos(q);
    if (a->pub < 0 || a->sub < 0) {
        fprintf(stderr, "ima-dds-node %s: cannot create the publisher or subscriber: %s\n",
                a->node_name, dds_strretcode(a->pub < 0 ? a->pub : a->sub));
        return -1;
    }
    return 0;
}

int agent_dds_start(agent_t *a)
{
    dds_qos_t *pq = agent_security_qos(a);
    if (!pq)
        return -1;
    a->pp = dds_create_participant((dds_domainid_t)a->o.domain, pq, NULL);
    dds_delete_qos(pq);
    if (a->pp < 0) {
        fprintf(stderr, "ima-dds-node %s: cannot create the DDS participant on domain %u%s: %s\n",
                a->node_name, a->o.domain, a->o.security_dir ? " with DDS Security" : "",
                dds_strretcode(a->pp));
        return -1;
    }
    if (create_pub_sub(a) != 0)
        return -1;
    for (int t = 0; t < T_COUNT; t++) {
        a->tp[t] = dds_create_topic(a->pp, topic_desc[t], agent_topic_name[t], NULL, NULL);
        if (a->tp[t] < 0) {
            fprintf(stderr, "ima-dds-node %s: cannot create topic %s: %s\n", a->node_name,
                    agent_topic_name[t], dds_strretcode(a->tp[t]));
            return -1;
        }
    }
    for (int t = 0; t < T_COUNT; t++) {
        a->rd[t] = 0;
        if (!agent_reads_topic(t))
            continue; /* no reader: the peers' samples of it are not even sent here */
        a->rd_ctx[t] = (agent_rd_ctx_t){a, t};
        dds_listener_t *l = dds_create_listener(&a->rd_ctx[t]);
        dds_lset_data_available(l, on_data_available);
        dds_lset_subscription_matched(l, on_subscription_matched);
        if (t == T_INPUTS)
            dds_lset_liveliness_changed(l, on_liveliness_changed);
        if (t == T_HEALTH)
            dds_lset_requested_deadline_missed(l, on_deadline_missed);
        dds_qos_t *q = endpoint_qos(a, t, false);
        a->rd[t] = dds_create_reader(a->sub, a->tp[t], q, l);
        dds_delete_qos(q);
        dds_delete_listener(l);
        if (a->rd[t] < 0) {
            fprintf(stderr, "ima-dds-node %s: cannot create the %s reader: %s\n", a->node_name,
                    agent_topic_name[t], dds_strretcode(a->rd[t]));
            return -1;
        }
    }
    for (int t = 0; t < T_COUNT; t++) {
        dds_qos_t *q = endpoint_qos(a, t, true);
        a->wr[t] = dds_create_writer(a->pub, a->tp[t], q, NULL);
        dds_delete_qos(q);
        if (a->wr[t] < 0) {
            fprintf(stderr, "ima-dds-node %s: cannot create the %s writer: %s\n", a->node_name,
                    agent_topic_name[t], dds_strretcode(a->wr[t]));
            return -1;
        }
    }
    dds_qos_t *q = dds_create_qos();
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    a->rd_participants = dds_create_reader(a->pp, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, q, NULL);
    dds_delete_qos(q);
    if (a->rd_participants < 0)
        agent_log(a, "cannot read the participants' built-in topic: %s; intruders go unlisted",
                  dds_strretcode(a->rd_participants));
    a->bound_sockets = agent_dds_bind_sockets(a);
    return 0;
}

void agent_dds_stop(agent_t *a)
{
    if (a->pp > 0)
        dds_delete(a->pp); /* readers and writers with it: peers see this node's writers go */
    a->pp = 0;
}

/* Cyclone 0.10 binds its unicast receive sockets to INADDR_ANY whatever the configured
 * interface (only the transmit socket gets the interface address). Binding every one of this
 * process's IP sockets to the configured device makes the kernel deliver to them only what
 * came in on that device, and send from them only through it. Returns the count bound. */
unsigned agent_dds_bind_sockets(agent_t *a)
{
    const char *dev = a->o.bind_device;
    if (!dev || !*dev)
        return 0;
    DIR *d = opendir("/proc/self/fd");
    if (!d) {
        agent_log(a, "cannot list /proc/self/fd: %s; DDS sockets left as they are",
                  strerror(errno));
        return 0;
    }
    unsigned bound = 0;
    int dfd = dirfd(d);
    struct dirent *e;
    while ((e = readdir(d))) {
        char *end;
        long fd = strtol(e->d_name, &end, 10);
        if (*end || end == e->d_name || fd == dfd)
            continue;
        int domain = 0;
        socklen_t len = sizeof domain;
        if (getsockopt((int)fd, SOL_SOCKET, SO_DOMAIN, &domain, &len) != 0)
            continue; /* not a socket */
        if (domain != AF_INET && domain != AF_INET6)
            continue;
        char cur[IFNAMSIZ] = "";
        len = sizeof cur;
        if (getsockopt((int)fd, SOL_SOCKET, SO_BINDTODEVICE, cur, &len) == 0 && cur[0]) {
            if (strcmp(cur, dev) == 0)
                bound++;
            else
                agent_log(a, "DDS socket %ld is bound to device %s, not %s", fd, cur, dev);
            continue;
        }
        if (setsockopt((int)fd, SOL_SOCKET, SO_BINDTODEVICE, dev, (socklen_t)strlen(dev) + 1) !=
            0) {
            agent_log(a, "cannot bind DDS socket %ld to %s: %s", fd, dev, strerror(errno));
            continue;
        }
        bound++;
    }
    closedir(d);
    return bound;
}

/* ---- peers ----------------------------------------------------------------------------- */

/* Told to stop: SIGINT or SIGTERM read, or waiting to be (blocked in every thread, it stays
 * pending for the main thread's signalfd; a listener may run first). */
static bool stopping(const agent_t *a)
{
    sigset_t pending;
    return a->stop || (sigpending(&pending) == 0 &&
                       (sigismember(&pending, SIGTERM) == 1 || sigismember(&pending, SIGINT) == 1));
}

/* Latches peer k dead (true), unless it is already or this agent is stopping (false). */
static bool peer_lost(agent_t *a, unsigned k, const char *reason)
{
    if (k < 1 || k > a->o.nodes || k == a->o.node)
        return false;
    agent_peer_t *p = &a->peer[k - 1];
    bool was_alive = p->alive;
    p->alive = false;
    if (p->dead)
        return false;
    if (stopping(a)) {
        /* The run is ending: the launcher stops every agent at once (their SIGTERMs all
         * pending before any runs on), and a peer's agent may be gone before this one. That
         * is the end, not a loss: nothing is latched, and it is traced once per peer. */
        if (!p->left && agent_trace_begin(a, "dds_peer_left")) {
            fprintf(a->trace, ",\"peer\":\"node%u\",\"reason\":\"%s\"", k, reason);
            agent_trace_end(a);
        }
        p->left = true;
        return false;
    }
    p->dead = true;
    p->lost_wall_ns = agent_wall_ns();
    agree_set_dead(&a->agree, k);
    if (agent_trace_begin(a, "dds_peer_lost")) {
        fprintf(a->trace, ",\"peer\":\"node%u\",\"reason\":\"%s\",\"was_alive\":%s", k, reason,
                was_alive ? "true" : "false");
        agent_trace_end(a);
    }
    agent_log(a, "node%u lost on DDS (%s): no longer waited for", k, reason);
    return true;
}

/* A hung processor: its agent lives on (its DDS liveliness holds) but its partitions are
 * frozen, so it publishes nothing. A peer this agent has waited for a whole lease period,
 * which has published nothing in that time and whose NodeHealth deadline was missed, is
 * latched dead like a lost one: the live nodes go on without it. */
bool agent_dds_declare_hung(agent_t *a, uint32_t missing)
{
    int64_t now = agent_mono_ns();
    bool any = false;
    for (unsigned k = 1; k <= a->o.nodes; k++) {
        agent_peer_t *p = &a->peer[k - 1];
        if (!(missing & (1u << (k - 1))) || p->dead || !p->deadline_missed)
            continue;
        int64_t since = p->last_rx_ns > a->pend_start_ns ? p->last_rx_ns : a->pend_start_ns;
        if (now - since < a->o.lease_ns)
            continue;
        any |= peer_lost(a, k, "hung");
    }
    return any;
}

static void peer_alive(agent_t *a, unsigned k)
{
    if (k < 1 || k > a->o.nodes || k == a->o.node)
        return;
    agent_peer_t *p = &a->peer[k - 1];
    if (p->alive)
        return;
    p->alive = true;
    if (agent_trace_begin(a, "dds_peer_alive")) {
        fprintf(a->trace, ",\"peer\":\"node%u\"", k);
        if (p->dead)
            fputs(",\"ignored\":\"latched dead for the run\"", a->trace);
        agent_trace_end(a);
    }
}

/* A node's writers come and go one by one: another participant writing in the node's
 * partition (a second holder of its identity) leaving must not make the node lost while its
 * agent's writer stays. */
static void handle_matched(agent_t *a, const agent_ev_t *ev)
{
    if (ev->change > 0) {
        agent_writer_t *w = agent_writer_of(a, ev->topic, ev->handle);
        if (!w)
            return;
        w->matched = true;
        unsigned k = w->node;
        if (k && k != a->o.node) {
            a->peer[k - 1].matched[ev->topic] = true;
            if (ev->topic == T_INPUTS)
                a->peer[k - 1].discovered = true;
        }
        return;
    }
    if (ev->change < 0) {
        agent_writer_t *w = agent_writer_find(a, ev->topic, ev->handle);
        if (!w)
            return;
        w->matched = false;
        w->alive = false;
        unsigned k = w->node;
        if (k && k != a->o.node && !agent_node_has_writer(a, ev->topic, k, false, w)) {
            a->peer[k - 1].matched[ev->topic] = false;
            if (ev->topic == T_INPUTS)
                peer_lost(a, k, "unmatched");
        }
    }
}

static void handle_liveliness(agent_t *a, const agent_ev_t *ev)
{
    agent_writer_t *w = agent_writer_of(a, ev->topic, ev->handle);
    if (!w || !w->node || w->node == a->o.node)
        return;
    unsigned k = w->node;
    if (ev->change > 0) {
        w->alive = true;
        peer_alive(a, k);
    } else if (ev->change < 0) {
        w->alive = false;
        if (!agent_node_has_writer(a, ev->topic, k, true, w))
            peer_lost(a, k, ev->not_alive_change > 0 ? "liveliness" : "writer_gone");
    }
}

static void handle_deadline(agent_t *a, const agent_ev_t *ev)
{
    rpas_NodeHealth key;
    memset(&key, 0, sizeof key);
    if (dds_instance_get_key(a->rd[T_HEALTH], ev->handle, &key) != DDS_RETCODE_OK)
        return;
    unsigned k = key.node;
    if (k < 1 || k > a->o.nodes || k == a->o.node)
        return;
    agent_peer_t *p = &a->peer[k - 1];
    /* A node's io gives its health when it changes and once a second, its inputs every
     * frame: the node missed the deadline only if nothing at all came from it within it. */
    if (p->heard && agent_mono_ns() - p->last_rx_ns < a->o.deadline_ns) {
        a->deadline_covered++;
        return;
    }
    /* In lockstep, the deadline (wall time) says something of the peer only while this node
     * flies: when its io waits for a frame's agreement, or has asked for two frames or more
     * since the peer was last heard. Otherwise the whole system is paused (the bus stopped
     * at the end of the run, the host stalled), not the peer. */
    if (!a->o.realtime && !a->pending &&
        (!a->have_frame || !p->heard || (int32_t)(a->pend_frame - p->heard_own_frame) < 2)) {
        a->deadline_paused++;
        return;
    }
    p->deadline_misses += ev->change > 0 ? (uint64_t)ev->change : 1;
    if (p->deadline_missed)
        return; /* one line per episode: until the node publishes its health again */
    p->deadline_missed = true;
    if (agent_trace_begin(a, "dds_deadline_missed")) {
        fprintf(a->trace, ",\"peer\":\"node%u\",\"topic\":\"rpas_NodeHealth\",\"deadline_ms\":%.1f",
                k, a->o.deadline_ns / 1e6);
        agent_trace_end(a);
    }
}

void agent_dds_process_events(agent_t *a)
{
    for (;;) {
        agent_ev_t ev;
        pthread_mutex_lock(&a->lock);
        bool have = a->ev_count > 0;
        if (have) {
            ev = a->evq[a->ev_head];
            a->ev_head = (a->ev_head + 1) % AGENT_EV_QUEUE;
            a->ev_count--;
        }
        pthread_mutex_unlock(&a->lock);
        if (!have)
            return;
        switch (ev.kind) {
        case EV_MATCHED:
            handle_matched(a, &ev);
            break;
        case EV_LIVELINESS:
            handle_liveliness(a, &ev);
            break;
        case EV_DEADLINE:
            handle_deadline(a, &ev);
            break;
        }
    }
}

bool agent_dds_discovery_complete(agent_t *a, uint32_t *missing)
{
    uint32_t m = 0;
    for (unsigned k = 1; k <= a->o.nodes; k++) {
        if (k == a->o.node)
            continue;
        for (int t = 0; t < T_COUNT; t++)
            if (agent_reads_topic(t) && !a->peer[k - 1].matched[t])
                m |= 1u << (k - 1);
    }
    if (missing)
        *missing = m;
    return m == 0;
}

/* ---- samples --------------------------------------------------------------------------- */

static void inputs_from_dds(struct xch_inputs *x, const rpas_CrossChannelInputs *s)
{
    memset(x, 0, sizeof *x);
    x->valid = s->valid;
    x->wait_mask = s->wait_mask;
    x->gps_t_ns = s->gps_t_ns;
    x->ahrs_t_ns = s->ahrs_t_ns;
    x->air_t_ns = s->air_t_ns;
    x->gps_seq = s->gps_seq;
    x->gps_fix = s->gps_fix;
    x->gps_sats = s->gps_sats;
    x->ahrs_seq = s->ahrs_seq;
    x->ahrs_status = s->ahrs_status;
    x->air_seq = s->air_seq;
    x->air_status = s->air_status;
    x->plan_crc = s->plan_crc;
    memcpy(x->gps, s->gps, sizeof x->gps);
    memcpy(x->ahrs, s->ahrs, sizeof x->ahrs);
    memcpy(x->air, s->air, sizeof x->air);
}

static void inputs_to_dds(rpas_CrossChannelInputs *s, const struct xch_inputs *x)
{
    s->valid = x->valid;
    s->wait_mask = x->wait_mask;
    s->gps_t_ns = x->gps_t_ns;
    s->ahrs_t_ns = x->ahrs_t_ns;
    s->air_t_ns = x->air_t_ns;
    s->gps_seq = x->gps_seq;
    s->gps_fix = x->gps_fix;
    s->gps_sats = x->gps_sats;
    s->ahrs_seq = x->ahrs_seq;
    s->ahrs_status = x->ahrs_status;
    s->air_seq = x->air_seq;
    s->air_status = x->air_status;
    s->plan_crc = x->plan_crc;
    memcpy(s->gps, x->gps, sizeof s->gps);
    memcpy(s->ahrs, x->ahrs, sizeof s->ahrs);
    memcpy(s->air, x->air, sizeof s->air);
}

#define TAKE_MAX 32

bool agent_reads_topic(int topic)
{
    /* The cross-channel exchange and node health; telemetry and mission data are for the
     * ground (a listener, a station), not for the other nodes. */
    return topic == T_INPUTS || topic == T_HEALTH;
}

static void take_topic(agent_t *a, int t)
{
    static union {
        rpas_CrossChannelInputs in;
        rpas_NodeHealth h;
        rpas_Telemetry tm;
        rpas_MissionData m;
    } buf[TAKE_MAX];
    void *ptrs[TAKE_MAX];
    dds_sample_info_t si[TAKE_MAX];
    for (int i = 0; i < TAKE_MAX; i++)
        ptrs[i] = &buf[i];
    while (a->rd[t] > 0) {
        int32_t n = dds_take(a->rd[t], ptrs, si, TAKE_MAX, TAKE_MAX);
        if (n <= 0)
            return;
        for (int32_t i = 0; i < n; i++) {
            /* every topic type starts with the node key */
            unsigned k = *(const uint32_t *)ptrs[i];
            if (!si[i].valid_data) {
                a->ts[t].invalid++;
                if (t != T_INPUTS)
                    continue;
                rpas_CrossChannelInputs key;
                memset(&key, 0, sizeof key);
                if (dds_instance_get_key(a->rd[t], si[i].instance_handle, &key) == 0)
                    k = key.node;
                if (k < 1 || k > a->o.nodes || k == a->o.node)
                    continue;
                /* a disposal comes from one writer: it must be the node's own */
                if (si[i].instance_state == DDS_IST_NOT_ALIVE_DISPOSED &&
                    !agent_from_node(a, t, si[i].publication_handle, k))
                    continue;
                if (si[i].instance_state == DDS_IST_NOT_ALIVE_NO_WRITERS) {
                    peer_lost(a, k, "no_writers");
                } else if (si[i].instance_state == DDS_IST_NOT_ALIVE_DISPOSED) {
                    agree_set_withdrawn(&a->agree, k);
                    if (agent_trace_begin(a, "xch_peer_withdrawn")) {
                        fprintf(a->trace, ",\"peer\":\"node%u\"", k);
                        agent_trace_end(a);
                    }
                }
                continue;
            }
            if (!agent_from_node(a, t, si[i].publication_handle, k))
                continue;
            if (k == a->o.node) {
                a->ts[t].invalid++; /* this node's key from another writer of its partition */
                continue;
            }
            a->ts[t].read++;
            a->peer[k - 1].last_rx_ns = agent_mono_ns();
            a->peer[k - 1].heard = true;
            a->peer[k - 1].heard_own_frame = a->pend_frame;
            if (t == T_INPUTS) {
                /* Cyclone stamps the sample in dds_write with the writer's clock, this
                 * machine's as well: the one-way latency of DDS between the two nodes. Not
                 * before discovery is over: a late joiner receives history. */
                if (a->ready)
                    agent_lat_add(&a->dds_lat, dds_time() - si[i].source_timestamp);
                struct xch_inputs x;
                inputs_from_dds(&x, &buf[i].in);
                if (x.wait_mask & AGREE_LOST_MARK) { /* a fault keeps that frame back */
                    if (agree_store_lost(&a->agree, k, buf[i].in.frame, buf[i].in.t_ns) &&
                        agent_trace_begin_at(a, "xch_peer_missing", buf[i].in.t_ns)) {
                        fprintf(a->trace, ",\"peer\":\"node%u\",\"frame\":%" PRIu32, k,
                                buf[i].in.frame);
                        agent_trace_end(a);
                    }
                } else
                    agree_store(&a->agree, k, buf[i].in.frame, buf[i].in.t_ns, &x);
            } else if (t == T_HEALTH) {
                a->peer[k - 1].deadline_missed = false; /* the episode is over */
            }
        }
    }
}

void agent_dds_take_all(agent_t *a)
{
    for (int t = 0; t < T_COUNT; t++)
        take_topic(a, t);
}

int agent_dds_publish(agent_t *a, int topic, const struct xch_hdr *h, const void *payload)
{
    union {
        rpas_CrossChannelInputs in;
        rpas_NodeHealth h;
        rpas_Telemetry tm;
        rpas_MissionData m;
    } s;
    memset(&s, 0, sizeof s);
    switch (topic) {
    case T_INPUTS: {
        inputs_to_dds(&s.in, payload);
        s.in.node = a->o.node;
        s.in.frame = h->frame;
        s.in.t_ns = h->t_ns;
        break;
    }
    case T_HEALTH: {
        const struct xch_health *x = payload;
        s.h = (rpas_NodeHealth){.node = a->o.node, .frame = h->frame, .t_ns = h->t_ns,
                                .membership = x->membership, .flags = x->flags,
                                .fcs_mode = x->fcs_mode, .failed = x->failed};
        break;
    }
    case T_TELEMETRY: {
        const struct xch_telemetry *x = payload;
        s.tm = (rpas_Telemetry){.node = a->o.node, .frame = h->frame, .t_ns = h->t_ns,
                                .fcs_mode = x->fcs_mode, .fallback = x->fallback,
                                .nav_flags = x->nav_flags, .lat_deg = x->lat_deg,
                                .lon_deg = x->lon_deg, .alt_ft = x->alt_ft, .ias_kt = x->ias_kt,
                                .gs_kt = x->gs_kt, .hdg_deg = x->hdg_deg, .trk_deg = x->trk_deg,
                                .vs_fpm = x->vs_fpm, .roll_deg = x->roll_deg,
                                .pitch_deg = x->pitch_deg};
        memcpy(s.tm.cmd, x->cmd, sizeof s.tm.cmd);
        break;
    }
    case T_MISSION: {
        const struct xch_mission *x = payload;
        s.m = (rpas_MissionData){.node = a->o.node, .frame = h->frame, .t_ns = h->t_ns,
                                 .mode = x->mode, .lat_mode = x->lat_mode,
                                 .vert_mode = x->vert_mode, .hdg_deg = x->hdg_deg,
                                 .alt_ft = x->alt_ft, .ias_kt = x->ias_kt, .vs_fpm = x->vs_fpm};
        break;
    }
    default:
        return -1;
    }
    dds_return_t rc = dds_write(a->wr[topic], &s);
    if (rc != DDS_RETCODE_OK) {
        a->ts[topic].write_errors++;
        agent_log(a, "writing %s failed: %s", agent_topic_name[topic], dds_strretcode(rc));
        return -1;
    }
    a->ts[topic].written++;
    if (topic == T_INPUTS)
        a->own_instance = true;
    return 0;
}

/* The io link is down: dispose this node's inputs instance, so that the other nodes stop
 * waiting for frames it will not publish (agent__agree.h). */
void agent_dds_withdraw(agent_t *a)
{
    if (!a->own_instance)
        return;
    rpas_CrossChannelInputs key;
    memset(&key, 0, sizeof key);
    key.node = a->o.node;
    if (dds_dispose(a->wr[T_INPUTS], &key) != DDS_RETCODE_OK)
        a->ts[T_INPUTS].write_errors++;
    a->own_instance = false;
}
