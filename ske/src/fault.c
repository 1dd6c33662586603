/* SPDX-License-Identifier: Apache-2.0 */
/* Injected faults (ima-ske --fault): each spec checked against the module, armed in its
 * partition's control block for the APEX library's fault hook to commit, its `fault` events
 * traced with the SKE's bookkeeping kept across restarts; the faults the SKE handles itself
 * (a module reset, and a spell that finds its partition not running). */
#include "ske__supervisor.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

/* What a class needs: a port of a given kind and direction, a process, a value. */
enum {
    NEEDS_PARTITION = 1u << 0,
    TAKES_PROCESS = 1u << 1,
    PORT_SOURCE_SAMPLING = 1u << 2, /* port= required: a source sampling port */
    PORT_SOURCE_QUEUING = 1u << 3, /* port= required: a source queuing port */
    PORT_DESTINATION = 1u << 4, /* port= optional: a destination port (default: the first) */
    TAKES_VALUE = 1u << 5,
    STATE_FAULT = 1u << 6, /* active over its spells, cleared after */
    NEEDS_MEMORY_LIMIT = 1u << 7,
    NEEDS_OUTPUT_FILE = 1u << 8,
};

typedef struct {
    const char *name;
    int cls;
    unsigned flags;
} class_info_t;

static const class_info_t classes[] = {
    {"partition_crash", SKE_FAULT_PARTITION_CRASH, NEEDS_PARTITION | TAKES_PROCESS},
    {"partition_hang", SKE_FAULT_PARTITION_HANG, NEEDS_PARTITION | TAKES_PROCESS | STATE_FAULT},
    {"cpu_overrun", SKE_FAULT_CPU_OVERRUN, NEEDS_PARTITION | TAKES_PROCESS | TAKES_VALUE},
    {"memory_violation", SKE_FAULT_MEMORY_VIOLATION, NEEDS_PARTITION | TAKES_PROCESS},
    {"numeric_error", SKE_FAULT_NUMERIC_ERROR, NEEDS_PARTITION | TAKES_PROCESS},
    {"stack_overflow", SKE_FAULT_STACK_OVERFLOW, NEEDS_PARTITION | TAKES_PROCESS},
    {"illegal_request", SKE_FAULT_ILLEGAL_REQUEST, NEEDS_PARTITION | TAKES_PROCESS},
    {"application_error", SKE_FAULT_APPLICATION_ERROR, NEEDS_PARTITION | TAKES_PROCESS},
    {"deadline_miss", SKE_FAULT_DEADLINE_MISS, NEEDS_PARTITION | TAKES_PROCESS},
    {"memory_exhaustion", SKE_FAULT_MEMORY_EXHAUSTION,
     NEEDS_PARTITION | TAKES_PROCESS | NEEDS_MEMORY_LIMIT},
    {"corrupt_output", SKE_FAULT_CORRUPT_OUTPUT, NEEDS_PARTITION | PORT_SOURCE_SAMPLING | STATE_FAULT},
    {"stuck_output", SKE_FAULT_STUCK_OUTPUT, NEEDS_PARTITION | PORT_SOURCE_SAMPLING | STATE_FAULT},
    {"queuing_flood", SKE_FAULT_QUEUING_FLOOD, NEEDS_PARTITION | PORT_SOURCE_QUEUING | STATE_FAULT},
    {"foreign_port_write", SKE_FAULT_FOREIGN_PORT_WRITE, NEEDS_PARTITION | PORT_DESTINATION},
    {"module_reset", SKE_FAULT_MODULE_RESET, 0},
    {"disk_full", SKE_FAULT_DISK_FULL, NEEDS_PARTITION | STATE_FAULT | NEEDS_OUTPUT_FILE},
};
#define N_CLASSES (sizeof classes / sizeof classes[0])

static const class_info_t *class_of(int cls)
{
    for (size_t i = 0; i < N_CLASSES; i++)
        if (classes[i].cls == cls)
            return &classes[i];
    return NULL;
}

static const char *const state_names[] = {NULL, "applied", "cleared", "refused"};

/* Appends ", NAME" items to a list in buf (for the refusals that say what exists). */
static void list_add(char *buf, size_t len, const char *item)
{
    size_t n = strlen(buf);
    if (n < len)
        snprintf(buf + n, len - n, "%s%s", n ? ", " : "", item);
}

static int refuse(char *err, size_t errlen, const char *spec, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int refuse(char *err, size_t errlen, const char *spec, const char *fmt, ...)
{
    char why[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    snprintf(err, errlen, "--fault '%s': %s", spec, why);
    return SKE_E_CONFIG;
}

/* The longest window the partition has in any schedule: a CPU overrun's default spins for
 * longer than that. */
static int64_t longest_window(const ske_module_cfg_t *m, int pi)
{
    int64_t d = 0;
    for (int i = 0; i < m->n_windows; i++)
        if (m->windows[i].partition == pi && m->windows[i].duration_ns > d)
            d = m->windows[i].duration_ns;
    return d;
}

/* The parameters of a class, each checked against the module. */
static int check_target(ske_fault_t *f, const class_info_t *ci, const ske_module_cfg_t *m,
                        const char *text, char *err, size_t errlen)
{
    const fi_spec_t *sp = &f->spec;
    const char *part = fi_spec_param(sp, "partition");
    const char *proc = fi_spec_param(sp, "process");
    const char *port = fi_spec_param(sp, "port");
    const char *value = fi_spec_param(sp, "value");
    for (int i = 0; i < sp->n_params; i++) {
        const char *k = sp->params[i].key;
        bool known = (!strcmp(k, "partition") && (ci->flags & NEEDS_PARTITION)) ||
                     (!strcmp(k, "process") && (ci->flags & TAKES_PROCESS)) ||
                     (!strcmp(k, "port") && (ci->flags & (PORT_SOURCE_SAMPLING | PORT_SOURCE_QUEUING |
                                                          PORT_DESTINATION))) ||
                     (!strcmp(k, "value") && (ci->flags & TAKES_VALUE));
        if (!known)
            return refuse(err, errlen, text, "%s takes no parameter '%s'", ci->name, k);
    }
    f->partition = -1;
    f->port = -1;
    if (!(ci->flags & NEEDS_PARTITION)) {
        snprintf(f->target, sizeof f->target, "module");
        return SKE_OK;
    }
    if (!part)
        return refuse(err, errlen, text, "%s needs partition=NAME", ci->name);
    char names[512] = "";
    for (int i = 0; i < m->n_partitions; i++) {
        if (!strcmp(m->partitions[i].name, part))
            f->partition = i;
        list_add(names, sizeof names, m->partitions[i].name);
    }
    if (f->partition < 0)
        return refuse(err, errlen, text, "unknown partition '%s' (the module's: %s)", part, names);
    const ske_partition_cfg_t *p = &m->partitions[f->partition];
    snprintf(f->target, sizeof f->target, "%s", p->name);
    if (proc) {
        names[0] = '\0';
        bool found = false;
        for (int i = 0; i < p->n_processes; i++) {
            found = found || !strcmp(p->processes[i].name, proc);
            list_add(names, sizeof names, p->processes[i].name);
        }
        if (!found)
            return refuse(err, errlen, text, "partition '%s' declares no process '%s' (%s%s)",
                          p->name, proc, names[0] ? "its Process elements: " : "it declares none",
                          names);
        snprintf(f->process, sizeof f->process, "%s", proc);
        snprintf(f->target, sizeof f->target, "%s.%s", p->name, proc);
    }
    unsigned want = ci->flags & (PORT_SOURCE_SAMPLING | PORT_SOURCE_QUEUING | PORT_DESTINATION);
    if (want) {
        if (!port && want != PORT_DESTINATION)
            return refuse(err, errlen, text, "%s needs port=NAME", ci->name);
        for (int k = 0; k < p->n_ports; k++)
            if (port ? !strcmp(p->ports[k].name, port)
                     : p->ports[k].dir == SKE_DIR_DESTINATION && f->port < 0)
                f->port = k;
        if (f->port < 0 && port)
            return refuse(err, errlen, text, "partition '%s' has no port '%s'", p->name, port);
        if (f->port < 0)
            return refuse(err, errlen, text, "%s cannot apply: partition '%s' has no destination "
                          "port to write into", ci->name, p->name);
        const ske_port_cfg_t *pc = &p->ports[f->port];
        bool ok = want == PORT_DESTINATION
                      ? pc->dir == SKE_DIR_DESTINATION
                      : pc->dir == SKE_DIR_SOURCE &&
                            pc->kind == (want == PORT_SOURCE_SAMPLING ? SKE_PORT_SAMPLING : SKE_PORT_QUEUING);
        if (!ok)
            return refuse(err, errlen, text, "%s cannot apply to port '%s' of '%s': it needs a %s "
                          "port", ci->name, pc->name, p->name,
                          want == PORT_DESTINATION     ? "destination"
                          : want == PORT_SOURCE_SAMPLING ? "source sampling"
                                                         : "source queuing");
        snprintf(f->target, sizeof f->target, "%s.%s", p->name, pc->name);
    }
    if (ci->flags & TAKES_VALUE) {
        /* Milliseconds of CPU, or a time with its unit. */
        double ms;
        if (value && fi_spec_double(sp, "value", 0, &ms) == 0) {
            if (!(ms > 0 && ms < 1e9))
                return refuse(err, errlen, text, "value=%s: a positive number of milliseconds", value);
            f->value_ns = (int64_t)(ms * 1e6);
        } else if (value && (fi_parse_time(value, &f->value_ns) != 0 || f->value_ns <= 0)) {
            return refuse(err, errlen, text, "value=%s: milliseconds, or a time (20ms, 1.5s)", value);
        } else if (!value) {
            f->value_ns = longest_window(m, f->partition) + 1000000;
        }
    }
    if ((ci->flags & NEEDS_OUTPUT_FILE) && !p->output_file[0])
        return refuse(err, errlen, text, "%s cannot apply: partition '%s' has no output file "
                      "(no ima:Linux OutputFile)", ci->name, p->name);
    if (ci->flags & NEEDS_MEMORY_LIMIT) {
        if (p->memory_bytes == 0)
            return refuse(err, errlen, text, "%s cannot apply: partition '%s' has no memory limit "
                          "(no Partition_Memory)", ci->name, p->name);
        f->value_ns = (int64_t)p->memory_bytes;
    }
    return SKE_OK;
}

int ske__faults_parse(ske_faults_t *fs, const ske_module_cfg_t *m, const char *const *specs,
                      int n, char *err, size_t errlen)
{
    memset(fs, 0, sizeof *fs);
    int per_partition[SKE_MAX_PARTITIONS] = {0};
    for (int i = 0; i < n; i++) {
        const char *text = specs[i];
        if (fs->n == SKE_MAX_FAULTS)
            return refuse(err, errlen, text, "more than %d faults", SKE_MAX_FAULTS);
        ske_fault_t *f = &fs->f[fs->n];
        char why[256];
        if (fi_spec_parse(text, &f->spec, why, sizeof why) != 0)
            return refuse(err, errlen, text, "%s", why);
        const class_info_t *ci = NULL;
        char names[512] = "";
        for (size_t c = 0; c < N_CLASSES; c++) {
            if (!strcmp(classes[c].name, f->spec.cls))
                ci = &classes[c];
            list_add(names, sizeof names, classes[c].name);
        }
        if (!ci)
            return refuse(err, errlen, text, "unknown fault class '%s' (ima-ske's: %s)",
                          f->spec.cls, names);
        f->cls = ci->cls;
        for (int j = 0; j < fs->n; j++)
            if (!strcmp(fs->f[j].spec.fid, f->spec.fid))
                return refuse(err, errlen, text, "fid '%s' is given twice", f->spec.fid);
        int rc = check_target(f, ci, m, text, err, errlen);
        if (rc != SKE_OK)
            return rc;
        if (f->partition >= 0 && f->cls != SKE_FAULT_DISK_FULL) {
            if (per_partition[f->partition] == SKE_FAULT_SLOTS)
                return refuse(err, errlen, text, "more than %d faults for partition '%s'",
                              SKE_FAULT_SLOTS, m->partitions[f->partition].name);
            f->slot = per_partition[f->partition]++;
        }
        f->done_spell = -1;
        fs->n++;
    }
    return SKE_OK;
}

void ske__faults_fill_ctl(const ske_t *s, const ske_part_t *p)
{
    ske_ctl_t *c = p->ctl;
    c->n_faults = 0;
    for (int i = 0; i < s->faults.n; i++) {
        const ske_fault_t *f = &s->faults.f[i];
        if (f->partition != p->index || f->cls == SKE_FAULT_DISK_FULL)
            continue; /* (a full disk is the SKE's to make) */
        ske_fault_slot_t *sl = &c->faults[f->slot];
        memset(sl, 0, sizeof *sl);
        sl->cls = (uint32_t)f->cls;
        sl->duration = (uint32_t)f->spec.duration;
        sl->at_ns = f->spec.at_ns;
        sl->until_ns = f->spec.until_ns;
        sl->period_ns = f->spec.period_ns;
        sl->on_ns = f->spec.on_ns;
        sl->value_ns = f->value_ns;
        sl->port = f->port;
        /* A permanent fault that happens once happens again in every new process of the
         * partition: its cause is still there (faultinject/include/fi/spec.h). */
        bool again = f->spec.duration == FI_PERMANENT && !(class_of(f->cls)->flags & STATE_FAULT);
        sl->done_spell = again ? -1 : f->done_spell;
        sl->active = f->active;
        snprintf(sl->process, sizeof sl->process, "%s", f->process);
        snprintf(sl->fid, sizeof sl->fid, "%s", f->spec.fid);
        if ((uint32_t)f->slot + 1 > c->n_faults)
            c->n_faults = (uint32_t)f->slot + 1;
    }
}

static void trace_fault(ske_t *s, int64_t t, const char *src, const ske_fault_t *f, int state,
                        const char *detail, size_t dlen)
{
    ske_trace_begin(&s->trace, t, src, "fault");
    ske_trace_str(&s->trace, "fid", f->spec.fid);
    ske_trace_str(&s->trace, "class", f->spec.cls);
    ske_trace_str(&s->trace, "target", f->target);
    ske_trace_str(&s->trace, "state", state_names[state]);
    ske_trace_strn(&s->trace, "detail", detail, dlen);
    ske_trace_end(&s->trace);
}

/* The partition's record of what it did to one of its faults. The slot and the state are
 * checked; the rest (class, fid, target) is the SKE's own. */
bool ske__fault_event(ske_t *s, ske_part_t *p, int64_t t, int32_t slot, int32_t state,
                      const char *text, size_t len)
{
    if (state < SKE_FAULT_APPLIED || state > SKE_FAULT_REFUSED)
        return false;
    for (int i = 0; i < s->faults.n; i++) {
        ske_fault_t *f = &s->faults.f[i];
        if (f->partition != p->index || f->slot != slot)
            continue;
        int64_t k = fi_spec_spell(&f->spec, t);
        if (state == SKE_FAULT_CLEARED) {
            f->active = false;
        } else if (k > f->done_spell) {
            f->done_spell = k;
            f->active = state == SKE_FAULT_APPLIED && (class_of(f->cls)->flags & STATE_FAULT);
        }
        trace_fault(s, t, p->cfg->name, f, state, text, len);
        return true;
    }
    return false;
}

/* A spell that starts while its partition is not running cannot be committed: refused; a
 * state fault whose spell ended meanwhile is cleared. Checked at the partition's windows. */
void ske__faults_window_start(ske_t *s, ske_part_t *p, int64_t t)
{
    if (ske__alive(p))
        return;
    for (int i = 0; i < s->faults.n; i++) {
        ske_fault_t *f = &s->faults.f[i];
        if (f->partition != p->index || f->cls == SKE_FAULT_DISK_FULL)
            continue;
        int64_t k = fi_spec_spell(&f->spec, t);
        char detail[96];
        if (f->active && k != f->done_spell) {
            f->active = false;
            int n = snprintf(detail, sizeof detail, "spell over while the partition is %s",
                             ske__pstate_name(p->state));
            trace_fault(s, t, "ske", f, SKE_FAULT_CLEARED, detail, (size_t)n);
        }
        if (k >= 0 && k > f->done_spell) {
            f->done_spell = k;
            int n = snprintf(detail, sizeof detail, "the partition is not running (%s)",
                             ske__pstate_name(p->state));
            trace_fault(s, t, "ske", f, SKE_FAULT_REFUSED, detail, (size_t)n);
        }
    }
}

/* The file-size limit of the partition's running process: `limit` bytes, or none (-1). */
static int set_output_limit(ske_part_t *p, int64_t limit)
{
    p->output_limit = limit;
    if (!ske__alive(p) || p->pid <= 0)
        return 0; /* its next process gets it at its start (spawn.c) */
    struct rlimit rl = {.rlim_cur = limit < 0 ? RLIM_INFINITY : (rlim_t)limit,
                        .rlim_max = RLIM_INFINITY};
    return prlimit(p->pid, RLIMIT_FSIZE, &rl, NULL);
}

/* A full disk under a partition's output file: from the start of a spell to its end the
 * file cannot grow. The SKE sets the file-size limit (RLIMIT_FSIZE) of the partition's
 * processes to the file's size then; a partition with an output file ignores SIGXFSZ
 * (spawn.c), so its writes fail with EFBIG, as they would with ENOSPC on a full disk. */
void ske__faults_output(ske_t *s, ske_part_t *p, int64_t t)
{
    for (int i = 0; i < s->faults.n; i++) {
        ske_fault_t *f = &s->faults.f[i];
        if (f->partition != p->index || f->cls != SKE_FAULT_DISK_FULL)
            continue;
        int64_t k = fi_spec_spell(&f->spec, t);
        char detail[128];
        int n;
        if (f->active && k != f->done_spell) {
            f->active = false;
            int rc = set_output_limit(p, -1);
            n = rc == 0 ? snprintf(detail, sizeof detail, "the output file can grow again")
                        : snprintf(detail, sizeof detail, "prlimit: %s", strerror(errno));
            trace_fault(s, t, "ske", f, SKE_FAULT_CLEARED, detail, (size_t)n);
        }
        if (k >= 0 && k > f->done_spell) {
            f->done_spell = k;
            struct stat st;
            if (fstat(p->output_fd, &st) != 0) {
                n = snprintf(detail, sizeof detail, "fstat: %s", strerror(errno));
                trace_fault(s, t, "ske", f, SKE_FAULT_REFUSED, detail, (size_t)n);
                continue;
            }
            if (set_output_limit(p, (int64_t)st.st_size) != 0) {
                n = snprintf(detail, sizeof detail, "prlimit: %s", strerror(errno));
                p->output_limit = -1;
                trace_fault(s, t, "ske", f, SKE_FAULT_REFUSED, detail, (size_t)n);
                continue;
            }
            f->active = true;
            n = snprintf(detail, sizeof detail, "the output file is full at %lld bytes: its "
                         "writes fail (EFBIG)", (long long)st.st_size);
            trace_fault(s, t, "ske", f, SKE_FAULT_APPLIED, detail, (size_t)n);
        }
    }
}

/* A module reset, the path of a Module HM RESET (ARINC 653 Part 1, 2.4.2): at the start of
 * the first major frame at or after its time, every partition starts again. Once per spell:
 * a module that reset at every frame would never run. */
void ske__faults_frame_start(ske_t *s, int64_t t, int64_t frame)
{
    for (int i = 0; i < s->faults.n; i++) {
        ske_fault_t *f = &s->faults.f[i];
        if (f->cls != SKE_FAULT_MODULE_RESET)
            continue;
        int64_t k = fi_spec_spell(&f->spec, t);
        if (k < 0 || k <= f->done_spell)
            continue;
        f->done_spell = k;
        s->hm_reset = true;
        char detail[96];
        int n = snprintf(detail, sizeof detail, "module reset at the start of frame %lld: every "
                         "partition starts again", (long long)frame);
        trace_fault(s, t, "ske", f, SKE_FAULT_APPLIED, detail, (size_t)n);
    }
}
