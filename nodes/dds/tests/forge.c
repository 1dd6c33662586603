/* SPDX-License-Identifier: Apache-2.0 */
/* ima-dds-forge: a hostile DDS participant for the security tests (tests/dds/test_security.py).
 *
 *   ima-dds-forge --domain D --nodes N --as K[,K...] --seconds S
 *                 [--security DIR --identity NAME] [--partition auto|NAME] [--future]
 *
 * It reads the nodes' cross-channel inputs like an agent and, for each sample of a node in
 * --as, publishes forged copies keyed as that node for its next two frames, before the node
 * does: the GPS and air data samples stamped at the frame's start (or 1000 s in the future
 * with --future), newer than any real one, 300 ft higher (and the GPS position 0.01 degree
 * north), so that an agreement which takes them flies a different aircraft. Without
 * --security it joins as an unauthenticated participant; with it, it holds the identity
 * NAME of the run's DIR (a stolen key). --partition auto writes in each forged node's
 * partition or, where the permissions refuse it, in its own identity's. Prints one JSON
 * line at the end (or on SIGTERM): what it wrote, and where. Cyclone's configuration comes from CYCLONEDDS_URI. */
#include <dds/dds.h>
#include <errno.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rpas.h"

#ifndef IMA_DDS_SECURITY_LIB_DIR
#define IMA_DDS_SECURITY_LIB_DIR ""
#endif

#define MAX_NODES 8
#define FRAME_NS 50000000LL /* the RPAS system's major frame */

typedef struct {
    unsigned domain, nodes, seconds;
    bool as[MAX_NODES + 1];
    const char *security, *identity, *partition;
    bool future;
} opts_t;

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

static int usage(void)
{
    fputs("usage: ima-dds-forge --domain D --nodes N --as K[,K...] --seconds S "
          "[--security DIR --identity NAME] [--partition auto|NAME] [--future]\n",
          stderr);
    return 2;
}

static int parse(int argc, char **argv, opts_t *o)
{
    *o = (opts_t){.partition = "auto"};
    for (int i = 1; i < argc; i++) {
        const char *k = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(k, "--future")) {
            o->future = true;
            continue;
        }
        if (!v)
            return usage();
        i++;
        if (!strcmp(k, "--domain"))
            o->domain = (unsigned)atoi(v);
        else if (!strcmp(k, "--nodes"))
            o->nodes = (unsigned)atoi(v);
        else if (!strcmp(k, "--seconds"))
            o->seconds = (unsigned)atoi(v);
        else if (!strcmp(k, "--security"))
            o->security = v;
        else if (!strcmp(k, "--identity"))
            o->identity = v;
        else if (!strcmp(k, "--partition"))
            o->partition = v;
        else if (!strcmp(k, "--as")) {
            for (const char *p = v; *p;) {
                unsigned n = (unsigned)strtoul(p, (char **)&p, 10);
                if (n < 1 || n > MAX_NODES)
                    return usage();
                o->as[n] = true;
                if (*p == ',')
                    p++;
                else if (*p)
                    return usage();
            }
        } else
            return usage();
    }
    if (!o->domain || !o->nodes || o->nodes > MAX_NODES || !o->seconds ||
        (o->security && !o->identity))
        return usage();
    return 0;
}

static void file_prop(dds_qos_t *q, const char *name, const char *dir, const char *file)
{
    char v[4096];
    snprintf(v, sizeof v, "file:%s/%s", dir, file);
    dds_qset_prop(q, name, v);
}

static void lib_prop(dds_qos_t *q, const char *plugin, const char *lib, const char *fn)
{
    char k[64], v[1024];
    snprintf(k, sizeof k, "dds.sec.%s.library.path", plugin);
    snprintf(v, sizeof v, "%s/lib%s.so", IMA_DDS_SECURITY_LIB_DIR, lib);
    dds_qset_prop(q, k, v);
    snprintf(k, sizeof k, "dds.sec.%s.library.init", plugin);
    snprintf(v, sizeof v, "init_%s", fn);
    dds_qset_prop(q, k, v);
    snprintf(k, sizeof k, "dds.sec.%s.library.finalize", plugin);
    snprintf(v, sizeof v, "finalize_%s", fn);
    dds_qset_prop(q, k, v);
}

static dds_qos_t *participant_qos(const opts_t *o)
{
    dds_qos_t *q = dds_create_qos();
    if (!o->security)
        return q;
    char cert[128], key[128];
    snprintf(cert, sizeof cert, "%s.pem", o->identity);
    snprintf(key, sizeof key, "%s.key", o->identity);
    lib_prop(q, "auth", "dds_security_auth", "authentication");
    lib_prop(q, "access", "dds_security_ac", "access_control");
    lib_prop(q, "crypto", "dds_security_crypto", "crypto");
    file_prop(q, "dds.sec.auth.identity_ca", o->security, "identity_ca.pem");
    file_prop(q, "dds.sec.auth.identity_certificate", o->security, cert);
    file_prop(q, "dds.sec.auth.private_key", o->security, key);
    file_prop(q, "dds.sec.access.permissions_ca", o->security, "permissions_ca.pem");
    file_prop(q, "dds.sec.access.governance", o->security, "governance.p7s");
    file_prop(q, "dds.sec.access.permissions", o->security, "permissions.p7s");
    return q;
}

/* A writer of the inputs topic in partition `part`, with the agents' QoS; <0 if refused. */
static dds_entity_t writer_in(dds_entity_t pp, dds_entity_t tp, const char *part)
{
    dds_qos_t *q = dds_create_qos();
    dds_qset_partition1(q, part);
    dds_entity_t pub = dds_create_publisher(pp, q, NULL);
    dds_delete_qos(q);
    if (pub < 0)
        return pub;
    q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 32);
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_writer_data_lifecycle(q, false);
    dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(500)); /* within the agents' */
    dds_entity_t wr = dds_create_writer(pub, tp, q, NULL);
    dds_delete_qos(q);
    return wr;
}

int main(int argc, char **argv)
{
    opts_t o;
    if (parse(argc, argv, &o) != 0)
        return 2;
    dds_qos_t *pq = participant_qos(&o);
    dds_entity_t pp = dds_create_participant(o.domain, pq, NULL);
    dds_delete_qos(pq);
    if (pp < 0) {
        fprintf(stderr, "ima-dds-forge: participant: %s\n", dds_strretcode(pp));
        return 1;
    }
    dds_entity_t tp = dds_create_topic(pp, &rpas_CrossChannelInputs_desc,
                                       "rpas_CrossChannelInputs", NULL, NULL);
    if (tp < 0) {
        fprintf(stderr, "ima-dds-forge: topic: %s\n", dds_strretcode(tp));
        return 1;
    }
    char names[MAX_NODES][16];
    const char *all[MAX_NODES];
    for (unsigned k = 1; k <= o.nodes; k++) {
        snprintf(names[k - 1], sizeof names[k - 1], "node%u", k);
        all[k - 1] = names[k - 1];
    }
    dds_qos_t *q = dds_create_qos();
    dds_qset_partition(q, o.nodes, all);
    dds_entity_t sub = dds_create_subscriber(pp, q, NULL);
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 32);
    dds_qset_ignorelocal(q, DDS_IGNORELOCAL_PARTICIPANT);
    dds_entity_t rd = sub < 0 ? sub : dds_create_reader(sub, tp, q, NULL);
    dds_delete_qos(q);
    if (rd < 0)
        fprintf(stderr, "ima-dds-forge: reader refused (%s): forging blind\n",
                dds_strretcode(rd));

    dds_entity_t wr[MAX_NODES + 1] = {0};
    char where[MAX_NODES + 1][160];
    for (unsigned k = 1; k <= o.nodes; k++) {
        if (!o.as[k])
            continue;
        const char *part = strcmp(o.partition, "auto") ? o.partition : names[k - 1];
        snprintf(where[k], sizeof where[k], "%s", part);
        wr[k] = writer_in(pp, tp, part);
        if (wr[k] < 0 && o.identity && !strcmp(o.partition, "auto")) {
            snprintf(where[k], sizeof where[k], "%s", o.identity); /* its own partition */
            wr[k] = writer_in(pp, tp, o.identity);
        }
        if (wr[k] < 0) {
            fprintf(stderr, "ima-dds-forge: no writer for node%u: %s\n", k,
                    dds_strretcode(wr[k]));
            return 1;
        }
    }

    uint64_t written[MAX_NODES + 1] = {0}, seen = 0;
    rpas_CrossChannelInputs buf[16];
    void *ptrs[16];
    dds_sample_info_t si[16];
    for (int i = 0; i < 16; i++)
        ptrs[i] = &buf[i];
    signal(SIGTERM, on_signal); /* the report is printed all the same */
    signal(SIGINT, on_signal);
    dds_time_t end = dds_time() + DDS_SECS((int64_t)o.seconds);
    while (!stop && dds_time() < end) {
        int32_t n = rd < 0 ? 0 : dds_take(rd, ptrs, si, 16, 16);
        for (int32_t i = 0; i < n; i++) {
            unsigned k = buf[i].node;
            if (!si[i].valid_data || k < 1 || k > o.nodes || !o.as[k])
                continue;
            seen++;
            /* the next two frames, before the node itself publishes them: an agent whose io
             * asks first answers with these */
            for (uint32_t ahead = 1; ahead <= 2; ahead++) {
                rpas_CrossChannelInputs f = buf[i];
                f.frame += ahead;
                f.t_ns += (int64_t)ahead * FRAME_NS;
                /* newer than any real sample of the frame, and not after the frame's start
                 * (io refuses samples stamped later than that) */
                f.gps_t_ns = o.future ? f.gps_t_ns + 1000000000000LL : f.t_ns;
                f.air_t_ns = o.future ? f.air_t_ns + 1000000000000LL : f.t_ns;
                f.gps[0] += 0.01;
                f.gps[2] += 300.0; /* GPS altitude, ft */
                f.air[1] += 300.0; /* pressure altitude, ft */
                if (dds_write(wr[k], &f) == DDS_RETCODE_OK)
                    written[k]++;
            }
        }
        if (n <= 0)
            dds_sleepfor(DDS_USECS(100));
    }
    printf("{\"seen\":%" PRIu64 ",\"writers\":[", seen);
    bool first = true;
    for (unsigned k = 1; k <= o.nodes; k++) {
        if (!o.as[k])
            continue;
        printf("%s{\"as\":%u,\"partition\":\"%s\",\"written\":%" PRIu64 "}", first ? "" : ",", k,
               where[k], written[k]);
        first = false;
    }
    printf("]}\n");
    dds_delete(pp);
    return 0;
}
