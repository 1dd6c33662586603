/* SPDX-License-Identifier: Apache-2.0 */
/* The partition's system-call policy, written out as classic BPF seccomp programs: an
 * allow-list of calls, some with argument rules; everything else raises SIGSYS. */
#include "ske_sandbox.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/audit.h>
#include <linux/seccomp.h>
#include <stdbool.h>
#include <stddef.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#if defined(__x86_64__)
#define SANDBOX_ARCH AUDIT_ARCH_X86_64
#elif defined(__aarch64__)
#define SANDBOX_ARCH AUDIT_ARCH_AARCH64
#endif

#define RET_ALLOW SECCOMP_RET_ALLOW
#define RET_DENY(reason) (SECCOMP_RET_TRAP | ((reason) & SECCOMP_RET_DATA))

/* The 32-bit half of a system-call argument holding the C `int` or flags value: the kernel
 * reads such arguments as 32-bit values, whatever the caller put in the upper half. */
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define ARG_LO(i) (offsetof(struct seccomp_data, args) + 8u * (i))
#define ARG_HI(i) (offsetof(struct seccomp_data, args) + 8u * (i) + 4u)
#else
#define ARG_LO(i) (offsetof(struct seccomp_data, args) + 8u * (i) + 4u)
#define ARG_HI(i) (offsetof(struct seccomp_data, args) + 8u * (i))
#endif

/* ---- program builder ------------------------------------------------------------------ */

typedef struct {
    struct sock_filter *ins;
    unsigned n, cap;
    bool overflow;
} prog_t;

static void emit(prog_t *p, uint16_t code, uint32_t k, uint8_t jt, uint8_t jf)
{
    if (p->n >= p->cap) {
        p->overflow = true;
        return;
    }
    p->ins[p->n++] = (struct sock_filter){code, jt, jf, k};
}

static void load(prog_t *p, uint32_t offset) { emit(p, BPF_LD | BPF_W | BPF_ABS, offset, 0, 0); }
static void ret(prog_t *p, uint32_t action) { emit(p, BPF_RET | BPF_K, action, 0, 0); }

/* A call allowed whatever its arguments (A holds the call number). */
static void allow(prog_t *p, long nr)
{
    emit(p, BPF_JMP | BPF_JEQ | BPF_K, (uint32_t)nr, 0, 1);
    ret(p, RET_ALLOW);
}

/* Argument rules: the call is allowed when every condition holds. */
typedef enum {
    C_IN, /* low word is one of v[0..n) */
    C_NOT_IN, /* low word is none of v[0..n) */
    C_RANGE, /* v[0] <= low word < v[1] */
    C_CLEAR, /* low word & v[0] == 0 */
    C_BELOW, /* low word < v[0] */
    C_ZERO, /* the whole 64-bit argument is 0 (a pointer) */
} cond_op_t;

typedef struct {
    uint8_t arg;
    uint8_t op;
    uint8_t n;
    uint32_t v[6];
} cond_t;

#define BODY_MAX 64

/* Jump targets inside a rule's body, resolved when the body is finished. */
enum { TO_NEXT = 0, TO_ALLOW = -1, TO_DENY = -2 };

typedef struct {
    struct sock_filter ins[BODY_MAX];
    signed char jt[BODY_MAX], jf[BODY_MAX]; /* TO_ALLOW, TO_DENY, or a forward skip */
    bool ja_deny[BODY_MAX];
    unsigned n;
    bool overflow;
#ifdef IMA_COVERAGE
    bool fall_through; /* a call whose arguments do not match goes on to the later rules */
#endif
} body_t;

static void body_emit(body_t *b, uint16_t code, uint32_t k, int jt, int jf)
{
    if (b->n >= BODY_MAX) {
        b->overflow = true;
        return;
    }
    b->ins[b->n] = (struct sock_filter){code, 0, 0, k};
    b->jt[b->n] = (signed char)jt;
    b->jf[b->n] = (signed char)jf;
    b->ja_deny[b->n] = false;
    b->n++;
}

static void body_load(body_t *b, uint32_t offset)
{
    body_emit(b, BPF_LD | BPF_W | BPF_ABS, offset, 0, 0);
}

static void body_jump(body_t *b, uint16_t op, uint32_t k, int jt, int jf)
{
    body_emit(b, BPF_JMP | op | BPF_K, k, jt, jf);
}

static void body_deny(body_t *b)
{
    body_emit(b, BPF_JMP | BPF_JA, 0, 0, 0);
    if (b->n)
        b->ja_deny[b->n - 1] = true;
}

static void body_cond(body_t *b, const cond_t *c)
{
    if (c->op == C_ZERO) {
        body_load(b, ARG_LO(c->arg));
        body_jump(b, BPF_JEQ, 0, TO_NEXT, TO_DENY);
        body_load(b, ARG_HI(c->arg));
        body_jump(b, BPF_JEQ, 0, TO_NEXT, TO_DENY);
        return;
    }
    body_load(b, ARG_LO(c->arg));
    switch (c->op) {
    case C_IN:
        /* Each match skips the remaining comparisons and the final deny. */
        for (unsigned i = 0; i < c->n; i++)
            body_jump(b, BPF_JEQ, c->v[i], (int)(c->n - i), TO_NEXT);
        body_deny(b);
        break;
    case C_NOT_IN:
        for (unsigned i = 0; i < c->n; i++)
            body_jump(b, BPF_JEQ, c->v[i], TO_DENY, TO_NEXT);
        break;
    case C_RANGE:
        body_jump(b, BPF_JGE, c->v[0], TO_NEXT, TO_DENY);
        body_jump(b, BPF_JGE, c->v[1], TO_DENY, TO_NEXT);
        break;
    case C_CLEAR:
        body_jump(b, BPF_JSET, c->v[0], TO_DENY, TO_NEXT);
        break;
    case C_BELOW:
        body_jump(b, BPF_JGE, c->v[0], TO_DENY, TO_NEXT);
        break;
    }
}

/* Appends a finished body (ending with "allow" then "deny") behind a test of the call
 * number that skips it for every other call. */
static void body_close(prog_t *p, body_t *b, long nr)
{
    unsigned allow_at = b->n;
    body_emit(b, BPF_RET | BPF_K, RET_ALLOW, 0, 0);
    unsigned deny_at = b->n;
#ifdef IMA_COVERAGE
    if (b->fall_through) /* the call number again, for the rules behind this one */
        body_load(b, offsetof(struct seccomp_data, nr));
    else
#endif
        body_emit(b, BPF_RET | BPF_K, RET_DENY(SKE_SANDBOX_DENIED_ARGS), 0, 0);
    if (b->overflow || b->n > 255) {
        p->overflow = true;
        return;
    }
    for (unsigned i = 0; i < b->n; i++) {
        struct sock_filter *f = &b->ins[i];
        if (b->ja_deny[i]) {
            f->k = deny_at - (i + 1);
            continue;
        }
        if (BPF_CLASS(f->code) != BPF_JMP)
            continue;
        int t[2] = {b->jt[i], b->jf[i]};
        for (int j = 0; j < 2; j++)
            if (t[j] == TO_ALLOW)
                t[j] = (int)(allow_at - (i + 1));
            else if (t[j] == TO_DENY)
                t[j] = (int)(deny_at - (i + 1));
        f->jt = (uint8_t)t[0];
        f->jf = (uint8_t)t[1];
    }
    emit(p, BPF_JMP | BPF_JEQ | BPF_K, (uint32_t)nr, 0, (uint8_t)b->n);
    for (unsigned i = 0; i < b->n; i++)
        emit(p, b->ins[i].code, b->ins[i].k, b->ins[i].jt, b->ins[i].jf);
}

static void rule(prog_t *p, long nr, const cond_t *c0, const cond_t *c1)
{
    body_t b = {.n = 0};
    if (c0)
        body_cond(&b, c0);
    if (c1)
        body_cond(&b, c1);
    body_close(p, &b, nr);
}

/* mmap: private mappings and anonymous shared ones (shared with no one: a partition has no
 * child) are its own memory; a shared mapping of a file only for the descriptors ima-ske
 * gave it (control block and ports), while the APEX library maps them. */
static void rule_mmap(prog_t *p, long nr, const ske_sandbox_policy_t *pol)
{
    body_t b = {.n = 0};
    body_load(&b, ARG_LO(3));
    body_jump(&b, BPF_JSET, MAP_SHARED, TO_NEXT, TO_ALLOW);
    body_jump(&b, BPF_JSET, MAP_ANONYMOUS, TO_ALLOW, TO_NEXT);
    cond_t fd = {4, C_RANGE, 2, {(uint32_t)pol->shared_fd_lo, (uint32_t)pol->shared_fd_hi}};
    if (pol->shared_fd_lo < pol->shared_fd_hi)
        body_cond(&b, &fd);
    else
        body_deny(&b);
    body_close(p, &b, nr);
}

/* ---- the policy ----------------------------------------------------------------------- */

static cond_t in1(uint8_t arg, uint32_t a) { return (cond_t){arg, C_IN, 1, {a}}; }

/* What every partition may do, in both stages (the RUN filter of a partition that may
 * not do I/O). The calls a partition makes most come first. */
static void common_calls(prog_t *p, const ske_sandbox_policy_t *pol, bool io, bool load)
{
    const cond_t clock_id = {0, C_CLEAR, 1, {0x80000000u}}; /* no other process's CPU clock */
    const cond_t self0 = in1(0, (uint32_t)pol->self);
    const cond_t self1 = in1(1, (uint32_t)pol->self);
    /* Standard output and error only, once running; before, the loader and ima-ske's child
     * may also write to their own descriptors (an exec error to ima-ske). */
    cond_t stdio = {0, C_IN, 2, {STDOUT_FILENO, STDERR_FILENO}};
    if (pol->output_fd > STDERR_FILENO)
        stdio.v[stdio.n++] = (uint32_t)pol->output_fd; /* and its output file */
    const cond_t *out_fd = io || load ? NULL : &stdio;

    allow(p, SYS_futex);
    allow(p, SYS_rt_sigprocmask); /* every switch between ARINC processes (swapcontext) */
    rule(p, SYS_clock_gettime, &clock_id, NULL);
    rule(p, SYS_clock_nanosleep, &clock_id, NULL);
    if (out_fd) {
        rule(p, SYS_write, out_fd, NULL);
        rule(p, SYS_writev, out_fd, NULL);
    } else {
        allow(p, SYS_write);
        allow(p, SYS_writev);
    }
    if (!io && pol->output_fd > STDERR_FILENO) {
        /* Its output file: made durable, never anything else */
        const cond_t output = in1(0, (uint32_t)pol->output_fd);
        rule(p, SYS_fdatasync, &output, NULL);
        rule(p, SYS_fsync, &output, NULL);
    }
    rule_mmap(p, SYS_mmap, pol);
    allow(p, SYS_mprotect);
    allow(p, SYS_munmap);
    allow(p, SYS_brk);
    allow(p, SYS_mremap);
    allow(p, SYS_msync);
    /* Advice about its own pages; not MADV_HWPOISON or MADV_SOFT_OFFLINE (100, 101), which
     * act on physical pages other processes may share. */
    const cond_t advice = {2, C_BELOW, 1, {100}};
    rule(p, SYS_madvise, &advice, NULL);
    rule(p, SYS_clock_getres, &clock_id, NULL);
    allow(p, SYS_gettimeofday);
#ifdef SYS_time
    allow(p, SYS_time);
#endif
    allow(p, SYS_nanosleep);
    allow(p, SYS_sched_yield);
    allow(p, SYS_sched_getaffinity); /* its own CPUs: the C library's thread attributes */
    allow(p, SYS_restart_syscall); /* a sleep or futex wait resumed after SIGSTOP/SIGCONT */
    allow(p, SYS_rt_sigaction);
    allow(p, SYS_rt_sigreturn);
    allow(p, SYS_sigaltstack);
    allow(p, SYS_getpid);
    allow(p, SYS_gettid);
    allow(p, SYS_getppid); /* ima-ske's: it can do nothing with it */
    rule(p, SYS_kill, &self0, NULL);
    rule(p, SYS_tkill, &self0, NULL);
    rule(p, SYS_tgkill, &self0, &self1);
    allow(p, SYS_exit);
    allow(p, SYS_exit_group);
    allow(p, SYS_getrandom);
    allow(p, SYS_sysinfo); /* the C library's qsort asks for the memory size */
    allow(p, SYS_getrusage);
    allow(p, SYS_times);
    allow(p, SYS_lseek);
    /* Reading its own limits (the C library reads its stack limit), never setting one. */
    const cond_t own = {0, C_IN, 2, {0, (uint32_t)pol->self}};
    const cond_t no_new_limit = {2, C_ZERO, 0, {0}};
    rule(p, SYS_prlimit64, &own, &no_new_limit);
#ifdef SYS_getrlimit
    allow(p, SYS_getrlimit);
#endif
    /* The C library's stdio asks what its standard output is. */
#ifdef SYS_fstat
    allow(p, SYS_fstat);
#endif
    allow(p, SYS_newfstatat);
    if (io) {
        const cond_t no_inject = {1, C_NOT_IN, 2, {TIOCSTI, TIOCLINUX}}; /* typing into a tty */
        rule(p, SYS_ioctl, &no_inject, NULL);
    } else {
        const cond_t tty_query = {1, C_IN, 2, {TCGETS, TIOCGWINSZ}}; /* isatty() */
        rule(p, SYS_ioctl, &tty_query, NULL);
    }
    allow(p, SYS_close);
}

/* Files and sockets: system partitions only. */
static void io_calls(prog_t *p)
{
    static const long any[] = {
        /* files */
        SYS_openat, SYS_read, SYS_readv, SYS_pread64, SYS_preadv, SYS_preadv2, SYS_pwrite64,
        SYS_pwritev, SYS_pwritev2, SYS_dup, SYS_dup3, SYS_fcntl, SYS_statx, SYS_faccessat,
        SYS_readlinkat, SYS_getdents64, SYS_getcwd, SYS_chdir, SYS_fchdir, SYS_mkdirat,
        SYS_unlinkat, SYS_renameat2, SYS_ftruncate, SYS_truncate, SYS_fallocate,
        SYS_fsync, SYS_fdatasync, SYS_fstatfs, SYS_statfs, SYS_flock,
        /* waiting for I/O */
        SYS_pipe2, SYS_eventfd2, SYS_ppoll, SYS_pselect6, SYS_epoll_create1, SYS_epoll_ctl,
        SYS_epoll_pwait,
        /* sockets */
        SYS_socket, SYS_socketpair, SYS_connect, SYS_bind, SYS_listen, SYS_accept, SYS_accept4,
        SYS_sendto, SYS_recvfrom, SYS_sendmsg, SYS_recvmsg, SYS_sendmmsg, SYS_recvmmsg,
        SYS_shutdown, SYS_getsockname, SYS_getpeername, SYS_setsockopt, SYS_getsockopt,
        /* what network libraries ask */
        SYS_uname, SYS_getuid, SYS_geteuid, SYS_getgid, SYS_getegid,
#ifdef SYS_open
        SYS_open, SYS_creat, SYS_stat, SYS_lstat, SYS_access, SYS_readlink, SYS_mkdir,
        SYS_unlink, SYS_rename, SYS_renameat, SYS_pipe, SYS_poll, SYS_select, SYS_epoll_wait,
        SYS_dup2,
#endif
#ifdef SYS_faccessat2
        SYS_faccessat2,
#endif
#ifdef SYS_openat2
        SYS_openat2,
#endif
#ifdef SYS_epoll_pwait2
        SYS_epoll_pwait2,
#endif
    };
    for (size_t i = 0; i < sizeof any / sizeof any[0]; i++)
        allow(p, any[i]);
}

#ifdef IMA_COVERAGE
/* Coverage builds only (cmake -DIMA_COVERAGE=ON): what libgcov needs to merge the process's
 * counters into its .gcda files when it exits or dumps them (ske/apex/src/coverage.c). First
 * in the program; a call they do not allow goes on to the partition's own rules. Normal
 * builds have none of these. */
static void rule_or_next(prog_t *p, long nr, const cond_t *c)
{
    body_t b = {.n = 0, .fall_through = true};
    body_cond(&b, c);
    body_close(p, &b, nr);
}

static void coverage_calls(prog_t *p)
{
    const cond_t gcda_open = in1(2, O_RDWR | O_CREAT); /* libgcov's open of a .gcda file */
    const cond_t gcda_lock = {1, C_IN, 2, {F_SETLKW, F_GETFL}};
    const cond_t fsize = in1(1, RLIMIT_FSIZE); /* lifted before the dump */
    rule_or_next(p, SYS_openat, &gcda_open);
    rule_or_next(p, SYS_fcntl, &gcda_lock);
    rule_or_next(p, SYS_prlimit64, &fsize);
    allow(p, SYS_read);
    allow(p, SYS_write);
}
#endif

/* What the program loader, the C library's start-up and the APEX library's attachment need
 * before the RUN filter is in place. */
static void load_calls(prog_t *p, const ske_sandbox_policy_t *pol, bool io)
{
    allow(p, SYS_execve); /* ima-ske's own exec of the partition's program */
    if (!io) {
        /* Shared libraries and the C library's own files, read-only. */
        const cond_t read_only = {2, C_CLEAR, 1, {O_ACCMODE | O_CREAT | O_TRUNC}};
        rule(p, SYS_openat, &read_only, NULL);
#ifdef SYS_open
        const cond_t read_only1 = {1, C_CLEAR, 1, {O_ACCMODE | O_CREAT | O_TRUNC}};
        rule(p, SYS_open, &read_only1, NULL);
        allow(p, SYS_access);
        allow(p, SYS_readlink);
        allow(p, SYS_stat);
        allow(p, SYS_lstat);
#endif
        allow(p, SYS_read);
        allow(p, SYS_pread64);
        allow(p, SYS_faccessat);
#ifdef SYS_faccessat2
        allow(p, SYS_faccessat2);
#endif
        allow(p, SYS_readlinkat);
        allow(p, SYS_statx);
    }
#ifdef SYS_arch_prctl
    allow(p, SYS_arch_prctl);
#endif
    allow(p, SYS_set_tid_address);
    allow(p, SYS_set_robust_list);
#ifdef SYS_rseq
    allow(p, SYS_rseq);
#endif
    const cond_t prctl_ops = {0, C_IN, 6,
                              {PR_SET_NO_NEW_PRIVS, PR_SET_TIMERSLACK, PR_GET_TIMERSLACK,
                               PR_SET_NAME, PR_GET_NAME, PR_SET_VMA}};
    rule(p, SYS_prctl, &prctl_ops, NULL);
    /* Only to add a filter (which can only narrow what is allowed). */
    const cond_t set_filter = in1(0, SECCOMP_SET_MODE_FILTER);
    const cond_t no_flags = in1(1, 0);
    rule(p, SYS_seccomp, &set_filter, &no_flags);
}

int ske_sandbox_build(const ske_sandbox_policy_t *pol, ske_sandbox_stage_t stage,
                      ske_sandbox_prog_t *out)
{
#ifndef SANDBOX_ARCH
    (void)pol;
    (void)stage;
    out->len = 0;
    return -ENOSYS;
#else
    prog_t p = {out->ins, 0, SKE_SANDBOX_PROG_MAX, false};
    bool io = (pol->flags & SKE_SANDBOX_IO) != 0;
    bool load_stage = stage == SKE_SANDBOX_LOAD;
    /* A call through another ABI has other numbers: refuse it before reading the number. */
    load(&p, offsetof(struct seccomp_data, arch));
    emit(&p, BPF_JMP | BPF_JEQ | BPF_K, SANDBOX_ARCH, 1, 0);
    ret(&p, RET_DENY(SKE_SANDBOX_DENIED_ABI));
    load(&p, offsetof(struct seccomp_data, nr));
#ifdef __x86_64__
    /* x32 calls carry the native architecture and a flag bit in their number. */
    emit(&p, BPF_JMP | BPF_JGE | BPF_K, 0x40000000u, 0, 1);
    ret(&p, RET_DENY(SKE_SANDBOX_DENIED_ABI));
#endif
#ifdef IMA_COVERAGE
    coverage_calls(&p);
#endif
    common_calls(&p, pol, io, load_stage);
    if (io)
        io_calls(&p);
    if (load_stage)
        load_calls(&p, pol, io);
    ret(&p, RET_DENY(SKE_SANDBOX_DENIED_CALL));
    if (p.overflow) {
        out->len = 0;
        return -E2BIG;
    }
    out->len = (unsigned short)p.n;
    return 0;
#endif
}

int ske_sandbox_install(const ske_sandbox_prog_t *prog)
{
    if (prog->len == 0)
        return -EINVAL;
    struct sock_fprog fprog = {prog->len, (struct sock_filter *)prog->ins};
    if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0)
        return -errno;
    if (syscall(SYS_seccomp, SECCOMP_SET_MODE_FILTER, 0, &fprog) != 0)
        return -errno;
    return 0;
}
