/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition of the isolation tests: what a system partition may do (files and sockets,
 * on this machine only) and that it is confined all the same. Arguments="PATH": the file it
 * creates, writes and reads back. Every step is reported as a CHECK line. */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <stdio.h>
#include <sys/socket.h>
#include <unistd.h>

#include "apex_check.h"

static const char *errname(long r) { return r >= 0 ? "ok" : strerror(errno); }

static void file(const char *path)
{
    static const char text[] = "written by a system partition\n";
    int fd = open(path, O_CREAT | O_WRONLY | O_TRUNC, 0600);
    check_str("file.create", "ok", errname(fd));
    if (fd < 0)
        return;
    ssize_t w = write(fd, text, sizeof text - 1);
    check_int("file.write", (long long)sizeof text - 1, w);
    close(fd);
    char buf[64] = "";
    FILE *f = fopen(path, "r");
    check_true("file.reopen", f != NULL);
    if (!f)
        return;
    check_true("file.read_back", fgets(buf, sizeof buf, f) && strcmp(buf, text) == 0);
    fclose(f);
}

/* A pair of connected local sockets: no traffic leaves the process. */
static void unix_pair(void)
{
    int sv[2];
    int r = socketpair(AF_UNIX, SOCK_STREAM, 0, sv);
    check_str("socketpair", "ok", errname(r));
    if (r != 0)
        return;
    char c = 0;
    check_int("socketpair.send", 1, send(sv[0], "x", 1, 0));
    check_int("socketpair.recv", 1, recv(sv[1], &c, 1, 0));
    check_int("socketpair.byte", 'x', c);
    close(sv[0]);
    close(sv[1]);
}

/* A datagram to itself on the loopback interface. */
static void loopback(void)
{
    int s = socket(AF_INET, SOCK_DGRAM, 0);
    check_str("udp.socket", "ok", errname(s));
    if (s < 0)
        return;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = 0};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    check_str("udp.bind", "ok", errname(bind(s, (struct sockaddr *)&a, sizeof a)));
    check_str("udp.getsockname", "ok", errname(getsockname(s, (struct sockaddr *)&a, &len)));
    check_int("udp.sendto", 1, sendto(s, "y", 1, 0, (struct sockaddr *)&a, sizeof a));
    char c = 0;
    check_int("udp.recvfrom", 1, recvfrom(s, &c, 1, 0, NULL, NULL));
    check_int("udp.byte", 'y', c);
    close(s);
}

/* It runs under a system-call filter too (mode 2 = filter). */
static void confined(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[128];
    long mode = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Seccomp: %ld", &mode) == 1)
            break;
    if (f)
        fclose(f);
    check_int("seccomp_mode", 2, mode);
}

int main(int argc, char **argv)
{
    file(argc > 1 ? argv[1] : "/nonexistent/file");
    unix_pair();
    loopback();
    confined();
    enter_normal();
    return 1;
}
