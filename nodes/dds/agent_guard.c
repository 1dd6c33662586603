/* SPDX-License-Identifier: Apache-2.0 */
/* Who may be the agent's io: a process of the run's owner and, when the launcher tells the
 * agent its node's SKE (--ske-pid-fd), a partition process of that SKE, i.e. one of its
 * children: the SKE forks every partition itself, restarted ones too. The launcher writes the
 * SKE's pid into an inherited pipe once it has started it (the agent starts first); until
 * then no connection is taken. Refusals are counted, traced and listed in the statistics'
 * `refusals` list, which other parts of the agent may add to (agent_refused_add). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "agent__agent.h"
#include "peer/parent.h"

void agent_refused_add(agent_t *a, const char *what, const char *detail)
{
    if (a->n_refused >= AGENT_REFUSED_MAX) {
        a->refusals_unlisted++;
        return;
    }
    agent_refused_t *r = &a->refused[a->n_refused++];
    snprintf(r->what, sizeof r->what, "%s", what);
    snprintf(r->detail, sizeof r->detail, "%s", detail);
}

void agent_guard_read_ske(agent_t *a)
{
    char buf[32];
    ssize_t n = read(a->o.ske_pid_fd, buf, sizeof buf - 1);
    if (n < 0 && (errno == EAGAIN || errno == EINTR))
        return;
    long pid = 0;
    if (n > 0) {
        buf[n] = '\0';
        char *end;
        pid = strtol(buf, &end, 10);
        if (end == buf || (*end && *end != '\n') || pid <= 1)
            pid = 0;
    }
    close(a->o.ske_pid_fd);
    a->o.ske_pid_fd = -1;
    /* A launcher that closed the pipe without a pid: no process can be io (-1 matches none). */
    a->ske_pid = pid > 0 ? (pid_t)pid : -1;
    if (agent_trace_begin(a, "io_ske")) {
        fprintf(a->trace, ",\"ske_pid\":%ld", (long)a->ske_pid);
        agent_trace_end(a);
    }
}

static void refuse(agent_t *a, const char *kind, const struct ucred *cred, pid_t ppid,
                   const char *comm)
{
    a->io_refused++;
    char detail[200];
    if (strcmp(kind, "io_refused_user") == 0)
        snprintf(detail, sizeof detail, "connection of uid %ld (pid %ld) to %s's io socket: "
                 "another user", (long)cred->uid, (long)cred->pid, a->node_name);
    else
        snprintf(detail, sizeof detail, "pid %ld (%s, parent %ld) is not a partition of %s's "
                 "SKE (pid %ld)", (long)cred->pid, comm, (long)ppid, a->node_name,
                 (long)a->ske_pid);
    agent_refused_add(a, "io_client", detail);
    /* A flood of connections is counted, not traced line by line. */
    if (a->io_refused <= AGENT_REFUSED_MAX && agent_trace_begin(a, kind)) {
        fprintf(a->trace, ",\"pid\":%ld,\"uid\":%ld", (long)cred->pid, (long)cred->uid);
        if (ppid)
            fprintf(a->trace, ",\"parent\":%ld", (long)ppid);
        agent_trace_end(a);
    }
}

bool agent_guard_may_be_io(agent_t *a, int fd)
{
    struct ucred cred = {0};
    socklen_t len = sizeof cred;
    if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0 || cred.uid != getuid()) {
        refuse(a, "io_refused_user", &cred, 0, "");
        return false;
    }
    if (a->ske_pid == 0 && a->o.ske_pid_fd < 0)
        return true; /* started by hand, without --ske-pid-fd: the owner's processes */
    char comm[64] = "?";
    pid_t ppid = peer_parent(cred.pid, comm, sizeof comm);
    if (a->ske_pid > 0 && ppid == a->ske_pid)
        return true;
    refuse(a, "io_refused_process", &cred, ppid, comm);
    return false;
}
