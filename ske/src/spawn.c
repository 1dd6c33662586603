/* SPDX-License-Identifier: Apache-2.0 */
/* Partition processes: the control block a new process gets, its fork and exec (confined
 * between the two), its attach, its end (reaped, recorded) and its kill. */
#include "ske__supervisor.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/personality.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ske__coverage.h"
#include "ske__sandbox.h"

extern char **environ;

#define READY_TIMEOUT_NS 10000000000LL /* a partition must attach within 10 s */

const char *ske__pstate_name(ske_pstate_t s)
{
    switch (s) {
    case SKE_PS_NOT_STARTED: return "not_started";
    case SKE_PS_RUNNING: return "running";
    case SKE_PS_STOPPED: return "stopped";
    case SKE_PS_EXITED: return "exited";
    case SKE_PS_CRASHED: return "crashed";
    case SKE_PS_IDLE: return "idle";
    }
    return "?";
}

bool ske__alive(const ske_part_t *p)
{
    return p->state == SKE_PS_RUNNING || p->state == SKE_PS_STOPPED;
}

/* The control block as a new process finds it: who it is, its ports, the System HM table,
 * the module schedules. */
static void fill_ctl(ske_t *s, ske_part_t *p)
{
    ske_ctl_t *c = p->ctl;
    /* The module's HM log keeps what the partition had not read when its last process
     * ended (its own end among it): a restarted recorder records it. */
    int hm_k = p->cfg->hm_log_port;
    uint32_t hm_tail = hm_k >= 0 ? atomic_load(&c->ports[hm_k].rx_tail) : 0;
    memset(c, 0, sizeof *c);
    c->magic = SKE_ABI_MAGIC;
    c->version = SKE_ABI_VERSION;
    c->ctl_size = (uint32_t)sizeof *c;
    c->partition_id = p->cfg->id;
    snprintf(c->partition_name, sizeof c->partition_name, "%s", p->cfg->name);
    snprintf(c->node, sizeof c->node, "%s", s->node);
    c->time_mode = s->time_mode;
    c->system_partition = p->cfg->system_partition;
    c->sandbox_flags = ske__sandbox_flags(p->cfg);
    /* The child's descriptor numbers: 3 the control block, 4.. its ports, then the exec-error
     * pipe, then its output file. */
    c->output_fd = p->output_fd >= 0 ? 5 + p->cfg->n_ports : -1;
    c->epoch_mono_ns = s->epoch_mono_ns;
    c->period_ns = p->cfg->period_ns;
    c->duration_ns = p->cfg->duration_ns;
    c->period_anchor_ns = p->cfg->period_anchor_ns;
    c->major_frame_ns = s->cfg->major_frame_ns;
    c->start_condition = p->start_condition;
    c->initial_mode = p->initial_mode;
    c->n_ports = (uint32_t)p->cfg->n_ports;
    for (int k = 0; k < p->cfg->n_ports; k++) {
        const ske_port_cfg_t *pc = &p->cfg->ports[k];
        ske_port_desc_t *d = &c->ports[k];
        snprintf(d->name, sizeof d->name, "%s", pc->name);
        d->kind = pc->kind;
        d->dir = pc->dir;
        d->max_size = pc->max_size;
        d->max_nb = pc->max_nb;
        d->refresh_ns = pc->refresh_ns;
        d->fd = 4 + k; /* the child's descriptor numbers: 3 is the control block */
        d->map_size = (uint32_t)p->ports[k].size;
        d->channel = pc->channel >= 0 ? (uint32_t)s->cfg->channels[pc->channel].id : 0;
        /* A (re)started partition finds its destination queues empty (its ports are
         * created anew), whatever the queue memory still holds from before; but for the
         * module's HM log, which it finds as its last process left it. */
        uint32_t head = 0, overflows = 0;
        if (pc->kind == SKE_PORT_QUEUING && pc->dir == SKE_DIR_DESTINATION && p->ports[k].mem) {
            const ske_queue_hdr_t *q = p->ports[k].mem;
            head = k == hm_k ? hm_tail : atomic_load(&q->head);
            overflows = atomic_load(&q->overflows);
        }
        atomic_store(&d->rx_tail, head);
        atomic_store(&d->overflow_ack, overflows);
    }
    atomic_store(&c->mode, p->initial_mode);
    _Static_assert(SKE_HM_STATES == HM_STATE_COUNT && SKE_HM_ERRORS == HM_ERR_COUNT,
                   "the control block's HM table has the health monitor's shape");
    memcpy(c->hm_level, s->cfg->hm.level, sizeof c->hm_level);
    const ske_module_cfg_t *m = s->cfg;
    c->n_schedules = (uint32_t)m->n_schedules;
    c->schedule_change_allowed = p->cfg->schedule_change;
    for (int i = 0; i < m->n_schedules && i < SKE_SCHEDULES; i++) {
        c->schedule_ids[i] = m->schedules[i].id;
        snprintf(c->schedule_names[i], SKE_NAME_MAX, "%s", m->schedules[i].name);
    }
    int cur = s->next_schedule;
    int32_t cur_id = m->n_schedules ? m->schedules[cur].id : 1;
    atomic_store(&c->current_schedule, cur_id);
    atomic_store(&c->next_schedule, cur_id);
    atomic_store(&c->last_switch_ns, s->last_switch_ns);
    c->duration_ns = p->cfg->duration_in[cur];
    c->period_anchor_ns = p->cfg->anchor_in[cur];
    ske__faults_fill_ctl(s, p);
    p->grant_seq = 0;
    p->mode_request_seq = 0;
}

static void child_exec(ske_t *s, ske_part_t *p, int errpipe, char **envp) __attribute__((noreturn));

/* The child gives up: ima-ske learns why from the exec-error pipe. */
static void __attribute__((noreturn)) child_fail(void)
{
    ske__coverage_child_flush();
    _exit(127);
}

static void child_exec(ske_t *s, ske_part_t *p, int errpipe, char **envp)
{
    ske__coverage_child_start();
    int n = p->cfg->n_ports;
    /* Partitions live in their own process group: a terminal's Ctrl-C reaches the SKE
     * only, which then stops them. They die with the SKE. */
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    /* Same addresses on every run: fault addresses in the trace (and anything a partition
     * derives from its own addresses) repeat, so emulated runs stay byte-identical. */
    personality(ADDR_NO_RANDOMIZE);
    /* No capability survives the exec, even for uid 0: with an empty bounding set the
     * program gains none (no CAP_SYS_PTRACE to open the SKE's descriptors, no CAP_SYS_ADMIN
     * for /proc/self/map_files, no CAP_KILL, ...), and no_new_privs keeps it that way. */
    for (int cap = 0; cap <= 63; cap++)
        prctl(PR_CAPBSET_DROP, (unsigned long)cap, 0UL, 0UL, 0UL);
    prctl(PR_SET_NO_NEW_PRIVS, 1UL, 0UL, 0UL, 0UL);
    struct sigaction dfl = {.sa_handler = SIG_DFL};
    sigaction(SIGINT, &dfl, NULL);
    sigaction(SIGTERM, &dfl, NULL);
    sigaction(SIGCHLD, &dfl, NULL);
    sigaction(SIGPIPE, &dfl, NULL); /* the SKE ignores it; a partition gets the default */
    if (p->output_fd >= 0) {
        /* A write past the file-size limit fails (EFBIG) instead of killing the writer: a
         * full disk under its output file (disk_full) is an error it sees, as ENOSPC. */
        struct sigaction ign = {.sa_handler = SIG_IGN};
        sigaction(SIGXFSZ, &ign, NULL);
        if (p->output_limit >= 0) {
            struct rlimit rl = {.rlim_cur = (rlim_t)p->output_limit, .rlim_max = RLIM_INFINITY};
            setrlimit(RLIMIT_FSIZE, &rl);
        }
    }
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, NULL);
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) {
        dup2(devnull, 0);
        close(devnull);
    }
    if (s->trace.f == stdout)
        dup2(2, 1); /* keep the JSON-lines trace on standard output clean */
    /* Move every descriptor the partition gets above the target range (3 .. 5 + the most
     * ports), then into place: 3 = control block, 4.. = its ports, then the exec-error pipe;
     * close the rest. Just above the range, so that the usual 1024-descriptor limit is no
     * limit here; a copy that cannot be made is the partition's start failing. */
    int high[SKE_MAX_PORTS + 2];
    const int base = SKE_MAX_PORTS + 6;
    bool moved = (high[0] = fcntl(p->ctl_fd, F_DUPFD, base)) >= 0;
    for (int k = 0; k < n; k++) {
        const ske_portmem_t *pm = &p->ports[k];
        int src = p->cfg->ports[k].dir == SKE_DIR_DESTINATION ? pm->fd_ro : pm->fd;
        moved &= (high[1 + k] = fcntl(src, F_DUPFD, base)) >= 0;
    }
    moved &= (high[1 + n] = fcntl(errpipe, F_DUPFD_CLOEXEC, base)) >= 0;
    int out_high = p->output_fd >= 0 ? fcntl(p->output_fd, F_DUPFD, base) : -1;
    moved &= p->output_fd < 0 || out_high >= 0;
    if (!moved) {
        int e = errno;
        ssize_t wc = write(errpipe, &e, sizeof e);
        (void)wc;
        _exit(127);
    }
    for (int k = 0; k <= n; k++)
        dup2(high[k], 3 + k);
    dup2(high[1 + n], 4 + n);
    fcntl(4 + n, F_SETFD, FD_CLOEXEC);
    int last = 4 + n;
    if (out_high >= 0) {
        dup2(out_high, 5 + n); /* its output file, kept across the exec */
        last = 5 + n;
    }
    close_range((unsigned)last + 1, ~0U, 0);
    if (getppid() != s->pid)
        child_fail(); /* the SKE is already gone */
    /* Last before the exec: the memory limit and the loader's system-call filter. A failure
     * goes to the SKE as a negative number, told apart from an exec error. */
    int confined = ske__sandbox_enter(p->cfg, 3, n, out_high >= 0 ? 5 + n : -1);
    if (confined != 0) {
        ssize_t wc = write(4 + n, &confined, sizeof confined);
        (void)wc;
        child_fail();
    }
    ske__coverage_child_flush();
    execve(p->cfg->executable, p->cfg->argv, envp);
    int e = errno;
    ssize_t w = write(4 + n, &e, sizeof e);
    (void)w;
    child_fail();
}

/* The SKE's environment with the partition's descriptors; out holds the output file's
 * variable (it lives as long as the caller's buffer). */
static char **make_env(const ske_part_t *p, char *out, size_t outlen)
{
    size_t n = 0;
    while (environ[n])
        n++;
    char **envp = calloc(n + 3, sizeof *envp);
    if (!envp)
        return NULL;
    size_t j = 0;
    for (size_t i = 0; i < n; i++)
        if (strncmp(environ[i], SKE_ENV_CTL_FD "=", strlen(SKE_ENV_CTL_FD) + 1) != 0 &&
            strncmp(environ[i], SKE_ENV_OUTPUT_FD "=", strlen(SKE_ENV_OUTPUT_FD) + 1) != 0)
            envp[j++] = environ[i];
    envp[j++] = SKE_ENV_CTL_FD "=3";
    if (p->output_fd >= 0) {
        snprintf(out, outlen, SKE_ENV_OUTPUT_FD "=%d", 5 + p->cfg->n_ports);
        envp[j++] = out;
    }
    envp[j] = NULL;
    return envp;
}

int ske__spawn(ske_t *s, ske_part_t *p, char *err, size_t errlen)
{
    fill_ctl(s, p);
    p->ended = false; /* a new process: the last one's end no longer describes the partition */
    char outvar[64];
    char **envp = make_env(p, outvar, sizeof outvar);
    int pipefd[2];
    if (!envp || pipe2(pipefd, O_CLOEXEC) != 0) {
        free(envp);
        snprintf(err, errlen, "cannot start partition '%s': %s", p->cfg->name, strerror(errno));
        return SKE_E_SYS;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        free(envp);
        close(pipefd[0]);
        close(pipefd[1]);
        snprintf(err, errlen, "fork: %s", strerror(errno));
        return SKE_E_SYS;
    }
    if (pid == 0)
        child_exec(s, p, pipefd[1], envp);
    free(envp);
    close(pipefd[1]);
    int e = 0;
    ssize_t r;
    do {
        r = read(pipefd[0], &e, sizeof e);
    } while (r < 0 && errno == EINTR);
    close(pipefd[0]);
    if (r == (ssize_t)sizeof e) {
        waitpid(pid, NULL, 0); /* reaped: its pid may be anybody's from now on */
        if (e < 0)
            snprintf(err, errlen, "cannot start partition '%s': cannot confine its process "
                     "(memory limit or system-call filter): %s", p->cfg->name, strerror(-e));
        else
            snprintf(err, errlen, "cannot start partition '%s': %s: %s", p->cfg->name,
                     p->cfg->executable, strerror(e));
        return SKE_E_PARTITION;
    }
    p->pid = pid;
    p->state = SKE_PS_RUNNING;
    p->cpu_at_yield_ns = -1;
    if (clock_getcpuclockid(pid, &p->cpu_clock) != 0)
        p->cpu_clock = (clockid_t)-1;
    /* Wait until the partition has attached and waits for its first grant, so that program
     * loading is never charged to a window. */
    int64_t t0 = ske_mono_ns();
    while (!atomic_load(&p->ctl->ready)) {
        int st;
        pid_t w = waitpid(pid, &st, WNOHANG);
        if (w == pid) {
            p->pid = 0; /* reaped: never signal that pid again */
            p->state = WIFSIGNALED(st) ? SKE_PS_CRASHED : SKE_PS_EXITED;
            p->ended = true;
            p->ended_by_signal = WIFSIGNALED(st);
            p->exit_code = WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st);
            snprintf(err, errlen, "partition '%s' (%s) %s before attaching to the SKE (%s %d)",
                     p->cfg->name, p->cfg->executable,
                     WIFSIGNALED(st) ? "was killed" : "exited",
                     WIFSIGNALED(st) ? "signal" : "status", p->exit_code);
            return SKE_E_PARTITION;
        }
        if (ske_mono_ns() - t0 > READY_TIMEOUT_NS) {
            kill(-pid, SIGKILL);
            kill(pid, SIGKILL);
            waitpid(pid, NULL, 0);
            p->pid = 0;
            p->state = SKE_PS_CRASHED;
            snprintf(err, errlen, "partition '%s' did not attach within 10 s (is it linked "
                     "with the APEX library?)", p->cfg->name);
            return SKE_E_PARTITION;
        }
        if (s->stop_signal) {
            snprintf(err, errlen, "stopped while starting partition '%s'", p->cfg->name);
            return SKE_E_PARTITION;
        }
        struct timespec ts = {0, 1000000};
        ske_futex_wait(&p->ctl->ready, 0, &ts);
    }
    /* Attached: its own filter is in place if it ever will be. A partition that is not
     * confined never gets the CPU. */
    if (ske__sandbox_verify(pid, p->cfg, err, errlen) != SKE_OK) {
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        p->pid = 0;
        p->state = SKE_PS_NOT_STARTED;
        return SKE_E_PARTITION;
    }
    return SKE_OK;
}

int64_t ske__cpu_now(const ske_part_t *p)
{
    struct timespec ts;
    if (p->cpu_clock == (clockid_t)-1 || clock_gettime(p->cpu_clock, &ts) != 0)
        return -1;
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static void record_exit(ske_t *s, ske_part_t *p, int status)
{
    /* What the partition reported before it ended comes first in the trace. */
    if (p->ctl && p->index == s->cur_partition)
        ske__drain_events(s, p, s->now_ns, s->win_end_ns);
    p->state = WIFSIGNALED(status) ? SKE_PS_CRASHED : SKE_PS_EXITED;
    p->ended = true;
    p->ended_by_signal = WIFSIGNALED(status);
    p->exit_code = WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status);
    p->pid = 0;
    p->exit_to_judge = true;
    ske_trace_begin(&s->trace, s->now_ns, "ske", "partition_exit");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    if (WIFSIGNALED(status)) {
        ske_trace_str(&s->trace, "status", "crashed");
        ske_trace_str(&s->trace, "signal", sigabbrev_np(p->exit_code) ? sigabbrev_np(p->exit_code) : "?");
    } else {
        ske_trace_str(&s->trace, "status", "exited");
        ske_trace_int(&s->trace, "code", p->exit_code);
    }
    ske_trace_end(&s->trace);
}

/* Reaps every partition that ended. */
void ske__reap(ske_t *s)
{
    s->child_event = 0;
    for (;;) {
        int st;
        pid_t w = waitpid(-1, &st, WNOHANG);
        if (w <= 0)
            return;
        for (int i = 0; i < s->cfg->n_partitions; i++)
            if (s->parts[i].pid == w && ske__alive(&s->parts[i]))
                record_exit(s, &s->parts[i], st);
    }
}

void ske__kill_partition(ske_part_t *p)
{
    if (p->pid > 0) {
        ske__coverage_dump(p->pid); /* coverage builds only: its counters first */
        kill(-p->pid, SIGKILL); /* its process group: anything it may have started, too */
        kill(p->pid, SIGKILL);
        waitpid(p->pid, NULL, 0);
        p->pid = 0;
    }
}

/* Starts a partition again. If that fails, the partition stays down and the trace says why:
 * one partition's failed restart never stops the others. */
int ske__respawn(ske_t *s, ske_part_t *p, int64_t t)
{
    char why[512] = "";
    if (ske__spawn(s, p, why, sizeof why) == SKE_OK)
        return SKE_OK;
    ske__kill_partition(p);
    p->state = SKE_PS_CRASHED;
    ske_trace_begin(&s->trace, t, "ske", "start_failed");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_str(&s->trace, "reason", why);
    ske_trace_end(&s->trace);
    return SKE_OK;
}
