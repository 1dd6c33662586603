/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the partition misbehaviours (fi/partition.h): each run in a child process,
 * which must end the way the misbehaviour says (the signal), or return what it says. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "fi/partition.h"

static int failures;
#define CHECK(c)                                                                                   \
    do {                                                                                           \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #c);                  \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

/* Runs fn in a child; its wait status. */
static int in_child(void (*fn)(void))
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        signal(SIGABRT, SIG_DFL);
        fn();
        _exit(0);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    return st;
}

static bool killed_by(int st, int sig) { return WIFSIGNALED(st) && WTERMSIG(st) == sig; }

static void do_crash(void) { fi_crash(); }
static void do_segv(void) { fi_memory_violation(); }
static void do_fpe(void) { fi_numeric_error(); }

static void do_stack(void)
{
    struct rlimit r = {256 * 1024, 256 * 1024}; /* a small stack: quick to fill */
    setrlimit(RLIMIT_STACK, &r);
    fi_stack_overflow();
}

static void do_readonly_write(void)
{
    void *m = mmap(NULL, 4096, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    fi_write_byte(m);
}

static void do_exhaust(void)
{
    struct rlimit r = {48u << 20, 48u << 20};
    setrlimit(RLIMIT_DATA, &r);
    size_t mib = fi_exhaust_memory(0);
    if (mib == 0 || mib >= 48)
        _exit(3); /* the limit was not what stopped it */
    fi_write_through_null();
}

static void test_signals(void)
{
    CHECK(killed_by(in_child(do_crash), SIGABRT));
    CHECK(killed_by(in_child(do_segv), SIGSEGV));
    CHECK(killed_by(in_child(do_fpe), SIGFPE));
    CHECK(killed_by(in_child(do_stack), SIGSEGV));
    CHECK(killed_by(in_child(do_readonly_write), SIGSEGV));
    CHECK(killed_by(in_child(do_exhaust), SIGSEGV));
}

static void test_write_byte_keeps_writable_memory(void)
{
    char b[4] = {1, 2, 3, 4};
    fi_write_byte(&b[2]);
    CHECK(b[0] == 1 && b[1] == 2 && b[2] == 3 && b[3] == 4);
}

static void test_exhaust_bound(void)
{
    CHECK(fi_exhaust_memory(3) == 3); /* no limit here: the bound stops it */
}

static void test_spin(void)
{
    int64_t used = fi_spin_cpu(20000000);
    CHECK(used >= 20000000 && used < 40000000);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0)
        fi_spin_forever();
    struct timespec ts = {0, 50000000};
    nanosleep(&ts, NULL);
    int st = 0;
    CHECK(waitpid(pid, &st, WNOHANG) == 0); /* still spinning */
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
}

static void test_corrupt(void)
{
    unsigned char b[4] = {0x00, 0x5A, 0xFF, 0x12};
    fi_corrupt_bytes(b, sizeof b);
    CHECK(b[0] == 0x5A && b[1] == 0x00 && b[2] == 0xA5 && b[3] == 0x48);
    fi_corrupt_bytes(b, sizeof b);
    CHECK(b[0] == 0x00 && b[1] == 0x5A && b[2] == 0xFF && b[3] == 0x12);
}

static bool send_to(void *ctx)
{
    int *room = ctx;
    if (*room == 0)
        return false;
    (*room)--;
    return true;
}

static void test_flood(void)
{
    int room = 4;
    fi_flood_result_t r = fi_flood(send_to, &room, 100, false);
    CHECK(r.sent == 4 && r.refused == 96);
    room = 4;
    r = fi_flood(send_to, &room, 100, true);
    CHECK(r.sent == 4 && r.refused == 1);
}

static void test_readonly_port_mapping(void)
{
    CHECK(fi_readonly_port_mapping() == NULL);
    int fd = memfd_create("ima-test-port", 0);
    CHECK(fd >= 0 && ftruncate(fd, 4096) == 0);
    void *rw = mmap(NULL, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    CHECK(rw != MAP_FAILED && fi_readonly_port_mapping() == NULL); /* writable: not it */
    void *ro = mmap(NULL, 4096, PROT_READ, MAP_SHARED, fd, 0);
    CHECK(ro != MAP_FAILED && fi_readonly_port_mapping() == ro);
    munmap(ro, 4096);
    munmap(rw, 4096);
    close(fd);
}

int main(void)
{
    test_signals();
    test_write_byte_keeps_writable_memory();
    test_exhaust_bound();
    test_spin();
    test_corrupt();
    test_flood();
    test_readonly_port_mapping();
    if (failures) {
        fprintf(stderr, "test_fi_partition: %d failure(s)\n", failures);
        return 1;
    }
    printf("test_fi_partition: ok\n");
    return 0;
}
