/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition of the isolation tests: its initialisation process tries one thing a
 * partition may not do, named by the module's Arguments, and says so first ("TRY <what>").
 * The call must raise SIGSYS and never be made; if it returns, the partition reports
 * "SURVIVED <what>" and runs on, which the test counts as a failure.
 *
 *   Arguments="none"            tries nothing: ticks once per period (the bystander)
 *   Arguments="<what>"          fork thread exec open socket kill kill_group ptrace setrlimit
 *                               shmget vm_read write_stdin cpu_clock mmap_shared i386 x32
 *   Arguments="ignored PATH"    ignores SIGSYS, then tries to create PATH
 *   Arguments="blocked PATH"    blocks SIGSYS, then tries to create PATH
 *   Arguments="handled PATH"    installs its own SIGSYS handler (replacing the APEX's), tries
 *                               to create PATH and to signal process 1, reports what its
 *                               handler saw, then runs on: the calls were still not made
 *   Arguments="system_fork"     forks (run in a system partition)
 */
#include <errno.h>
#include <fcntl.h>
#include <linux/audit.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/ipc.h>
#include <sys/mman.h>
#include <sys/ptrace.h>
#include <sys/resource.h>
#include <sys/shm.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "apex_check.h"
#include "ske_sandbox.h"

#ifndef SYS_SECCOMP
#define SYS_SECCOMP 1 /* si_code of a seccomp SIGSYS (<asm-generic/siginfo.h>) */
#endif

static const char *what = "none";
static const char *path = "";

static void tick(void)
{
    for (long n = 0;; n++) {
        RETURN_CODE_TYPE rc;
        report("tick %ld", n);
        PERIODIC_WAIT(&rc);
    }
}

static void *thread_main(void *arg) { return arg; }

static long try_create(void)
{
    int fd = open(path, O_CREAT | O_WRONLY | O_TRUNC, 0600);
    if (fd >= 0)
        close(fd);
    return fd;
}

/* Does the forbidden thing; returns what the call returned (if it ever does). */
static long attempt(void)
{
    if (strcmp(what, "fork") == 0 || strcmp(what, "system_fork") == 0) {
        pid_t pid = fork();
        if (pid == 0)
            _exit(0); /* were it ever created, the child would end at once */
        return pid;
    }
    if (strcmp(what, "thread") == 0) {
        pthread_t t;
        return pthread_create(&t, NULL, thread_main, NULL);
    }
    if (strcmp(what, "exec") == 0)
        return execl("/bin/true", "true", (char *)NULL);
    if (strcmp(what, "open") == 0)
        return open("/proc/self/status", O_RDONLY);
    if (strcmp(what, "socket") == 0)
        return socket(AF_UNIX, SOCK_STREAM, 0);
    if (strcmp(what, "kill") == 0)
        return kill(1, 0); /* signal 0: had it been allowed, it would only test for process 1 */
    if (strcmp(what, "kill_group") == 0)
        return kill(0, 0);
    if (strcmp(what, "ptrace") == 0)
        return ptrace(PTRACE_PEEKDATA, 1, NULL, NULL);
    if (strcmp(what, "setrlimit") == 0) {
        struct rlimit r = {RLIM_INFINITY, RLIM_INFINITY};
        return setrlimit(RLIMIT_DATA, &r);
    }
    if (strcmp(what, "shmget") == 0) {
        int id = shmget(IPC_PRIVATE, 4096, IPC_CREAT | 0600);
        if (id >= 0)
            shmctl(id, IPC_RMID, NULL);
        return id;
    }
    if (strcmp(what, "vm_read") == 0) {
        char buf[8];
        struct iovec local = {buf, sizeof buf}, remote = {(void *)0x400000, sizeof buf};
        return process_vm_readv(1, &local, 1, &remote, 1, 0);
    }
    if (strcmp(what, "write_stdin") == 0)
        return write(STDIN_FILENO, "x", 1); /* only standard output and error are writable */
    if (strcmp(what, "cpu_clock") == 0) {
        clockid_t c;
        return clock_getcpuclockid(1, &c); /* another process's CPU clock */
    }
    if (strcmp(what, "mmap_shared") == 0) {
        /* A shared mapping of a descriptor that is not one of its ports (standard error). */
        void *m = mmap(NULL, 4096, PROT_READ, MAP_SHARED, STDERR_FILENO, 0);
        return m == MAP_FAILED ? -1 : 0;
    }
#if defined(__x86_64__)
    if (strcmp(what, "i386") == 0) {
        /* The 32-bit system-call entry, where 20 is getpid: numbers mean other calls there. */
        long r = 20;
        __asm__ volatile("int $0x80" : "+a"(r) : : "memory");
        return r;
    }
    if (strcmp(what, "x32") == 0)
        return syscall(0x40000000 | SYS_getpid);
#endif
    if (strcmp(what, "ignored") == 0) {
        signal(SIGSYS, SIG_IGN);
        return try_create();
    }
    if (strcmp(what, "blocked") == 0) {
        sigset_t s;
        sigemptyset(&s);
        sigaddset(&s, SIGSYS);
        sigprocmask(SIG_BLOCK, &s, NULL);
        return try_create();
    }
    report("SKIP %s is not known on this machine", what);
    return 0;
}

/* ---- a partition replacing the APEX library's SIGSYS handler ------------------------- */

static volatile sig_atomic_t seen, seen_code, seen_call, seen_reason;
static volatile uint32_t seen_arch;

static void on_sigsys(int sig, siginfo_t *si, void *uc)
{
    (void)sig;
    (void)uc;
    seen++;
    seen_code = si->si_code;
    seen_call = si->si_syscall;
    seen_reason = si->si_errno;
    seen_arch = si->si_arch;
}

static void handled(void)
{
    struct sigaction sa = {.sa_sigaction = on_sigsys, .sa_flags = SA_SIGINFO};
    sigemptyset(&sa.sa_mask);
    sigaction(SIGSYS, &sa, NULL);

    long r = try_create();
    (void)r;
    check_int("handled.open.signals", 1, seen);
    check_int("handled.open.si_code", SYS_SECCOMP, seen_code);
    check_int("handled.open.si_syscall", SYS_openat, seen_call);
    check_int("handled.open.reason", SKE_SANDBOX_DENIED_CALL, seen_reason);
#if defined(__x86_64__)
    check_int("handled.open.si_arch", AUDIT_ARCH_X86_64, seen_arch);
    /* The call was skipped: it "returns" its own number, the kernel's rollback value. */
    check_int("handled.open.returned", SYS_openat, r);
#endif
    kill(1, 0);
    check_int("handled.kill.signals", 2, seen);
    check_int("handled.kill.si_syscall", SYS_kill, seen_call);
    check_int("handled.kill.reason", SKE_SANDBOX_DENIED_ARGS, seen_reason);
    kill(getpid(), 0); /* signalling itself is allowed */
    check_int("handled.kill_self.signals", 2, seen);
#if defined(__x86_64__)
    long nr = 20; /* getpid through the 32-bit entry */
    __asm__ volatile("int $0x80" : "+a"(nr) : : "memory");
    check_int("handled.i386.signals", 3, seen);
    check_int("handled.i386.reason", SKE_SANDBOX_DENIED_ABI, seen_reason);
#endif
}

int main(int argc, char **argv)
{
    if (argc > 1)
        what = argv[1];
    if (argc > 2)
        path = argv[2];
    if (strcmp(what, "handled") == 0) {
        handled();
    } else if (strcmp(what, "none") != 0) {
        report("TRY %s", what);
        errno = 0;
        long r = attempt();
        report("SURVIVED %s returned %ld errno %d", what, r, errno);
    }
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    start_new_process("tick", tick, 10, st.PERIOD);
    enter_normal();
    return 1;
}
