/* SPDX-License-Identifier: Apache-2.0 */
/* The parent of a process, for the bus and the DDS agents, which accept a client only if it is
 * a given process or one of its children (a node's SKE forks its partitions itself). */
#ifndef PEER_PARENT_H
#define PEER_PARENT_H

#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

/* The parent of `pid` and its command name (into comm, len bytes), from /proc/PID/stat; -1 if
 * the process is gone. */
static inline pid_t peer_parent(pid_t pid, char *comm, size_t len)
{
    char path[64], buf[512];
    snprintf(path, sizeof path, "/proc/%ld/stat", (long)pid);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return -1;
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0)
        return -1;
    buf[n] = '\0';
    /* PID (COMM) STATE PPID ...: the name may hold spaces and parentheses, the last ')' ends it */
    char *open_p = strchr(buf, '('), *close_p = strrchr(buf, ')');
    if (!open_p || !close_p || close_p < open_p)
        return -1;
    snprintf(comm, len, "%.*s", (int)(close_p - open_p - 1), open_p + 1);
    char state;
    long ppid;
    if (sscanf(close_p + 1, " %c %ld", &state, &ppid) != 2)
        return -1;
    return (pid_t)ppid;
}

#endif
