/* SPDX-License-Identifier: Apache-2.0 */
/* The bus process's set-up (listening socket, trace file, wire model), its statistics file,
 * and its end; bus_loop.c runs it. */
#include "canbus__server.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

volatile sig_atomic_t canbus_signalled;

int canbus_bus_open(canbus_bus_t *b, const canbus_opts_t *o)
{
    int rc;
    memset(b, 0, sizeof *b);
    b->o = *o;
    b->next_index = (int)o->n_order; /* clients not in --client-order come after its places */
    b->listen_fd = -1;
    b->stop_reason = CANBUS_STOP_END;
    if ((rc = canbus_wire_init(&b->wire, o->bitrate, o->gap_bits)))
        return rc;
    for (size_t i = 0; i < o->n_faults; i++)
        if ((rc = canbus_wire_add_fault(&b->wire, &o->faults[i].fault)))
            goto fail_wire;
    b->rxbuf = malloc((size_t)RX_BATCH * RXBUF_SIZE);
    if (!b->rxbuf) {
        rc = -ENOMEM;
        goto fail_wire;
    }
    if (o->trace_path) {
        if (strcmp(o->trace_path, "-") == 0)
            b->trace = stdout;
        else if (!(b->trace = fopen(o->trace_path, "w"))) {
            rc = -errno;
            goto fail_rx;
        }
        setvbuf(b->trace, NULL, _IOFBF, 1 << 20);
    }
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    if (strlen(o->socket_path) >= sizeof sa.sun_path) {
        rc = -ENAMETOOLONG;
        goto fail_trace;
    }
    strcpy(sa.sun_path, o->socket_path);
    b->listen_fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (b->listen_fd < 0) {
        rc = -errno;
        goto fail_trace;
    }
    struct stat st;
    if (lstat(o->socket_path, &st) == 0 && S_ISSOCK(st.st_mode)) {
        /* A socket nobody listens on is stale (an earlier run); a live one is not ours. */
        int probe = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
        if (probe >= 0 && connect(probe, (struct sockaddr *)&sa, sizeof sa) == 0) {
            close(probe);
            rc = -EADDRINUSE;
            goto fail_sock;
        }
        if (probe >= 0)
            close(probe);
        unlink(o->socket_path);
    }
    /* 0600: only the run's owner may connect (who does is checked again at accept) */
    if (bind(b->listen_fd, (struct sockaddr *)&sa, sizeof sa) ||
        chmod(o->socket_path, S_IRUSR | S_IWUSR) || listen(b->listen_fd, 128)) {
        rc = -errno;
        goto fail_sock;
    }
    if (o->control_fd >= 0 && (rc = canbus__control_open(b))) {
        unlink(o->socket_path);
        goto fail_sock;
    }
    return 0;

fail_sock:
    close(b->listen_fd);
    b->listen_fd = -1;
fail_trace:
    if (b->trace && b->trace != stdout)
        fclose(b->trace);
    b->trace = NULL;
fail_rx:
    free(b->rxbuf);
    b->rxbuf = NULL;
fail_wire:
    canbus_wire_fini(&b->wire);
    return rc;
}

int canbus_bus_write_stats(canbus_bus_t *b, const char *path)
{
    FILE *f = strcmp(path, "-") == 0 ? stdout : fopen(path, "w");
    if (!f)
        return -errno;
    const canbus_wire_t *w = &b->wire;
    double load, max1;
    canbus_wire_load(w, b->t, &load, &max1);
    double wall = b->end_wall > b->start_wall ? (double)(b->end_wall - b->start_wall) / 1e9 : 0;
    fprintf(f,
            "{\"bitrate\":%" PRIu32 ",\"quantum_ns\":%" PRId64 ",\"quanta\":%" PRIu64
            ",\"elapsed_ns\":%" PRId64 ",\"frames\":%" PRIu64 ",\"bits\":%" PRIu64
            ",\"busy_bits\":%" PRIu64 ",\"busy_ns\":%" PRId64 ",\"load\":%.6f,\"load_max_1s\":%.6f"
            ",\"error_frames\":%" PRIu64 ",\"bus_off_events\":%" PRIu64 ",\"dropped\":%" PRIu64
            ",\"duplicated\":%" PRIu64 ",\"rx_dropped\":%" PRIu64 ",\"rejected\":%" PRIu64 ",\"bad_hellos\":%" PRIu64 ",\"late_joins\":%" PRIu64
            ",\"refused_full\":%" PRIu64 ",\"send_timeouts\":%" PRIu64
            ",\"garbage_disconnects\":%" PRIu64 ",\"faults_armed\":%" PRIu64
            ",\"refused_users\":%" PRIu64 ",\"refused_hellos\":%" PRIu64
            ",\"refused_records\":%" PRIu64
            ",\"wall_s\":%.6f,\"frames_per_wall_s\":%.1f,\"release_late_max_us\":%.1f"
            ",\"quanta_late\":%" PRIu64 ",\"stop\":\"%s\",\"clients\":[",
            b->o.bitrate, b->o.quantum_ns, b->quanta, b->t, w->frames, w->frame_bits,
            w->busy_bits, canbus_wire_bit_ns(w, w->busy_bits), load, max1, w->error_frames,
            w->bus_off_events, w->dropped, w->duplicated, w->rx_dropped, b->rejected, b->bad_hellos, b->late_joins, b->full,
            b->send_timeouts, b->garbage_kicks, b->faults_armed + b->o.n_faults, b->refused_users,
            b->refused_hellos, b->refused_records, wall,
            wall > 0 ? (double)w->frames / wall : 0.0, (double)b->late_max_ns / 1e3, b->quanta_late,
            canbus__stop_name(b->stop_reason));
    for (int i = 0; i < b->next_index; i++) {
        const canbus_client_t *c = b->by_index[i];
        const canbus_wire_ctl_t *k = &w->ctl[i];
        if (!c)
            continue; /* a --client-order place nobody took */
        fprintf(f,
                "%s{\"index\":%d,\"name\":%.*s,\"roles\":%u,\"tx\":%" PRIu64 ",\"rx\":%" PRIu64
                ",\"rejected\":%" PRIu64 ",\"clamped\":%" PRIu64 ",\"overflow\":%" PRIu64
                ",\"tx_ok\":%" PRIu64
                ",\"tx_errors\":%" PRIu64 ",\"dropped\":%" PRIu64 ",\"bus_off_events\":%" PRIu64
                ",\"tec\":%u,\"rec\":%u,\"state\":\"%s\",\"left\":%s,\"listen_only\":%s"
                ",\"ticks\":%" PRIu64 ",\"ticks_skipped\":%" PRIu64 "}",
                i ? "," : "", i, (int)c->jname.n, c->jname.p, c->roles, c->tx, c->rx,
                c->rejected, c->clamped, c->overflow, k->tx_ok, k->tx_err, k->dropped,
                k->bus_off_events,
                k->tec, k->rec, canbus__state_name(canbus_wire_state(w, (uint8_t)i)),
                c->gone ? "true" : "false", c->listen_only ? "true" : "false", c->ticks,
                c->ticks_skipped);
    }
    /* Who ended the run (null: it reached its end), and what the bus refused. */
    canbus_sbuf_t *s = &b->line;
    canbus_sb_str(s, "],\"stopped_by\":");
    if (b->stop_reason == CANBUS_STOP_SIGNAL)
        canbus_sb_str(s, "\"signal\"");
    else if (b->stopped_by.n)
        canbus_sb_mem(s, b->stopped_by.p, b->stopped_by.n);
    else
        canbus_sb_str(s, "null");
    canbus_sb_str(s, ",\"refusals\":");
    canbus__sb_refused(b, s);
    canbus_sb_str(s, "}\n");
    int rc = s->oom ? -ENOMEM : 0;
    if (!s->oom)
        fwrite(s->p, 1, s->n, f);
    s->n = 0;
    if ((fflush(f) || ferror(f)) && !rc)
        rc = -EIO;
    if (f != stdout && fclose(f) && !rc)
        rc = -EIO;
    return rc;
}

void canbus_bus_close(canbus_bus_t *b)
{
    for (size_t i = 0; i < b->n_live; i++)
        if (!b->live[i]->gone) {
            close(b->live[i]->fd);
            b->live[i]->gone = true;
            if (b->live[i]->index < 0) {
                canbus_sb_free(&b->live[i]->staged);
                canbus_sb_free(&b->live[i]->jname);
                free(b->live[i]);
            }
        }
    for (int i = 0; i < b->next_index; i++) {
        canbus_client_t *c = b->by_index[i];
        if (!c)
            continue;
        free(c->q);
        canbus_sb_free(&c->staged);
        canbus_sb_free(&c->jname);
        free(c);
    }
    free(b->live);
    if (b->listen_fd >= 0) {
        close(b->listen_fd);
        unlink(b->o.socket_path);
    }
    if (b->trace) {
        if (fflush(b->trace))
            b->trace_error = true;
        if (b->trace != stdout)
            fclose(b->trace);
    }
    canbus_sb_free(&b->staged);
    canbus_sb_free(&b->line);
    canbus_sb_free(&b->refused);
    canbus_sb_free(&b->stopped_by);
    free(b->out);
    free(b->rxbuf);
    canbus_wire_fini(&b->wire);
}
