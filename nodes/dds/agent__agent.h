/* SPDX-License-Identifier: Apache-2.0 */
/* The DDS agent's state, shared by its parts: DDS side (agent_dds.c), io link (agent_io.c),
 * trace and statistics (agent_out.c) and the main loop (agent.c).
 *
 * Threads: the main thread serves the io link, the signals and the events the listeners queue.
 * Cyclone calls the listeners on its own threads. The one on the cross-channel inputs reader
 * takes the samples and answers a pending request itself, in Cyclone's receive thread, so
 * that a peer's inputs reach io without waking the main thread first (the exchange's latency
 * is a frame budget in real time). Every other listener only queues an event or wakes the
 * main thread through a pipe. The agent's state (the exchange, the peers, the io socket, the
 * trace, the statistics) is guarded by `state`: the main thread holds it except while it
 * waits in ppoll, the inputs listener while it runs. */
#ifndef AGENT__AGENT_H
#define AGENT__AGENT_H

#include <dds/dds.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "agent__agree.h"
#include "agent__fault.h"
#include "xch/proto.h"

enum { T_INPUTS, T_HEALTH, T_TELEMETRY, T_MISSION, T_COUNT };

typedef struct {
    unsigned node, nodes;
    const char *socket_path;
    uint32_t domain;
    const char *config;        /* resolved path of the Cyclone configuration */
    bool realtime;
    int64_t xch_timeout_ns;    /* real time: longest wait for an AGREED */
    int64_t lease_ns;          /* liveliness lease */
    int64_t deadline_ns;       /* NodeHealth deadline */
    int64_t startup_timeout_ns;/* how long to wait for the other agents at startup */
    const char *bind_device;   /* interface the DDS sockets are bound to ("" = leave them) */
    const char *security_dir;  /* the run's DDS Security files (NULL: no security) */
    const char *trace_path, *stats_path;
    bool quiet;
    int ske_pid_fd;            /* --ske-pid-fd: where the launcher writes the SKE's pid, or -1 */
} agent_opts_t;

/* What a Cyclone listener tells the main thread. */
typedef enum { EV_MATCHED, EV_LIVELINESS, EV_DEADLINE } agent_ev_kind_t;

typedef struct {
    agent_ev_kind_t kind;
    int topic;
    dds_instance_handle_t handle; /* publication (MATCHED, LIVELINESS) or instance (DEADLINE) */
    int32_t change;               /* current/alive count change; DEADLINE: count change */
    int32_t not_alive_change;
} agent_ev_t;

#define AGENT_EV_QUEUE 1024
#define AGENT_MAX_WRITERS 64 /* remote writers remembered (handle -> node) */

/* A remote writer, and the node it publishes for: the one whose DDS partition it writes in
 * (only node K's identity may write in partition "nodeK" when security is on). */
typedef struct {
    dds_instance_handle_t handle;
    int topic;
    unsigned node;       /* 0 unknown (not in one node's partition of this run) */
    bool known;          /* its partition was looked up */
    bool matched, alive;
    uint64_t refused;    /* samples it wrote under another node's key, or outside the nodes */
    unsigned claimed;    /* the node key of the latest one */
    char partition[24];  /* for the report ("" when it writes in several or none) */
    dds_guid_t participant;
} agent_writer_t;

/* A participant of the run's domain that is neither this agent nor another node's agent
 * (agent_dds_census): a tool, or an intruder. */
#define AGENT_MAX_FOREIGN 16
typedef struct {
    dds_guid_t guid;
    char process[32];  /* its __ProcessName property, JSON-safe ("" unknown) */
    long pid;          /* its __Pid property (0 unknown) */
    bool refused;      /* it wrote samples this agent refused */
} agent_foreign_t;

typedef struct {
    bool discovered;     /* its inputs writer was matched at least once */
    bool matched[T_COUNT];
    bool alive;          /* its inputs writer is alive on DDS */
    bool dead;           /* latched */
    bool left;           /* gone once this agent was told to stop (traced once) */
    bool deadline_missed;/* a NodeHealth deadline miss traced, no sample since */
    int64_t last_rx_ns;  /* CLOCK_MONOTONIC of its latest sample taken, any topic */
    bool heard;          /* a sample of it has come, any topic */
    uint32_t heard_own_frame; /* this node's latest frame when the last one came */
    int64_t lost_wall_ns;
    uint64_t deadline_misses;
} agent_peer_t;

typedef struct {
    uint64_t written, read, invalid, write_errors;
} agent_topic_stats_t;

/* A series of latency samples, in ns (the first AGENT_LAT_MAX kept). */
#define AGENT_LAT_MAX (1u << 20)

typedef struct {
    uint32_t *ns;
    uint32_t n;
} agent_lat_t;

typedef struct agent agent_t;

/* A publication a dds_delay fault holds back until io hands over frame `release`. */
typedef struct {
    int topic; /* T_INPUTS or T_HEALTH */
    uint32_t release;
    struct xch_hdr h;
    union {
        struct xch_inputs in;
        struct xch_health health;
    } p;
} agent_held_t;

#define AGENT_HELD_MAX 128 /* two topics x DDS_DELAY_MAX_FRAMES, and room */

typedef struct {
    agent_t *agent;
    int topic;
} agent_rd_ctx_t;

/* An entry of the statistics' `refusals` list: what was refused ("io_client", ...), and how. */
typedef struct {
    char what[24];
    char detail[200];
} agent_refused_t;

#define AGENT_REFUSED_MAX 32 /* listed; later ones only counted */

struct agent {
    agent_opts_t o;
    char node_name[16];

    /* DDS */
    dds_entity_t pp, pub, sub, tp[T_COUNT], rd[T_COUNT], wr[T_COUNT];
    dds_entity_t rd_participants; /* the built-in topic: who else joined the domain */
    agent_foreign_t foreign[AGENT_MAX_FOREIGN];
    int n_foreign;
    agent_rd_ctx_t rd_ctx[T_COUNT];
    agent_writer_t writers[AGENT_MAX_WRITERS];
    int n_writers;
    unsigned bound_sockets;    /* UDP sockets bound to opts.bind_device */

    /* guards everything below but the event queue (see the top of this file) */
    pthread_mutex_t state;
    bool answer_in_listener;   /* false from the shutdown on: the listener touches nothing */

    /* listener -> main thread */
    pthread_mutex_t lock;
    agent_ev_t evq[AGENT_EV_QUEUE];
    unsigned ev_head, ev_count;
    uint64_t ev_dropped;
    atomic_bool wake_pending;
    int wake_rd, wake_wr;
    int sig_fd;
    bool stop;

    /* io link */
    int listen_fd, io_fd;
    int io_next_fd;            /* a partition of the SKE that connected while io_fd was up */
    bool io_hello;             /* HELLO received on io_fd */
    uint64_t io_connections, io_disconnects, io_refused;
    pid_t ske_pid;             /* --ske-pid-fd: the node's SKE; 0 not known yet, -1 none */
    agent_refused_t refused[AGENT_REFUSED_MAX];
    unsigned n_refused;
    uint64_t refusals_unlisted;
    bool own_instance;         /* our CrossChannelInputs instance is registered (not disposed) */

    /* the exchange */
    agree_t agree;
    agent_peer_t peer[XCH_MAX_NODES];
    bool pending;
    uint32_t pend_frame, pend_mask;
    int64_t pend_t_ns;
    int64_t pend_start_ns;     /* CLOCK_MONOTONIC of the request */
    bool pend_waited;
    int64_t last_t_ns;         /* emulated time of the latest request (for the trace) */
    bool have_frame;           /* io has asked for a frame: pend_frame is its latest */

    /* faults (agent_fault.c): this node's publications they keep back */
    dds_faults_t faults;
    agent_held_t held[AGENT_HELD_MAX]; /* a ring, in the order io handed them over */
    unsigned held_head, held_n;
    uint64_t withheld, published_late;

    /* statistics */
    agent_topic_stats_t ts[T_COUNT];
    uint64_t agreed, waits, timeouts, superseded, bad_datagrams, partial;
    uint64_t refused_samples;  /* from writers that are not the node of the sample's key */
    uint64_t deadline_paused;  /* lockstep: deadline misses while this node was paused too */
    uint64_t deadline_covered; /* health deadlines missed by a node heard from within them */
    agent_lat_t xch_lat;       /* io's request to its AGREED */
    agent_lat_t dds_lat;       /* a peer's dds_write of its inputs to their take here */
    bool ready;                /* discovery is over: the DDS latency is measured from here on */
    int64_t start_mono_ns;

    FILE *trace;
    uint64_t traced_bad;
};

int64_t agent_mono_ns(void);
int64_t agent_wall_ns(void);
int agent_lat_init(agent_lat_t *l);
void agent_lat_add(agent_lat_t *l, int64_t ns);
void agent_lat_free(agent_lat_t *l);

/* agent_dds.c */
/* Wakes the main thread out of its ppoll (any thread). */
void agent_wake(agent_t *a);
int agent_dds_start(agent_t *a);
void agent_dds_stop(agent_t *a);
/* Before agent_dds_stop: the participants that joined the domain and are not the nodes'
 * agents, into a->foreign. */
void agent_dds_census(agent_t *a);
void agent_dds_process_events(agent_t *a);
void agent_dds_take_all(agent_t *a);
bool agent_dds_discovery_complete(agent_t *a, uint32_t *missing);
int agent_dds_publish(agent_t *a, int topic, const struct xch_hdr *h, const void *payload);
/* Whether the agent reads a topic from the other nodes (it writes every topic). */
bool agent_reads_topic(int topic);
void agent_dds_withdraw(agent_t *a);
unsigned agent_dds_bind_sockets(agent_t *a);
/* Emulated time: latches as hung the peers of `missing` that are silent (see agent_dds.c);
 * true if it did any. */
bool agent_dds_declare_hung(agent_t *a, uint32_t missing);

/* agent_writers.c: the other participants (see there). */
/* The DDS partition node K's agent publishes in; readers take a writer's node from it. */
#define AGENT_PARTITION_FMT "node%u"
agent_writer_t *agent_writer_find(agent_t *a, int topic, dds_instance_handle_t h);
/* The writer of handle on topic, its partition looked up once while it is matched; NULL if
 * unknown. */
agent_writer_t *agent_writer_of(agent_t *a, int topic, dds_instance_handle_t h);
/* Whether node k has a writer of topic matched (alive, if `alive`) other than `except`. */
bool agent_node_has_writer(agent_t *a, int topic, unsigned k, bool alive,
                           const agent_writer_t *except);
/* Whether a sample keyed as node k comes from a writer in node k's partition; if not, it is
 * refused: counted on its writer and traced at its first (dds_refused). */
bool agent_from_node(agent_t *a, int t, dds_instance_handle_t h, unsigned k);

extern const char *const agent_topic_name[T_COUNT];

/* agent_security.c: the participant's QoS, with the DDS Security properties when
 * --security is given; NULL (reported) if its files or Cyclone's plugins are missing. */
dds_qos_t *agent_security_qos(agent_t *a);

/* agent_io.c */
int agent_io_listen(agent_t *a);
void agent_io_accept(agent_t *a);
void agent_io_readable(agent_t *a);
void agent_io_close(agent_t *a, const char *reason);
void agent_io_check_pending(agent_t *a, bool timed_out);
/* The listeners' queued events, the samples that came in, then the pending request. */
void agent_io_catch_up(agent_t *a);
void agent_io_shutdown(agent_t *a);

/* agent_guard.c: who may be io */
/* Reads the SKE's pid the launcher wrote to --ske-pid-fd (the descriptor is then closed). */
void agent_guard_read_ske(agent_t *a);
/* Whether the peer of a connection to the io socket may be io; a refusal is counted, traced
 * and listed. */
bool agent_guard_may_be_io(agent_t *a, int fd);
/* An entry of the statistics' `refusals` list (what: "io_client", ...). */
void agent_refused_add(agent_t *a, const char *what, const char *detail);

/* agent_fault.c */
/* Publishes one of io's INPUTS or HEALTH as this node's faults have it: now, late, or not (in
 * emulated time a withheld INPUTS is published as a lost mark, agent__agree.h); first the
 * late ones due by its frame. */
int agent_fault_publish(agent_t *a, int topic, const struct xch_hdr *h, const void *payload);

/* agent_out.c: the trace (one JSON object per line) and the statistics. */
/* Starts a trace line with the common fields; false (write nothing more) without a trace. */
bool agent_trace_begin(agent_t *a, const char *kind);
/* The same, with the emulated time of the event rather than of the latest request. */
bool agent_trace_begin_at(agent_t *a, const char *kind, int64_t t_ns);
void agent_trace_end(agent_t *a);
void agent_trace_simple(agent_t *a, const char *kind);
/* Writes the nodes of mask as a JSON array member: ,"key":["node1",...] */
void agent_trace_nodes(agent_t *a, const char *key, uint32_t mask);
int agent_write_stats(agent_t *a);
void agent_log(agent_t *a, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
