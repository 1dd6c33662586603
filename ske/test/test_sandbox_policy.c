/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of the partition's system-call policy: the BPF programs of both stages, run by
 * a small interpreter on the calls a partition makes, argument by argument. (The isolation
 * tests in tests/isolation run the same programs in the kernel.) */
#include <fcntl.h>
#include <linux/audit.h>
#include <linux/seccomp.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "ske_sandbox.h"
#include "ske_test.h"

#if defined(__x86_64__)
#define ARCH AUDIT_ARCH_X86_64
#elif defined(__aarch64__)
#define ARCH AUDIT_ARCH_AARCH64
#endif

#define SELF 4242
#define CTL_FD 3 /* then three ports: 4, 5, 6 */
#define PORT_LO 4
#define PORT_HI 7

enum { ALLOW = 0, CALL = 1, ARGS = 2, ABI = 3, BAD_PROGRAM = -1 };

/* A write to a descriptor a partition may not write: refused, but in coverage builds, where
 * libgcov writes its .gcda files from the partition (test_coverage_calls). */
#ifdef IMA_COVERAGE
#define WRITE_ELSEWHERE ALLOW
#else
#define WRITE_ELSEWHERE ARGS
#endif

/* Runs the program on one call: ALLOW, or the SIGSYS reason it raises. */
static int run(const ske_sandbox_prog_t *prog, uint32_t arch, long nr, const uint64_t args[6])
{
    struct seccomp_data d = {.nr = (int)nr, .arch = arch};
    for (int i = 0; i < 6; i++)
        d.args[i] = args[i];
    uint32_t a = 0;
    for (unsigned pc = 0; pc < prog->len;) {
        const struct sock_filter *f = &prog->ins[pc++];
        switch (f->code) {
        case BPF_LD | BPF_W | BPF_ABS:
            if (f->k + 4 > sizeof d)
                return BAD_PROGRAM;
            memcpy(&a, (const char *)&d + f->k, 4);
            break;
        case BPF_JMP | BPF_JA: pc += f->k; break;
        case BPF_JMP | BPF_JEQ | BPF_K: pc += a == f->k ? f->jt : f->jf; break;
        case BPF_JMP | BPF_JGE | BPF_K: pc += a >= f->k ? f->jt : f->jf; break;
        case BPF_JMP | BPF_JSET | BPF_K: pc += (a & f->k) ? f->jt : f->jf; break;
        case BPF_RET | BPF_K:
            if ((f->k & SECCOMP_RET_ACTION_FULL) == SECCOMP_RET_ALLOW)
                return ALLOW;
            if ((f->k & SECCOMP_RET_ACTION_FULL) == SECCOMP_RET_TRAP)
                return (int)(f->k & SECCOMP_RET_DATA);
            return BAD_PROGRAM;
        default: return BAD_PROGRAM;
        }
    }
    return BAD_PROGRAM; /* ran off the end */
}

typedef struct {
    ske_sandbox_prog_t load, run;
} progs_t;

static void build(progs_t *p, uint32_t flags)
{
    /* As ima-ske and the APEX library build them: the descriptors ima-ske passes may be
     * mapped shared while the APEX maps them; once it runs, they are closed. */
    ske_sandbox_policy_t load = {flags, SELF, CTL_FD, PORT_HI, -1};
    CHECK_EQ(ske_sandbox_build(&load, SKE_SANDBOX_LOAD, &p->load), 0);
    ske_sandbox_policy_t running = {flags, SELF, 0, 0, -1};
    CHECK_EQ(ske_sandbox_build(&running, SKE_SANDBOX_RUN, &p->run), 0);
    CHECK(p->load.len > 0 && p->run.len > 0);
}

/* What a running partition gets: both filters apply, the stricter answer wins (a trap of
 * the RUN filter is the one reported, as the kernel runs the newest filter first). */
static int running(const progs_t *p, long nr, uint64_t a0, uint64_t a1, uint64_t a2, uint64_t a3,
                   uint64_t a4)
{
    const uint64_t args[6] = {a0, a1, a2, a3, a4, 0};
    int r = run(&p->run, ARCH, nr, args);
    return r != ALLOW ? r : run(&p->load, ARCH, nr, args);
}

static int loading(const progs_t *p, long nr, uint64_t a0, uint64_t a1, uint64_t a2, uint64_t a3,
                   uint64_t a4)
{
    const uint64_t args[6] = {a0, a1, a2, a3, a4, 0};
    return run(&p->load, ARCH, nr, args);
}

static void test_normal_partition(void)
{
    progs_t p;
    build(&p, 0);
    /* What the APEX library and the C library need while running. */
    CHECK_EQ(running(&p, SYS_futex, 0, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_rt_sigprocmask, 0, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_clock_nanosleep, CLOCK_MONOTONIC, 1, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_write, STDERR_FILENO, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_write, STDOUT_FILENO, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_write, 0xffffffff00000002ull, 0, 0, 0, 0), ALLOW); /* int fd 2 */
    CHECK_EQ(running(&p, SYS_write, STDIN_FILENO, 0, 0, 0, 0), WRITE_ELSEWHERE);
    CHECK_EQ(running(&p, SYS_write, PORT_LO, 0, 0, 0, 0), WRITE_ELSEWHERE);
    CHECK_EQ(running(&p, SYS_exit_group, 0, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_ioctl, 1, TCGETS, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_ioctl, 1, TIOCSTI, 0, 0, 0), ARGS);
    /* Memory: private and anonymous mappings, no shared mapping of any file. */
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1), ALLOW);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED | MAP_ANONYMOUS, -1), ALLOW);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, PORT_LO), ARGS);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, CTL_FD), ARGS);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED_VALIDATE, 2), ARGS);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_PRIVATE, 2), ALLOW);
    CHECK_EQ(running(&p, SYS_madvise, 0, 4096, MADV_DONTNEED, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_madvise, 0, 4096, MADV_HWPOISON, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_close, 2, 0, 0, 0, 0), ALLOW);
    /* Signals to itself only. */
    CHECK_EQ(running(&p, SYS_kill, SELF, SIGABRT, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_kill, 1, 0, 0, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_kill, 0, SIGKILL, 0, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_kill, (uint64_t)-1, SIGKILL, 0, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_tgkill, SELF, SELF, SIGABRT, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_tgkill, SELF, SELF + 1, SIGABRT, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_tgkill, SELF + 1, SELF, SIGABRT, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_tkill, SELF + 1, SIGKILL, 0, 0, 0), ARGS);
    /* Clocks: its own and the system's, not another process's CPU clock (negative ids). */
    CHECK_EQ(running(&p, SYS_clock_gettime, CLOCK_PROCESS_CPUTIME_ID, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_clock_gettime, (uint32_t)-6, 0, 0, 0, 0), ARGS);
    /* Limits: read, never set. */
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_STACK, 0, 0x7ffd0000, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_DATA, 0x7ffd0000, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_DATA, 0x100000000ull, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_prlimit64, 1, RLIMIT_DATA, 0, 0x7ffd0000, 0), ARGS);
    /* Nothing that reaches outside the partition. */
    static const long denied[] = {
        SYS_clone,  SYS_clone3,  SYS_execve,   SYS_execveat, SYS_ptrace,    SYS_process_vm_readv,
        SYS_process_vm_writev, SYS_setrlimit, SYS_personality, SYS_mount, SYS_unshare, SYS_setns,
        SYS_shmget, SYS_shmat,   SYS_msgget,   SYS_semget,   SYS_openat,    SYS_socket,
        SYS_connect, SYS_memfd_create, SYS_prctl, SYS_seccomp,  SYS_pidfd_open,
        SYS_io_uring_setup, SYS_bpf, SYS_userfaultfd, SYS_dup3,   SYS_getuid,
#ifdef SYS_fork
        SYS_fork,   SYS_vfork,   SYS_open,
#endif
#ifndef IMA_COVERAGE
        SYS_read, /* libgcov reads its .gcda files in coverage builds */
#endif
    };
    for (size_t i = 0; i < sizeof denied / sizeof denied[0]; i++) {
        int r = running(&p, denied[i], 0, 0, 0, 0, 0);
        if (r != CALL)
            fprintf(stderr, "system call %ld: got %d\n", denied[i], r);
        CHECK_EQ(r, CALL);
    }
    /* Other ABIs. */
    static const uint64_t none[6];
    CHECK_EQ(run(&p.run, AUDIT_ARCH_I386, 2, none), ABI);
    CHECK_EQ(run(&p.load, AUDIT_ARCH_I386, 2, none), ABI);
#ifdef __x86_64__
    CHECK_EQ(run(&p.run, ARCH, 0x40000000 | SYS_getpid, none), ABI);
    CHECK_EQ(run(&p.load, ARCH, 0x40000000 | SYS_getpid, none), ABI);
#endif
}

static void test_load_stage(void)
{
    progs_t p;
    build(&p, 0);
    /* The loader reads its libraries; nothing is written or created. */
    CHECK_EQ(loading(&p, SYS_execve, 0, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_RDONLY | O_CLOEXEC, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_WRONLY, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_RDWR, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_RDONLY | O_CREAT, 0600, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_RDONLY | O_TRUNC, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_read, 5, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_write, 7, 0, 0, 0, 0), ALLOW); /* an exec error to ima-ske */
    /* The control block and the ports are mapped shared, then their descriptors closed;
     * no other file. */
    CHECK_EQ(loading(&p, SYS_mmap, 0, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, CTL_FD), ALLOW);
    CHECK_EQ(loading(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, PORT_LO), ALLOW);
    CHECK_EQ(loading(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, PORT_HI - 1), ALLOW);
    CHECK_EQ(loading(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, PORT_HI), ARGS);
    CHECK_EQ(loading(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, CTL_FD - 1), ARGS);
    CHECK_EQ(loading(&p, SYS_close, CTL_FD, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_close, PORT_LO, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_prctl, PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_prctl, PR_SET_TIMERSLACK, 1, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_prctl, PR_SET_PDEATHSIG, 0, 0, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_prctl, PR_SET_DUMPABLE, 1, 0, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_seccomp, SECCOMP_SET_MODE_FILTER, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_seccomp, SECCOMP_SET_MODE_FILTER, SECCOMP_FILTER_FLAG_NEW_LISTENER,
                     0, 0, 0),
             ARGS);
    /* Before its own filter, a partition can no more reach out than after. */
    CHECK_EQ(loading(&p, SYS_clone, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(loading(&p, SYS_socket, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(loading(&p, SYS_ptrace, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(loading(&p, SYS_kill, 1, 0, 0, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_prlimit64, 0, RLIMIT_DATA, 0x7ffd0000, 0, 0), ARGS);
    CHECK_EQ(loading(&p, SYS_shmget, 0, 0, 0, 0, 0), CALL);
    /* Once running, what only the loader needed is gone. */
    CHECK_EQ(running(&p, SYS_execve, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_openat, AT_FDCWD, 0, O_RDONLY, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, PORT_LO), ARGS);
}

static void test_system_partition(void)
{
    progs_t p;
    build(&p, SKE_SANDBOX_IO);
    CHECK_EQ(running(&p, SYS_openat, AT_FDCWD, 0, O_CREAT | O_RDWR, 0600, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_read, 9, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_write, 9, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_socket, 2, 1, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_sendto, 9, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_recvmsg, 9, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_ppoll, 0, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_ioctl, 9, TIOCSTI, 0, 0, 0), ARGS);
    /* Its files and sockets are I/O, never shared memory. */
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, 9), ARGS);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_SHARED, PORT_LO), ARGS);
    CHECK_EQ(running(&p, SYS_mmap, 0, 4096, PROT_READ, MAP_PRIVATE, 9), ALLOW);
    CHECK_EQ(running(&p, SYS_dup3, 9, PORT_LO, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_uname, 0, 0, 0, 0, 0), ALLOW);
    /* Confined all the same. */
    CHECK_EQ(running(&p, SYS_clone, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_execve, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_kill, 1, 0, 0, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_shmget, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_memfd_create, 0, 0, 0, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_DATA, 0x7ffd0000, 0, 0), ARGS);
}

static void test_no_ports(void)
{
    /* A partition without ports maps only its control block shared. */
    ske_sandbox_policy_t pol = {0, SELF, CTL_FD, CTL_FD + 1, -1};
    ske_sandbox_prog_t prog;
    CHECK_EQ(ske_sandbox_build(&pol, SKE_SANDBOX_LOAD, &prog), 0);
    const uint64_t ctl[6] = {0, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, CTL_FD, 0};
    CHECK_EQ(run(&prog, ARCH, SYS_mmap, ctl), ALLOW);
    const uint64_t shared[6] = {0, 4096, PROT_READ, MAP_SHARED, CTL_FD + 1, 0};
    const uint64_t anon[6] = {0, 4096, PROT_READ, MAP_SHARED | MAP_ANONYMOUS, (uint64_t)-1, 0};
    CHECK_EQ(run(&prog, ARCH, SYS_mmap, shared), ARGS);
    CHECK_EQ(run(&prog, ARCH, SYS_mmap, anon), ALLOW);
}

static void test_output_file(void)
{
    /* A partition with an output file (ima:Linux OutputFile) writes and syncs that one
     * descriptor besides standard output and error, and no other; without one, neither. */
    const int32_t out = PORT_HI + 1;
    ske_sandbox_policy_t pol = {0, SELF, 0, 0, out};
    ske_sandbox_prog_t prog;
    CHECK_EQ(ske_sandbox_build(&pol, SKE_SANDBOX_RUN, &prog), 0);
    const uint64_t to_out[6] = {(uint64_t)out, 0, 320, 0, 0, 0};
    const uint64_t to_err[6] = {STDERR_FILENO, 0, 1, 0, 0, 0};
    const uint64_t to_port[6] = {PORT_LO, 0, 1, 0, 0, 0};
    CHECK_EQ(run(&prog, ARCH, SYS_write, to_out), ALLOW);
    CHECK_EQ(run(&prog, ARCH, SYS_write, to_err), ALLOW);
    CHECK_EQ(run(&prog, ARCH, SYS_write, to_port), WRITE_ELSEWHERE);
    CHECK_EQ(run(&prog, ARCH, SYS_fdatasync, to_out), ALLOW);
    CHECK_EQ(run(&prog, ARCH, SYS_fdatasync, to_err), ARGS);
    CHECK(run(&prog, ARCH, SYS_openat, to_out) != ALLOW);
    ske_sandbox_policy_t none = {0, SELF, 0, 0, -1};
    CHECK_EQ(ske_sandbox_build(&none, SKE_SANDBOX_RUN, &prog), 0);
    CHECK_EQ(run(&prog, ARCH, SYS_write, to_out), WRITE_ELSEWHERE);
    CHECK(run(&prog, ARCH, SYS_fdatasync, to_out) != ALLOW);
}

#ifdef IMA_COVERAGE
static void test_coverage_calls(void)
{
    /* Coverage builds: libgcov opens, locks, reads and writes its .gcda files, and the dump
     * lifts the file-size limit; nothing else is added, and the partition's own rules still
     * answer every other use of these calls. */
    progs_t p;
    build(&p, 0);
    const uint64_t gcda = O_RDWR | O_CREAT;
    CHECK_EQ(running(&p, SYS_openat, AT_FDCWD, 0, gcda, 0666, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_openat, AT_FDCWD, 0, O_RDONLY, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_openat, AT_FDCWD, 0, O_WRONLY | O_CREAT | O_TRUNC, 0666, 0), CALL);
    CHECK_EQ(running(&p, SYS_fcntl, 3, F_SETLKW, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_fcntl, 3, F_GETFL, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_fcntl, 3, F_DUPFD, 0, 0, 0), CALL);
    CHECK_EQ(running(&p, SYS_read, 3, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_write, 3, 0, 0, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_FSIZE, 0x7ffd0000, 0, 0), ALLOW);
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_DATA, 0x7ffd0000, 0, 0), ARGS);
    CHECK_EQ(running(&p, SYS_prlimit64, 0, RLIMIT_STACK, 0, 0x7ffd0000, 0), ALLOW);
    /* The loader's read-only opens and a system partition's files still get through. */
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_RDONLY | O_CLOEXEC, 0, 0), ALLOW);
    CHECK_EQ(loading(&p, SYS_openat, AT_FDCWD, 0, O_WRONLY, 0, 0), ARGS);
    progs_t io;
    build(&io, SKE_SANDBOX_IO);
    CHECK_EQ(running(&io, SYS_openat, AT_FDCWD, 0, O_WRONLY | O_APPEND, 0, 0), ALLOW);
    CHECK_EQ(running(&io, SYS_fcntl, 3, F_SETFL, 0, 0, 0), ALLOW);
}
#endif

int main(void)
{
    RUN(test_normal_partition);
    RUN(test_output_file);
    RUN(test_load_stage);
    RUN(test_system_partition);
    RUN(test_no_ports);
#ifdef IMA_COVERAGE
    RUN(test_coverage_calls);
#endif
    return ske_test_result();
}
