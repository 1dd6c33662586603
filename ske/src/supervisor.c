/* SPDX-License-Identifier: Apache-2.0 */
/* The SKE's supervisor: starts each partition as a process holding only its own ports,
 * runs the cyclic plan by granting the CPU to one partition at a time, stops a partition
 * that keeps it past its window, moves queuing messages, and records all of it. */
#include "ske/ske.h"
#include "ske/plan.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/personality.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "canbus/client.h"
#include "ske__sandbox.h"
#include "ske__stats.h"
#include "ske__trace.h"

extern char **environ;

#define SPIN_NS 40000 /* busy-wait this long for a yield before sleeping on the futex */
#define READY_TIMEOUT_NS 10000000000LL /* a partition must attach within 10 s */
#define HANG_FACTOR 20 /* emulated mode: a window may take this many times its length in wall */
#define HANG_MIN_NS 2000000000LL /* time (at least 2 s) while using no CPU before it is cut */
#define SAMPLE_LIMIT 2000000
/* A partition that handed the CPU back has a few microseconds of system-call tail; more than
 * this much CPU before its next window means it went on computing. Above a scheduler tick
 * (4 ms at 250 Hz): the CPU clock of a process running on another CPU may lag by one. */
#define OUTSIDE_LIMIT_NS 5000000
#define RT_SPIN_NS 200000 /* real-time mode: spin this long before a window starts */
#define SYSTEM_MESSAGE_MAX (1u << 20) /* the largest MaxMessageSize the schema accepts */

typedef enum {
    PS_NOT_STARTED,
    PS_RUNNING, /* alive: waiting for a grant or holding one */
    PS_STOPPED, /* SIGSTOPped after an overrun; continued at its next window */
    PS_EXITED,
    PS_CRASHED,
    PS_IDLE, /* SET_PARTITION_MODE(IDLE) */
} pstate_t;

typedef struct {
    int fd; /* SKE's read-write descriptor */
    int fd_ro; /* read-only descriptor for destinations, -1 if not needed */
    void *mem;
    size_t size;
} portmem_t;

typedef struct {
    const ske_partition_cfg_t *cfg;
    int index;
    pid_t pid;
    pstate_t state;
    int exit_code; /* exit status or signal number */
    int ctl_fd;
    ske_ctl_t *ctl;
    portmem_t ports[SKE_MAX_PORTS];
    uint32_t grant_seq;
    uint32_t mode_request_seq;
    uint32_t start_condition;
    uint32_t initial_mode;
    clockid_t cpu_clock;
    int64_t cpu_at_yield_ns; /* -1: unknown */
    int64_t cpu_outside_max_ns;
    int64_t cpu_ns;
    uint64_t windows;
    uint64_t overruns;
    uint64_t restarts;
    bool exit_to_judge; /* ended on its own: the health monitor has yet to decide */
} part_t;

struct ske {
    const ske_module_cfg_t *cfg;
    ske_run_opts_t opts;
    ske_time_mode_t time_mode;
    char node[SKE_NAME_MAX];
    part_t parts[SKE_MAX_PARTITIONS];
    uint64_t chan_messages[SKE_MAX_CHANNELS];
    uint64_t chan_overflows[SKE_MAX_CHANNELS];
    ske_trace_t trace;
    ske_samples_t switch_ns;
    ske_samples_t jitter_ns;
    int64_t epoch_mono_ns;
    int64_t start_mono_ns;
    int64_t frames_done;
    int64_t now_ns; /* module time of the current window start */
    int64_t win_end_ns; /* and its end */
    int cur_partition; /* partition holding the current window, -1 between windows */
    int64_t prev_yield_mono_ns; /* the previous window's yield, for the switch figure */
    uint8_t *xfer; /* one message, for queue transfers */
    pid_t pid; /* the SKE's own process, for its partitions to check */
    int next_schedule; /* schedule index to run from the next major frame */
    int64_t last_switch_ns;
    bool hm_shutdown; /* a module-level SHUTDOWN: the run ends */
    bool hm_reset; /* a module-level RESET: every partition restarts at the next frame */
    uint64_t hm_events;
    volatile sig_atomic_t stop_signal;
    volatile sig_atomic_t child_event;
    char exit_reason[16];
    bool on_bus; /* windows wait for the CAN bus's time quanta */
    bool bus_stopped; /* the bus ended the run */
    canbus_client_t bus;
};

static const char *state_name(pstate_t s)
{
    switch (s) {
    case PS_NOT_STARTED: return "not_started";
    case PS_RUNNING: return "running";
    case PS_STOPPED: return "stopped";
    case PS_EXITED: return "exited";
    case PS_CRASHED: return "crashed";
    case PS_IDLE: return "idle";
    }
    return "?";
}

static const char *mode_name(uint32_t m)
{
    static const char *names[] = {"IDLE", "COLD_START", "WARM_START", "NORMAL"};
    return m < 4 ? names[m] : "?";
}

static bool alive(const part_t *p) { return p->state == PS_RUNNING || p->state == PS_STOPPED; }

void ske_request_stop(ske_t *ske, int signo) { ske->stop_signal = signo; }
void ske_notify_child(ske_t *ske) { ske->child_event = 1; }
int ske_stop_signal(const ske_t *ske) { return ske->stop_signal; }
bool ske_shut_down_by_hm(const ske_t *ske) { return ske->hm_shutdown; }

/* A spin-wait hint to the CPU (a sibling hyper-thread gets the pipeline meanwhile). */
static void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __asm__ __volatile__("pause" ::: "memory");
#elif defined(__aarch64__)
    __asm__ __volatile__("yield" ::: "memory");
#else
    atomic_signal_fence(memory_order_seq_cst);
#endif
}

/* ---- memory objects ------------------------------------------------------------------- */

static int memobj(const char *name, size_t size, void **mem)
{
    int fd = memfd_create(name, MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (fd < 0)
        return -errno;
    /* Sealed at its size: a partition holding a descriptor cannot shrink it under the SKE's
     * mapping (the SKE would die of SIGBUS on its next access). */
    /* Read-only for its owner: a descriptor handed out read-write stays so, but nobody
     * without capabilities (every partition) can open it anew for writing, e.g. a read-only
     * destination descriptor through /proc/self/fd before the APEX library closes it. */
    if (ftruncate(fd, (off_t)size) != 0 ||
        fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0 ||
        fchmod(fd, 0400) != 0) {
        int e = errno;
        close(fd);
        return -e;
    }
    void *p = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
        int e = errno;
        close(fd);
        return -e;
    }
    *mem = p;
    return fd;
}

/* A second descriptor of the same memory opened read-only: a mapping made through it can
 * never become writable, not even with mprotect(). */
static int reopen_ro(int fd)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    return open(path, O_RDONLY | O_CLOEXEC);
}

static int setup_ports(ske_t *s, char *err, size_t errlen)
{
    const ske_module_cfg_t *m = s->cfg;
    /* Sampling channels first: the source's memory object is shared by its destinations. */
    for (int pi = 0; pi < m->n_partitions; pi++) {
        part_t *p = &s->parts[pi];
        for (int k = 0; k < p->cfg->n_ports; k++) {
            const ske_port_cfg_t *pc = &p->cfg->ports[k];
            portmem_t *pm = &p->ports[k];
            pm->fd = pm->fd_ro = -1;
            if (pc->kind == SKE_PORT_SAMPLING && pc->dir == SKE_DIR_DESTINATION && pc->channel >= 0)
                continue; /* filled from the source below */
            char name[80];
            snprintf(name, sizeof name, "ima-%s-%s", p->cfg->name, pc->name);
            pm->size = pc->kind == SKE_PORT_SAMPLING ? ske_sampling_map_size(pc->max_size)
                                                     : ske_queue_map_size(pc->max_size, pc->max_nb);
            pm->fd = memobj(name, pm->size, &pm->mem);
            if (pm->fd < 0) {
                snprintf(err, errlen, "port memory for %s.%s: %s", p->cfg->name, pc->name,
                         strerror(-pm->fd));
                return SKE_E_SYS;
            }
            if (pc->kind == SKE_PORT_SAMPLING)
                ske_sampling_init(pm->mem, pc->max_size);
            else
                ske_queue_init(pm->mem, pc->max_size, pc->max_nb);
            if (pc->dir == SKE_DIR_DESTINATION) {
                pm->fd_ro = reopen_ro(pm->fd);
                if (pm->fd_ro < 0) {
                    snprintf(err, errlen, "read-only port descriptor: %s", strerror(errno));
                    return SKE_E_SYS;
                }
            }
        }
    }
    for (int c = 0; c < m->n_channels; c++) {
        const ske_channel_cfg_t *ch = &m->channels[c];
        if (ch->kind != SKE_PORT_SAMPLING)
            continue;
        const portmem_t *src = &s->parts[ch->src.partition].ports[ch->src.port];
        for (int d = 0; d < ch->n_dst; d++) {
            portmem_t *pm = &s->parts[ch->dst[d].partition].ports[ch->dst[d].port];
            pm->mem = src->mem;
            pm->size = src->size;
            pm->fd = -1;
            pm->fd_ro = reopen_ro(src->fd);
            if (pm->fd_ro < 0) {
                snprintf(err, errlen, "read-only port descriptor: %s", strerror(errno));
                return SKE_E_SYS;
            }
        }
    }
    return SKE_OK;
}

/* ---- control blocks ------------------------------------------------------------------- */

static void fill_ctl(ske_t *s, part_t *p)
{
    ske_ctl_t *c = p->ctl;
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
         * created anew), whatever the queue memory still holds from before. */
        uint32_t head = 0, overflows = 0;
        if (pc->kind == SKE_PORT_QUEUING && pc->dir == SKE_DIR_DESTINATION && p->ports[k].mem) {
            const ske_queue_hdr_t *q = p->ports[k].mem;
            head = atomic_load(&q->head);
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
    p->grant_seq = 0;
    p->mode_request_seq = 0;
}

/* ---- trace helpers -------------------------------------------------------------------- */

static void trace_mode(ske_t *s, part_t *p, int64_t t, uint32_t mode, uint32_t from, const char *why)
{
    /* The SKE's own record of a mode change it made (power-on, IDLE, restart). */
    ske_trace_begin(&s->trace, t, "ske", "mode");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_str(&s->trace, "mode", mode_name(mode));
    ske_trace_str(&s->trace, "from", mode_name(from));
    if (why)
        ske_trace_str(&s->trace, "reason", why);
    ske_trace_end(&s->trace);
}

/* ---- process management --------------------------------------------------------------- */

static void child_exec(ske_t *s, part_t *p, int errpipe, char **envp) __attribute__((noreturn));

static void child_exec(ske_t *s, part_t *p, int errpipe, char **envp)
{
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
    /* Move every descriptor the partition gets above the target range, then into place:
     * 3 = control block, 4.. = its ports, then the exec-error pipe; close the rest. */
    int high[SKE_MAX_PORTS + 2];
    const int base = 1024;
    high[0] = fcntl(p->ctl_fd, F_DUPFD, base);
    for (int k = 0; k < n; k++) {
        const portmem_t *pm = &p->ports[k];
        int src = p->cfg->ports[k].dir == SKE_DIR_DESTINATION ? pm->fd_ro : pm->fd;
        high[1 + k] = fcntl(src, F_DUPFD, base);
    }
    high[1 + n] = fcntl(errpipe, F_DUPFD_CLOEXEC, base);
    for (int k = 0; k <= n; k++)
        dup2(high[k], 3 + k);
    dup2(high[1 + n], 4 + n);
    fcntl(4 + n, F_SETFD, FD_CLOEXEC);
    close_range(5 + (unsigned)n, ~0U, 0);
    if (getppid() != s->pid)
        _exit(127); /* the SKE is already gone */
    /* Last before the exec: the memory limit and the loader's system-call filter. A failure
     * goes to the SKE as a negative number, told apart from an exec error. */
    int confined = ske__sandbox_enter(p->cfg, 3, n);
    if (confined != 0) {
        ssize_t wc = write(4 + n, &confined, sizeof confined);
        (void)wc;
        _exit(127);
    }
    execve(p->cfg->executable, p->cfg->argv, envp);
    int e = errno;
    ssize_t w = write(4 + n, &e, sizeof e);
    (void)w;
    _exit(127);
}

static char **make_env(void)
{
    size_t n = 0;
    while (environ[n])
        n++;
    char **envp = calloc(n + 2, sizeof *envp);
    if (!envp)
        return NULL;
    size_t j = 0;
    for (size_t i = 0; i < n; i++)
        if (strncmp(environ[i], SKE_ENV_CTL_FD "=", strlen(SKE_ENV_CTL_FD) + 1) != 0)
            envp[j++] = environ[i];
    envp[j++] = SKE_ENV_CTL_FD "=3";
    envp[j] = NULL;
    return envp;
}

static int spawn(ske_t *s, part_t *p, char *err, size_t errlen)
{
    fill_ctl(s, p);
    char **envp = make_env();
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
    p->state = PS_RUNNING;
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
            p->state = WIFSIGNALED(st) ? PS_CRASHED : PS_EXITED;
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
            p->state = PS_CRASHED;
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
        p->state = PS_NOT_STARTED;
        return SKE_E_PARTITION;
    }
    return SKE_OK;
}

static int64_t cpu_now(const part_t *p)
{
    struct timespec ts;
    if (p->cpu_clock == (clockid_t)-1 || clock_gettime(p->cpu_clock, &ts) != 0)
        return -1;
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static void drain_events(ske_t *s, part_t *p, int64_t win_start, int64_t win_end);

static void record_exit(ske_t *s, part_t *p, int status)
{
    /* What the partition reported before it ended comes first in the trace. */
    if (p->ctl && p->index == s->cur_partition)
        drain_events(s, p, s->now_ns, s->win_end_ns);
    p->state = WIFSIGNALED(status) ? PS_CRASHED : PS_EXITED;
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
static void reap(ske_t *s)
{
    s->child_event = 0;
    for (;;) {
        int st;
        pid_t w = waitpid(-1, &st, WNOHANG);
        if (w <= 0)
            return;
        for (int i = 0; i < s->cfg->n_partitions; i++)
            if (s->parts[i].pid == w && alive(&s->parts[i]))
                record_exit(s, &s->parts[i], st);
    }
}

static void kill_partition(part_t *p)
{
    if (p->pid > 0) {
        kill(-p->pid, SIGKILL); /* its process group: anything it may have started, too */
        kill(p->pid, SIGKILL);
        waitpid(p->pid, NULL, 0);
        p->pid = 0;
    }
}

/* ---- health monitoring ------------------------------------------------------------------ */

/* The system state a partition is in, as far as the SKE can tell. */
static hm_state_t partition_state(const part_t *p)
{
    uint32_t mode = p->ctl ? atomic_load(&p->ctl->mode) : SKE_MODE_COLD_START;
    return mode == SKE_MODE_NORMAL ? HM_STATE_PROCESS : HM_STATE_PARTITION_INIT;
}

/* Writes an hm event's fields; the caller ends it (ske_trace_end). */
static void trace_hm_fields(ske_t *s, int64_t t, const part_t *p, hm_error_t err, hm_level_t level,
                            hm_action_t action, hm_state_t state, int32_t process,
                            const char *pname, const char *message, size_t mlen, const char *note)
{
    s->hm_events++;
    ske_trace_begin(&s->trace, t, level == HM_LEVEL_PROCESS ? p->cfg->name : "ske", "hm");
    ske_trace_str(&s->trace, "error", hm_error_name(err));
    ske_trace_str(&s->trace, "level", hm_level_name(level));
    ske_trace_str(&s->trace, "action", hm_action_name(action));
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    if (pname)
        ske_trace_str(&s->trace, "process", pname);
    else
        ske_trace_raw(&s->trace, "process", "null");
    ske_trace_int(&s->trace, "process_id", process);
    ske_trace_str(&s->trace, "state", hm_state_name(state));
    ske_trace_int(&s->trace, "error_code", hm_apex_error_code(err));
    if (message && mlen)
        ske_trace_strn(&s->trace, "message", message, mlen);
    if (note)
        ske_trace_str(&s->trace, "note", note);
}

static void trace_hm(ske_t *s, int64_t t, const part_t *p, hm_error_t err, hm_level_t level,
                     hm_action_t action, hm_state_t state, int32_t process, const char *pname,
                     const char *message, size_t mlen, const char *note)
{
    trace_hm_fields(s, t, p, err, level, action, state, process, pname, message, mlen, note);
    ske_trace_end(&s->trace);
}

static int spawn(ske_t *s, part_t *p, char *err, size_t errlen);

/* Starts a partition again. If that fails, the partition stays down and the trace says why:
 * one partition's failed restart never stops the others. */
static int respawn(ske_t *s, part_t *p, int64_t t)
{
    char why[512] = "";
    if (spawn(s, p, why, sizeof why) == SKE_OK)
        return SKE_OK;
    kill_partition(p);
    p->state = PS_CRASHED;
    ske_trace_begin(&s->trace, t, "ske", "start_failed");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_str(&s->trace, "reason", why);
    ske_trace_end(&s->trace);
    return SKE_OK;
}

/* A partition-level action of the Partition HM table (ARINC 653 Part 1, 2.4.2). */
static int apply_partition_action(ske_t *s, part_t *p, hm_action_t action, int64_t t, char *err,
                                  size_t errlen)
{
    uint32_t cur = p->ctl ? atomic_load(&p->ctl->mode) : SKE_MODE_NORMAL;
    switch (action) {
    case HM_ACT_IDLE:
        kill_partition(p);
        p->state = PS_IDLE;
        trace_mode(s, p, t, SKE_MODE_IDLE, cur, "health monitor");
        return SKE_OK;
    case HM_ACT_WARM_START:
    case HM_ACT_COLD_START: {
        uint32_t mode = action == HM_ACT_WARM_START ? SKE_MODE_WARM_START : SKE_MODE_COLD_START;
        kill_partition(p);
        trace_mode(s, p, t, mode, cur, "health monitor");
        p->start_condition = 3; /* HM_PARTITION_RESTART */
        p->initial_mode = mode;
        p->restarts++;
        p->state = PS_NOT_STARTED;
        return respawn(s, p, t);
    }
    default:
        return SKE_OK;
    }
}

/* Applies the health monitor's decision on an error that reached the SKE: the partition could
 * not handle it, or the SKE detected it itself. The decision is hm_decide's, from the SKE's own
 * copy of the tables, never from the partition's. */
static int hm_handle(ske_t *s, part_t *p, int64_t t, hm_error_t e, hm_state_t state,
                     hm_origin_t origin, int32_t process, const char *pname, const char *msg,
                     size_t mlen, bool fatal, char *err, size_t errlen)
{
    /* Whatever reaches the SKE no error handler could take. A partition already ended has no
     * context left that could hang. */
    hm_decision_t d = hm_decide(&s->cfg->hm, &p->cfg->hm, state, e, origin, false,
                                fatal && alive(p));
    /* A module decision is the module's; what it leaves to the partition is told apart. */
    bool module_note = d.level == HM_LEVEL_MODULE && d.note;
    trace_hm(s, t, p, e, d.level, d.action, state, process, pname, msg, mlen,
             module_note ? NULL : d.note);
    if (d.level == HM_LEVEL_MODULE && d.action == HM_ACT_SHUTDOWN)
        s->hm_shutdown = true;
    else if (d.level == HM_LEVEL_MODULE && d.action == HM_ACT_RESET)
        s->hm_reset = true;
    if (module_note) {
        ske_trace_begin(&s->trace, t, "ske", "hm_note");
        ske_trace_str(&s->trace, "partition", p->cfg->name);
        ske_trace_str(&s->trace, "note", d.note);
        ske_trace_end(&s->trace);
    }
    return apply_partition_action(s, p, d.partition_action, t, err, errlen);
}

/* An error the partition posted (partition or module level). Every field is checked. */
static int hm_take_post(ske_t *s, part_t *p, int64_t t, char *err, size_t errlen)
{
    ske_ctl_t *c = p->ctl;
    uint32_t seq = atomic_load(&c->hm_seq);
    if (seq == atomic_load(&c->hm_ack))
        return SKE_OK;
    hm_error_t e = (hm_error_t)c->hm_error;
    hm_state_t st = (hm_state_t)c->hm_state;
    char pname[SKE_NAME_MAX], msg[SKE_EVENT_TEXT];
    memcpy(pname, c->hm_process_name, sizeof pname);
    pname[sizeof pname - 1] = '\0';
    size_t mlen = c->hm_len < sizeof msg ? c->hm_len : sizeof msg;
    memcpy(msg, c->hm_message, mlen);
    int32_t process = c->hm_process;
    bool fatal = c->hm_fatal != 0;
    atomic_store(&c->hm_ack, seq); /* the partition goes on once the action is decided */
    if (!hm_error_name(e) || !hm_state_name(st) || e == HM_ERR_WINDOW_OVERRUN || e == HM_ERR_PARTITION_EXIT)
        return SKE_OK; /* not an error a partition can report */
    /* The failed process's name; none for the initialisation process (the error handler,
     * whose identifier is 0 too, has one). */
    hm_origin_t origin = !pname[0]     ? HM_ORIGIN_PARTITION
                         : process == 0 ? HM_ORIGIN_ERROR_HANDLER
                                        : HM_ORIGIN_PROCESS;
    return hm_handle(s, p, t, e, st, origin, process, pname[0] ? pname : NULL, msg, mlen, fatal,
                     err, errlen);
}

/* Applies a pending module RESET: every partition starts again (ARINC 653 Part 1, 2.4.2). */
static int hm_module_reset(ske_t *s, int64_t t, char *err, size_t errlen)
{
    s->hm_reset = false;
    for (int i = 0; i < s->cfg->n_partitions; i++) {
        part_t *p = &s->parts[i];
        uint32_t cur = p->ctl ? atomic_load(&p->ctl->mode) : SKE_MODE_IDLE;
        kill_partition(p);
        trace_mode(s, p, t, SKE_MODE_COLD_START, cur, "module reset");
        p->start_condition = 2; /* HM_MODULE_RESTART */
        p->initial_mode = SKE_MODE_COLD_START;
        p->restarts++;
        p->state = PS_NOT_STARTED;
        respawn(s, p, t);
    }
    (void)err;
    (void)errlen;
    return SKE_OK;
}

/* ---- one window ----------------------------------------------------------------------- */

typedef enum { W_YIELD, W_OVERRUN, W_EXIT, W_STOP } wres_t;

/* Why a window ended in an overrun (the trace's `cause`). */
typedef enum {
    OV_CPU_BUDGET, /* emulated: used the window's length in CPU time */
    OV_WALL_LIMIT, /* emulated: held the window far longer in wall time without using CPU */
    OV_WINDOW_END, /* real time: still running at the window's wall-clock end */
} ov_cause_t;

static const char *const ov_cause_names[] = {"cpu_budget", "wall_limit", "window_end"};


static bool yielded(const part_t *p)
{
    return atomic_load_explicit(&p->ctl->yield_seq, memory_order_acquire) == p->grant_seq;
}

/* Waits for the partition to hand the CPU back. Emulated mode: the window's length is a
 * budget of CPU time (computation takes no emulated time, but it may not take unbounded
 * real time either). Real-time mode: the window ends at its wall-clock end. */
static wres_t wait_yield(ske_t *s, part_t *p, int64_t budget_ns, int64_t end_mono_ns, int64_t cpu0,
                         ov_cause_t *cause)
{
    int64_t t0 = ske_mono_ns();
    /* Most windows of a light partition end within microseconds: notice that at once. */
    for (uint32_t i = 1;; i++) {
        if (yielded(p))
            return W_YIELD;
        cpu_relax();
        if ((i & 63) == 0 && (ske_mono_ns() - t0 > SPIN_NS || s->child_event || s->stop_signal))
            break;
    }
    for (;;) {
        if (yielded(p))
            return W_YIELD;
        if (s->child_event) {
            reap(s);
            if (!alive(p))
                return W_EXIT;
        }
        if (s->stop_signal)
            return W_STOP;
        int64_t now = ske_mono_ns();
        int64_t wait_ns;
        if (s->time_mode == SKE_TIME_REALTIME) {
            wait_ns = end_mono_ns - now;
            if (wait_ns <= 0) {
                *cause = OV_WINDOW_END;
                return W_OVERRUN;
            }
        } else {
            int64_t used = cpu0 >= 0 ? cpu_now(p) - cpu0 : now - t0;
            if (used >= budget_ns) {
                *cause = OV_CPU_BUDGET;
                return W_OVERRUN;
            }
            int64_t hang = budget_ns * HANG_FACTOR > HANG_MIN_NS ? budget_ns * HANG_FACTOR : HANG_MIN_NS;
            if (now - t0 > hang) {
                *cause = OV_WALL_LIMIT; /* blocked without using its CPU: the plan cannot wait */
                return W_OVERRUN;
            }
            wait_ns = budget_ns - used;
            if (wait_ns > 10000000)
                wait_ns = 10000000;
            if (wait_ns < 50000)
                wait_ns = 50000;
        }
        atomic_store(&p->ctl->ske_sleeping, 1);
        uint32_t v = atomic_load(&p->ctl->yield_seq);
        if (v != p->grant_seq) {
            struct timespec ts = {wait_ns / 1000000000LL, wait_ns % 1000000000LL};
            ske_futex_wait(&p->ctl->yield_seq, v, &ts);
        }
        atomic_store(&p->ctl->ske_sleeping, 0);
    }
}

/* Moves the messages a source queuing port holds to the destination's queue, as the core
 * software does at the end of the source's window (ARINC 653 Part 1, queuing mode). */
static void transfer_queues(ske_t *s, part_t *p, int64_t t_ns)
{
    const ske_module_cfg_t *m = s->cfg;
    for (int k = 0; k < p->cfg->n_ports; k++) {
        const ske_port_cfg_t *pc = &p->cfg->ports[k];
        if (pc->kind != SKE_PORT_QUEUING || pc->dir != SKE_DIR_SOURCE || pc->channel < 0)
            continue;
        const ske_channel_cfg_t *ch = &m->channels[pc->channel];
        part_t *dp = &s->parts[ch->dst[0].partition];
        const ske_port_cfg_t *dc = &dp->cfg->ports[ch->dst[0].port];
        ske_queue_hdr_t *sq = p->ports[k].mem;
        void *dq = dp->ports[ch->dst[0].port].mem;
        ske_port_desc_t *dd = &dp->ctl->ports[ch->dst[0].port];
        uint32_t stail = atomic_load(&sq->tail);
        uint32_t n = ske_queue_count(sq, pc->max_nb, stail);
        if (n == UINT32_MAX) {
            /* The source wrote inconsistent indices into its own queue: drop its content. */
            atomic_store(&sq->tail, atomic_load(&sq->head));
            ske_trace_begin(&s->trace, t_ns, "ske", "port");
            ske_trace_str(&s->trace, "event", "corrupt");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_str(&s->trace, "port", pc->name);
            ske_trace_end(&s->trace);
            continue;
        }
        uint8_t *buf = s->xfer;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t len;
            int64_t mt;
            ske_queue_peek(sq, pc->max_size, pc->max_nb, stail, buf, &len, &mt);
            stail++;
            uint32_t dtail = atomic_load(&dd->rx_tail);
            if (ske_queue_count(dq, dc->max_nb, dtail) == UINT32_MAX) {
                /* The destination corrupted its consumer index: resynchronise it. */
                atomic_store(&dd->rx_tail, atomic_load(&((ske_queue_hdr_t *)dq)->head));
                dtail = atomic_load(&dd->rx_tail);
            }
            /* Stamped with its arrival, the end of the source's window: a receiver whose
             * time-out comes later gets it, one whose time-out came first does not. */
            (void)mt;
            if (ske_queue_push(dq, dc->max_size, dc->max_nb, dtail, buf, len, t_ns)) {
                s->chan_messages[pc->channel]++;
            } else {
                atomic_fetch_add(&((ske_queue_hdr_t *)dq)->overflows, 1);
                s->chan_overflows[pc->channel]++;
                ske_trace_begin(&s->trace, t_ns, "ske", "port");
                ske_trace_str(&s->trace, "event", "overflow");
                ske_trace_str(&s->trace, "channel", ch->name);
                ske_trace_str(&s->trace, "partition", dp->cfg->name);
                ske_trace_str(&s->trace, "port", dc->name);
                ske_trace_end(&s->trace);
            }
        }
        atomic_store(&sq->tail, stail);
    }
}

/* Copies the partition's events into the trace. The ring is written by the partition, so
 * every field is checked; an event claiming a time outside the window is kept but marked. */
static void drain_events(ske_t *s, part_t *p, int64_t win_start, int64_t win_end)
{
    ske_ctl_t *c = p->ctl;
    uint32_t head = atomic_load_explicit(&c->ev_head, memory_order_acquire);
    uint32_t tail = atomic_load(&c->ev_tail);
    uint32_t n = head - tail;
    if (n > SKE_EVENT_RING) {
        atomic_store(&c->ev_tail, head);
        return;
    }
    for (; tail != head; tail++) {
        ske_event_t e = c->ev[tail % SKE_EVENT_RING];
        int64_t t = e.t_ns;
        bool suspect = t < win_start || t > win_end;
        if (suspect)
            t = win_start;
        uint32_t len = e.len < SKE_EVENT_TEXT ? e.len : SKE_EVENT_TEXT;
        switch (e.kind) {
        case SKE_EV_MODE:
            if (e.a < 0 || e.a > 3 || e.b < 0 || e.b > 3)
                continue;
            ske_trace_begin(&s->trace, t, p->cfg->name, "mode");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_str(&s->trace, "mode", mode_name((uint32_t)e.a));
            ske_trace_str(&s->trace, "from", mode_name((uint32_t)e.b));
            break;
        case SKE_EV_PORT_VALIDITY:
            if (e.a < 0 || e.a >= p->cfg->n_ports)
                continue;
            ske_trace_begin(&s->trace, t, p->cfg->name, "port");
            ske_trace_str(&s->trace, "event", e.b ? "valid" : "invalid");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_str(&s->trace, "port", p->cfg->ports[e.a].name);
            break;
        case SKE_EV_APP_MESSAGE:
            ske_trace_begin(&s->trace, t, p->cfg->name, "app_message");
            ske_trace_int(&s->trace, "process", e.a);
            ske_trace_strn(&s->trace, "text", e.text, len);
            break;
        case SKE_EV_HM: {
            /* Decided in the partition: its error handler takes the error. */
            hm_error_t he = (hm_error_t)e.a;
            if (!hm_error_name(he) || len < SKE_NAME_MAX)
                continue;
            char pname[SKE_NAME_MAX];
            memcpy(pname, e.text, sizeof pname);
            pname[sizeof pname - 1] = '\0';
            trace_hm_fields(s, t, p, he, HM_LEVEL_PROCESS, HM_ACT_ERROR_HANDLER, HM_STATE_PROCESS,
                            e.b, pname, e.text + SKE_NAME_MAX, len - SKE_NAME_MAX, NULL);
            break;
        }
        case SKE_EV_PROCESS:
            ske_trace_begin(&s->trace, t, p->cfg->name, "process");
            ske_trace_int(&s->trace, "process", e.a);
            ske_trace_strn(&s->trace, "name", e.text, strnlen(e.text, len));
            ske_trace_str(&s->trace, "event", e.b == SKE_PROC_EV_START ? "start" : "stop");
            break;
        default:
            continue;
        }
        if (suspect) {
            ske_trace_bool(&s->trace, "suspect_time", true);
            ske_trace_int(&s->trace, "reported_t_ns", e.t_ns);
        }
        ske_trace_end(&s->trace);
    }
    atomic_store(&c->ev_tail, head);
    uint32_t dropped = atomic_exchange(&c->ev_dropped, 0);
    if (dropped) {
        ske_trace_begin(&s->trace, win_end, "ske", "events_dropped");
        ske_trace_str(&s->trace, "partition", p->cfg->name);
        ske_trace_int(&s->trace, "count", dropped);
        ske_trace_end(&s->trace);
    }
}

/* A partition asked for IDLE or a restart through SET_PARTITION_MODE. */
static int handle_mode_request(ske_t *s, part_t *p, int64_t t, char *err, size_t errlen)
{
    uint32_t seq = atomic_load(&p->ctl->mode_request_seq);
    if (seq == p->mode_request_seq)
        return SKE_OK;
    p->mode_request_seq = seq;
    uint32_t req = atomic_load(&p->ctl->mode_request);
    uint32_t cur = atomic_load(&p->ctl->mode);
    if (req == SKE_MODE_IDLE) {
        kill_partition(p);
        p->state = PS_IDLE;
        trace_mode(s, p, t, SKE_MODE_IDLE, cur, "SET_PARTITION_MODE");
        return SKE_OK;
    }
    if (req == SKE_MODE_COLD_START || req == SKE_MODE_WARM_START) {
        kill_partition(p);
        trace_mode(s, p, t, req, cur, "SET_PARTITION_MODE");
        p->start_condition = 1; /* PARTITION_RESTART */
        p->initial_mode = req;
        p->restarts++;
        p->state = PS_NOT_STARTED;
        return respawn(s, p, t);
    }
    (void)err;
    (void)errlen;
    return SKE_OK;
}

/* A partition asked for another module schedule (SET_MODULE_SCHEDULE): checked again here,
 * it takes effect at the next major frame (ARINC 653 Part 2, 3.2). */
static void take_schedule_request(ske_t *s, part_t *p, int64_t t)
{
    ske_ctl_t *c = p->ctl;
    uint32_t seq = atomic_load(&c->schedule_request_seq);
    if (seq == atomic_load(&c->schedule_request_ack))
        return;
    atomic_store(&c->schedule_request_ack, seq);
    int32_t id = atomic_load(&c->schedule_request);
    const ske_module_cfg_t *m = s->cfg;
    int to = -1;
    for (int i = 0; i < m->n_schedules; i++)
        if (m->schedules[i].id == id)
            to = i;
    if (to < 0 || !p->cfg->schedule_change)
        return; /* the partition's APEX already refused it */
    s->next_schedule = to;
    ske_trace_begin(&s->trace, t, "ske", "schedule_request");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_int(&s->trace, "schedule", id);
    ske_trace_str(&s->trace, "name", m->schedules[to].name);
    ske_trace_end(&s->trace);
    for (int i = 0; i < m->n_partitions; i++)
        if (s->parts[i].ctl)
            atomic_store(&s->parts[i].ctl->next_schedule, id);
}

/* Runs schedule `to` from the frame starting at t: every partition's control block follows. */
static void switch_schedule(ske_t *s, ske_slot_t *slot, int to)
{
    const ske_module_cfg_t *m = s->cfg;
    int from = slot->schedule;
    ske_plan_switch(m, slot, to);
    s->last_switch_ns = slot->frame * m->major_frame_ns;
    ske_trace_begin(&s->trace, s->last_switch_ns, "ske", "schedule_switch");
    ske_trace_int(&s->trace, "from", m->schedules[from].id);
    ske_trace_int(&s->trace, "to", m->schedules[to].id);
    ske_trace_str(&s->trace, "name", m->schedules[to].name);
    ske_trace_int(&s->trace, "frame", slot->frame);
    ske_trace_end(&s->trace);
    for (int i = 0; i < m->n_partitions; i++) {
        ske_ctl_t *c = s->parts[i].ctl;
        if (!c)
            continue;
        atomic_store(&c->current_schedule, m->schedules[to].id);
        atomic_store(&c->next_schedule, m->schedules[to].id);
        atomic_store(&c->last_switch_ns, s->last_switch_ns);
        c->duration_ns = m->partitions[i].duration_in[to];
        c->period_anchor_ns = m->partitions[i].anchor_in[to];
    }
}

/* A partition whose process ended without being asked to: PARTITION_EXIT. */
static int judge_exits(ske_t *s, int64_t t, char *err, size_t errlen)
{
    for (int i = 0; i < s->cfg->n_partitions; i++) {
        part_t *p = &s->parts[i];
        if (!p->exit_to_judge)
            continue;
        p->exit_to_judge = false;
        int rc = SKE_OK;
        if (p->ctl)
            rc = hm_take_post(s, p, t, err, errlen); /* what it reported before it ended */
        if (rc != SKE_OK)
            return rc;
        if (p->state != PS_EXITED && p->state != PS_CRASHED)
            continue; /* the health monitor already idled or restarted it */
        char msg[64];
        int n = p->state == PS_CRASHED
                    ? snprintf(msg, sizeof msg, "killed by SIG%s",
                               sigabbrev_np(p->exit_code) ? sigabbrev_np(p->exit_code) : "?")
                    : snprintf(msg, sizeof msg, "exited with status %d", p->exit_code);
        rc = hm_handle(s, p, t, HM_ERR_PARTITION_EXIT, partition_state(p), HM_ORIGIN_SKE, 0,
                       NULL, msg, (size_t)n, false, err, errlen);
        if (rc != SKE_OK)
            return rc;
    }
    return SKE_OK;
}

static int run_window(ske_t *s, const ske_slot_t *slot, char *err, size_t errlen)
{
    const ske_window_cfg_t *w = slot->window;
    part_t *p = &s->parts[w->partition];
    int64_t frame = slot->frame;
    int64_t start = slot->start_ns;
    int64_t end = slot->end_ns;
    s->now_ns = start;
    s->win_end_ns = end;
    s->cur_partition = -1;
    bool rt = s->time_mode == SKE_TIME_REALTIME;
    int64_t start_mono = s->epoch_mono_ns + start;
    int64_t late = 0;
    if (rt) {
        /* Sleep until shortly before the window, then spin to its exact start: a sleeping
         * thread wakes tens of microseconds late, a spinning one within a microsecond. */
        int64_t wake = start_mono - RT_SPIN_NS;
        struct timespec ts = {wake / 1000000000LL, wake % 1000000000LL};
        while (ske_mono_ns() < wake &&
               clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
            if (s->stop_signal)
                return SKE_OK;
            if (s->child_event)
                reap(s);
        }
        while (ske_mono_ns() < start_mono)
            cpu_relax();
        late = ske_mono_ns() - start_mono;
    }
    if (s->child_event)
        reap(s);

    ske_trace_begin(&s->trace, start, "ske", "window_start");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_int(&s->trace, "window", w->id);
    ske_trace_int(&s->trace, "frame", frame);
    if (!alive(p))
        ske_trace_str(&s->trace, "partition_state", state_name(p->state));
    if (rt)
        ske_trace_int(&s->trace, "late_ns", late);
    ske_trace_end(&s->trace);

    wres_t r = W_EXIT;
    ov_cause_t cause = OV_CPU_BUDGET;
    bool granted = false;
    int64_t outside_ns = 0; /* CPU the partition used since it last handed the CPU back */
    if (alive(p)) {
        granted = true;
        s->cur_partition = w->partition;
        int64_t cpu0 = cpu_now(p);
        if (p->cpu_at_yield_ns >= 0 && cpu0 >= 0) {
            outside_ns = cpu0 - p->cpu_at_yield_ns;
            if (outside_ns > p->cpu_outside_max_ns)
                p->cpu_outside_max_ns = outside_ns;
        }
        if (outside_ns > OUTSIDE_LIMIT_NS) {
            /* It handed the CPU back but went on computing between its windows (the
             * kernel's accounting says so): time taken from the other partitions. */
            ske_trace_begin(&s->trace, start, "ske", "overrun");
            ske_trace_str(&s->trace, "partition", p->cfg->name);
            ske_trace_int(&s->trace, "window", w->id);
            ske_trace_int(&s->trace, "frame", frame);
            ske_trace_str(&s->trace, "cause", "outside_window");
            ske_trace_str(&s->trace, "action", "reported");
            ske_trace_end(&s->trace);
            p->overruns++;
        }
        if (p->state == PS_STOPPED) {
            kill(p->pid, SIGCONT);
            p->state = PS_RUNNING;
        }
        atomic_store(&p->ctl->win_start_ns, start);
        atomic_store(&p->ctl->win_end_ns, end);
        p->grant_seq++;
        atomic_store_explicit(&p->ctl->grant_seq, p->grant_seq, memory_order_release);
        ske_futex_wake(&p->ctl->grant_seq);
        p->windows++;
        pid_t granted_pid = p->pid;
        r = wait_yield(s, p, w->duration_ns, s->epoch_mono_ns + end, cpu0, &cause);
        /* A partition that posted an error waits for the decision: take it now and, if the
         * partition goes on (IGNORE), give it the rest of its window, still on the same
         * CPU budget. What it reported before the error comes first in the trace. */
        while (r == W_YIELD && alive(p) && atomic_load(&p->ctl->hm_seq) != atomic_load(&p->ctl->hm_ack)) {
            drain_events(s, p, start, end);
            int64_t at = p->ctl->hm_t_ns;
            at = at < start ? start : at > end ? end : at;
            pid_t before = p->pid;
            int hrc = hm_take_post(s, p, at, err, errlen);
            if (hrc != SKE_OK)
                return hrc;
            /* Idled, shut down, or restarted (a new process starts in its next window). */
            if (!alive(p) || s->hm_shutdown || p->pid != before)
                break;
            p->grant_seq++;
            atomic_store_explicit(&p->ctl->grant_seq, p->grant_seq, memory_order_release);
            ske_futex_wake(&p->ctl->grant_seq);
            r = wait_yield(s, p, w->duration_ns, s->epoch_mono_ns + end, cpu0, &cause);
        }
        /* A process restarted by the health monitor has a clock of its own: this window's
         * accounting is the granted process's only. */
        bool same = p->pid == granted_pid;
        int64_t cpu1 = same ? cpu_now(p) : -1;
        if (r == W_OVERRUN) {
            /* No waiting for the stop to take effect: a process with SIGSTOP pending cannot
             * return to user space, so it computes nothing more whether it is on a CPU now or
             * waiting for one; waiting for it could only delay the next window. A stop that
             * has not landed yet when the partition's next window comes is discarded by
             * that window's SIGCONT. */
            kill(p->pid, SIGSTOP);
            if (yielded(p)) {
                kill(p->pid, SIGCONT); /* it handed the CPU back in the instant before */
                r = W_YIELD;
            } else {
                p->state = PS_STOPPED;
                p->overruns++;
            }
        }
        if (cpu0 >= 0 && cpu1 >= 0)
            p->cpu_ns += cpu1 - cpu0;
        p->cpu_at_yield_ns = r == W_YIELD && same ? cpu1 : -1;
        if (r == W_YIELD && same) {
            int64_t wake = atomic_load(&p->ctl->wake_mono_ns);
            int64_t yield = atomic_load(&p->ctl->yield_mono_ns);
            if (rt) {
                int64_t j = wake - start_mono;
                if (j > -1000000000LL && j < 1000000000LL)
                    ske_samples_add(&s->jitter_ns, j < 0 ? 0 : j);
            } else if (s->prev_yield_mono_ns > 0) {
                int64_t sw = wake - s->prev_yield_mono_ns;
                if (sw > 0 && sw < 1000000000LL)
                    ske_samples_add(&s->switch_ns, sw);
            }
            s->prev_yield_mono_ns = yield;
        } else {
            s->prev_yield_mono_ns = 0;
        }
    } else {
        s->prev_yield_mono_ns = 0;
    }

    /* In time order: what the partition reported inside its window, then what happened at
     * the window's end. */
    if (granted && p->ctl)
        drain_events(s, p, start, end);
    int rc = SKE_OK;
    if (r == W_OVERRUN) {
        ske_trace_begin(&s->trace, end, "ske", "overrun");
        ske_trace_str(&s->trace, "partition", p->cfg->name);
        ske_trace_int(&s->trace, "window", w->id);
        ske_trace_int(&s->trace, "frame", frame);
        ske_trace_int(&s->trace, "budget_ns", w->duration_ns);
        ske_trace_str(&s->trace, "cause", ov_cause_names[cause]);
        ske_trace_str(&s->trace, "action", "stopped");
        ske_trace_end(&s->trace);
    }
    if (granted && p->ctl)
        transfer_queues(s, p, end);
    if (r == W_YIELD && alive(p))
        rc = hm_take_post(s, p, end, err, errlen);
    if (rc == SKE_OK && r == W_YIELD && alive(p))
        take_schedule_request(s, p, end);
    if (rc == SKE_OK && outside_ns > OUTSIDE_LIMIT_NS && alive(p)) {
        char msg[96];
        int n = snprintf(msg, sizeof msg, "used CPU between its windows before window %d", w->id);
        rc = hm_handle(s, p, end, HM_ERR_WINDOW_OVERRUN, partition_state(p), HM_ORIGIN_SKE, 0,
                       NULL, msg, (size_t)n, false, err, errlen);
    }
    if (rc == SKE_OK && r == W_OVERRUN && alive(p)) {
        char msg[80];
        int n = snprintf(msg, sizeof msg, "window %d kept past its end (budget %lld ns)", w->id,
                         (long long)w->duration_ns);
        /* IGNORE leaves it stopped until its next window; IDLE or a restart end it now. */
        rc = hm_handle(s, p, end, HM_ERR_WINDOW_OVERRUN, partition_state(p), HM_ORIGIN_SKE, 0,
                       NULL, msg, (size_t)n, false, err, errlen);
    }
    if (rc == SKE_OK)
        rc = judge_exits(s, end, err, errlen);
    s->cur_partition = -1;
    ske_trace_begin(&s->trace, end, "ske", "window_end");
    ske_trace_str(&s->trace, "partition", p->cfg->name);
    ske_trace_int(&s->trace, "window", w->id);
    ske_trace_int(&s->trace, "frame", frame);
    if (granted) {
        ske_trace_bool(&s->trace, "yielded", r == W_YIELD);
        if (r == W_YIELD && !rt) {
            int64_t yt = atomic_load(&p->ctl->yield_t_ns);
            if (yt >= start && yt <= end)
                ske_trace_int(&s->trace, "yield_t_ns", yt);
        }
    }
    ske_trace_end(&s->trace);
    if (rc != SKE_OK)
        return rc;
    if (r == W_YIELD && alive(p))
        return handle_mode_request(s, p, end, err, errlen);
    return SKE_OK;
}

/* ---- life cycle ----------------------------------------------------------------------- */

int ske_create(const ske_module_cfg_t *cfg, const ske_run_opts_t *opts, ske_t **out, char *err,
               size_t errlen)
{
    *out = NULL;
    ske_t *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return SKE_E_NOMEM;
    }
    s->cfg = cfg;
    s->opts = *opts;
    s->cur_partition = -1;
    s->next_schedule = cfg->n_schedules ? cfg->initial_schedule : 0;
    s->time_mode = opts->time_mode >= 0 ? (ske_time_mode_t)opts->time_mode : cfg->time_mode;
    snprintf(s->node, sizeof s->node, "%s", opts->node ? opts->node : cfg->node);
    s->xfer = malloc(SYSTEM_MESSAGE_MAX);
    if (!s->xfer) {
        free(s);
        snprintf(err, errlen, "out of memory");
        return SKE_E_NOMEM;
    }
    ske_samples_init(&s->switch_ns, SAMPLE_LIMIT);
    ske_samples_init(&s->jitter_ns, SAMPLE_LIMIT);
    snprintf(s->exit_reason, sizeof s->exit_reason, "frames");
    for (int i = 0; i < cfg->n_partitions; i++) {
        part_t *p = &s->parts[i];
        p->cfg = &cfg->partitions[i];
        p->index = i;
        p->state = PS_NOT_STARTED;
        p->ctl_fd = -1;
        p->start_condition = 0; /* NORMAL_START */
        p->initial_mode = SKE_MODE_COLD_START;
        for (int k = 0; k < SKE_MAX_PORTS; k++)
            p->ports[k].fd = p->ports[k].fd_ro = -1;
    }
    int rc = setup_ports(s, err, errlen);
    if (rc != SKE_OK)
        goto fail;
    for (int i = 0; i < cfg->n_partitions; i++) {
        part_t *p = &s->parts[i];
        char name[64];
        snprintf(name, sizeof name, "ima-ctl-%s", p->cfg->name);
        void *mem;
        p->ctl_fd = memobj(name, sizeof(ske_ctl_t), &mem);
        if (p->ctl_fd < 0) {
            snprintf(err, errlen, "control block: %s", strerror(-p->ctl_fd));
            rc = SKE_E_SYS;
            goto fail;
        }
        p->ctl = mem;
    }
    if (ske_trace_open(&s->trace, opts->trace_path, s->node) != 0) {
        snprintf(err, errlen, "cannot write the trace %s: %s", opts->trace_path, strerror(errno));
        rc = SKE_E_IO;
        goto fail;
    }
    *out = s;
    return SKE_OK;
fail:
    ske_destroy(s);
    return rc;
}

/* The module's windows as a JSON array: the trace's module_start and the statistics. */
static void write_windows_json(FILE *f, const ske_module_cfg_t *m)
{
    fputc('[', f);
    for (int i = 0; i < m->n_windows; i++) {
        const ske_window_cfg_t *w = &m->windows[i];
        fprintf(f, "%s{\"window\":%d,\"partition\":", i ? "," : "", w->id);
        ske_json_escape(f, m->partitions[w->partition].name, strlen(m->partitions[w->partition].name));
        fprintf(f, ",\"offset_ns\":%" PRId64 ",\"duration_ns\":%" PRId64, w->offset_ns,
                w->duration_ns);
        if (m->n_schedules > 1)
            fprintf(f, ",\"schedule\":%d", m->schedules[w->schedule].id);
        fputc('}', f);
    }
    fputc(']', f);
}

static void trace_schedule(ske_t *s)
{
    const ske_module_cfg_t *m = s->cfg;
    ske_trace_begin(&s->trace, 0, "ske", "module_start");
    ske_trace_str(&s->trace, "module", m->module_name);
    ske_trace_str(&s->trace, "time_mode", s->time_mode == SKE_TIME_REALTIME ? "realtime" : "emulated");
    ske_trace_int(&s->trace, "major_frame_ns", m->major_frame_ns);
    if (s->trace.f) {
        fputs(",\"windows\":", s->trace.f);
        write_windows_json(s->trace.f, m);
        if (m->n_schedules > 1)
            fprintf(s->trace.f, ",\"initial_schedule\":%d", m->schedules[m->initial_schedule].id);
    }
    ske_trace_end(&s->trace);
    for (int i = 0; i < m->n_partitions; i++)
        trace_mode(s, &s->parts[i], 0, SKE_MODE_COLD_START, SKE_MODE_IDLE, "power-on");
}

static int write_stats(ske_t *s, double wall_s)
{
    if (!s->opts.stats_path)
        return 0;
    FILE *f = fopen(s->opts.stats_path, "w");
    if (!f)
        return -errno;
    const ske_module_cfg_t *m = s->cfg;
    fputs("{\"module\":", f);
    ske_json_escape(f, m->module_name, strlen(m->module_name));
    fputs(",\"node\":", f);
    ske_json_escape(f, s->node, strlen(s->node));
    fprintf(f, ",\"mode\":\"%s\",\"major_frame_ns\":%" PRId64 ",\"frames\":%" PRId64
               ",\"emulated_ns\":%" PRId64 ",\"wall_s\":%.6f,\"exit_reason\":\"%s\",\"partitions\":[",
            s->time_mode == SKE_TIME_REALTIME ? "realtime" : "emulated", m->major_frame_ns,
            s->frames_done, s->frames_done * m->major_frame_ns, wall_s, s->exit_reason);
    for (int i = 0; i < m->n_partitions; i++) {
        const part_t *p = &s->parts[i];
        int64_t per_frame = ske_plan_partition_ns(m, i);
        int nwin = p->cfg->n_windows;
        fprintf(f, "%s{\"id\":%d,\"name\":", i ? "," : "", p->cfg->id);
        ske_json_escape(f, p->cfg->name, strlen(p->cfg->name));
        fprintf(f, ",\"windows_per_frame\":%d,\"window_ns_per_frame\":%" PRId64
                   ",\"windows\":%llu,\"cpu_ns\":%" PRId64 ",\"overruns\":%llu,\"restarts\":%llu"
                   ",\"state\":\"%s\",\"exit_status\":",
                nwin, per_frame, (unsigned long long)p->windows, p->cpu_ns,
                (unsigned long long)p->overruns, (unsigned long long)p->restarts,
                state_name(p->state));
        if (p->state == PS_EXITED || p->state == PS_CRASHED)
            fprintf(f, "%d", p->exit_code);
        else
            fputs("null", f);
        const char *sig = p->state == PS_CRASHED ? sigabbrev_np(p->exit_code) : NULL;
        fputs(",\"exit_signal\":", f);
        if (sig)
            fprintf(f, "\"%s\"", sig);
        else
            fputs("null", f);
        fprintf(f, ",\"cpu_outside_windows_ns_max\":%" PRId64 "}", p->cpu_outside_max_ns);
    }
    fprintf(f, "],\"hm_events\":%llu", (unsigned long long)s->hm_events);
    fputs(",\"windows\":", f);
    write_windows_json(f, m);
    fputs(",\"window_switch_us\":", f);
    ske_samples_json_us(&s->switch_ns, f);
    fputs(",\"jitter_us\":", f);
    ske_samples_json_us(&s->jitter_ns, f);
    fputs(",\"channels\":[", f);
    for (int c = 0; c < m->n_channels; c++) {
        const ske_channel_cfg_t *ch = &m->channels[c];
        uint64_t msgs = s->chan_messages[c];
        if (ch->kind == SKE_PORT_SAMPLING) {
            const ske_sampling_hdr_t *h = s->parts[ch->src.partition].ports[ch->src.port].mem;
            msgs = atomic_load(&h->seq);
        }
        fprintf(f, "%s{\"id\":%d,\"name\":", c ? "," : "", ch->id);
        ske_json_escape(f, ch->name, strlen(ch->name));
        fprintf(f, ",\"kind\":\"%s\",\"messages\":%llu,\"overflows\":%llu}",
                ch->kind == SKE_PORT_SAMPLING ? "sampling" : "queuing", (unsigned long long)msgs,
                (unsigned long long)s->chan_overflows[c]);
    }
    fputs("]}\n", f);
    int rc = ferror(f) ? -EIO : 0;
    if (fclose(f) != 0 && rc == 0)
        rc = -(errno ? errno : EIO);
    return rc;
}

/* Lockstep: a window starting at t runs only once the bus has granted time past t; until then
 * the node reports its quantum done and waits for the next one (nodes/include/canbus/proto.h). */
static int wait_for_quantum(ske_t *s, int64_t t, char *err, size_t errlen)
{
    while (t >= s->bus.granted_ns) {
        int r = canbus_client_done_wait(&s->bus);
        if (r == CANBUS_STOPPED) {
            s->bus_stopped = true;
            return SKE_OK;
        }
        if (r == -EINTR) {
            if (s->stop_signal)
                return SKE_OK;
            if (s->child_event)
                reap(s);
            continue;
        }
        if (r < 0) {
            snprintf(err, errlen, "CAN bus: %s", strerror(-r));
            return SKE_E_IO;
        }
    }
    return SKE_OK;
}

int ske_run(ske_t *s, char *err, size_t errlen)
{
    const ske_module_cfg_t *m = s->cfg;
    int rc = SKE_OK;
    s->start_mono_ns = ske_mono_ns();
    s->pid = getpid();
    /* Partitions run as the same user: without this, /proc/<ske>/fd would hand them every
     * other partition's memory. */
    prctl(PR_SET_DUMPABLE, 0UL);
    if (s->time_mode == SKE_TIME_REALTIME)
        prctl(PR_SET_TIMERSLACK, 1UL); /* the default 50 µs slack would be window jitter */
    s->epoch_mono_ns = s->start_mono_ns; /* refined below for real-time mode */
    if (s->opts.lockstep_path) {
        char berr[256];
        int brc = canbus_client_connect(&s->bus, s->opts.lockstep_path, s->node,
                                        CANBUS_ROLE_LOCKSTEP, s->opts.node_index, berr, sizeof berr);
        if (brc != CANBUS_OK) {
            snprintf(err, errlen, "%s", berr);
            snprintf(s->exit_reason, sizeof s->exit_reason, "error");
            rc = SKE_E_IO;
            goto done;
        }
        s->on_bus = true;
    }
    for (int i = 0; i < m->n_partitions && rc == SKE_OK; i++)
        rc = spawn(s, &s->parts[i], err, errlen);
    if (rc != SKE_OK) {
        snprintf(s->exit_reason, sizeof s->exit_reason, s->stop_signal ? "signal" : "error");
        goto done;
    }
    /* Module time 0 is now (plus a little margin in real time so the first window starts
     * on time); partitions read the epoch from their control block at each grant. */
    s->epoch_mono_ns = ske_mono_ns() + (s->time_mode == SKE_TIME_REALTIME ? 2000000 : 0);
    for (int i = 0; i < m->n_partitions; i++)
        s->parts[i].ctl->epoch_mono_ns = s->epoch_mono_ns;
    trace_schedule(s);
    ske_slot_t slot;
    for (ske_plan_first(m, &slot); s->opts.frames < 0 || slot.frame < s->opts.frames;
         ske_plan_next(m, &slot)) {
        if (s->stop_signal || s->hm_shutdown)
            break;
        if (slot.index == 0 && slot.frame > INT64_MAX / m->major_frame_ns - 1) {
            /* The next major frame would start past the end of the 64-bit nanosecond clock
             * (about 292 years of module time). */
            snprintf(s->exit_reason, sizeof s->exit_reason, "end_of_time");
            break;
        }
        if (s->on_bus && (rc = wait_for_quantum(s, slot.start_ns, err, errlen)) != SKE_OK)
            break;
        if (s->bus_stopped || s->stop_signal)
            break;
        if (slot.index == 0 && m->n_schedules && s->next_schedule != slot.schedule)
            switch_schedule(s, &slot, s->next_schedule);
        if (slot.index == 0 && s->hm_reset) {
            rc = hm_module_reset(s, slot.start_ns, err, errlen);
            if (rc != SKE_OK)
                break;
        }
        rc = run_window(s, &slot, err, errlen);
        if (rc != SKE_OK)
            break;
        if (slot.index == m->n_windows - 1) {
            s->frames_done = slot.frame + 1;
            ske_trace_maybe_flush(&s->trace, ske_mono_ns());
        }
    }
    if (rc != SKE_OK)
        snprintf(s->exit_reason, sizeof s->exit_reason, "error");
    else if (s->stop_signal)
        snprintf(s->exit_reason, sizeof s->exit_reason, "signal");
    else if (s->hm_shutdown)
        snprintf(s->exit_reason, sizeof s->exit_reason, "hm_shutdown");
    else if (s->bus_stopped)
        snprintf(s->exit_reason, sizeof s->exit_reason, "bus_stop");
done:
    if (s->on_bus)
        canbus_client_close(&s->bus);
    for (int i = 0; i < m->n_partitions; i++)
        kill_partition(&s->parts[i]);
    /* A shutdown mid-frame stops at the end of the window where it was decided. */
    int64_t stop_t = s->frames_done * m->major_frame_ns;
    if (s->hm_shutdown && s->win_end_ns > stop_t)
        stop_t = s->win_end_ns;
    ske_trace_begin(&s->trace, stop_t, "ske", "module_stop");
    ske_trace_int(&s->trace, "frames", s->frames_done);
    ske_trace_str(&s->trace, "reason", s->exit_reason);
    ske_trace_end(&s->trace);
    int trc = ske_trace_close(&s->trace);
    int src = write_stats(s, (double)(ske_mono_ns() - s->start_mono_ns) / 1e9);
    /* Recorded data that could not be written is a failed run, whatever else went right. */
    if (trc != 0 && rc == SKE_OK) {
        snprintf(err, errlen, "the trace %s could not be written: %s", s->opts.trace_path,
                 strerror(-trc));
        rc = SKE_E_IO;
    }
    if (src != 0 && rc == SKE_OK) {
        snprintf(err, errlen, "the statistics %s could not be written: %s", s->opts.stats_path,
                 strerror(-src));
        rc = SKE_E_IO;
    }
    return rc;
}

void ske_destroy(ske_t *s)
{
    if (!s)
        return;
    for (int i = 0; i < SKE_MAX_PARTITIONS; i++) {
        part_t *p = &s->parts[i];
        if (!p->cfg)
            continue;
        kill_partition(p);
        for (int k = 0; k < p->cfg->n_ports; k++) {
            portmem_t *pm = &p->ports[k];
            if (pm->fd >= 0) {
                munmap(pm->mem, pm->size);
                close(pm->fd);
            }
            if (pm->fd_ro >= 0)
                close(pm->fd_ro);
        }
        if (p->ctl)
            munmap(p->ctl, sizeof(ske_ctl_t));
        if (p->ctl_fd >= 0)
            close(p->ctl_fd);
    }
    ske_trace_close(&s->trace);
    ske_samples_free(&s->switch_ns);
    ske_samples_free(&s->jitter_ns);
    free(s->xfer);
    free(s);
}
