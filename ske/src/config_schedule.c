/* SPDX-License-Identifier: Apache-2.0 */
/* The module schedules of the module XML (Module_Schedule): partition periods and windows,
 * checked against the rules of ARINC 653 Part 1, 2.3.1 that a schema cannot say. */
#include "ske__config.h"

#include <stdlib.h>
#include <string.h>

void ske__load_schedule(ske_loader_t *L, const xmlNode *n)
{
    ske_module_cfg_t *m = L->m;
    if (m->n_schedules >= SKE_MAX_SCHEDULES) {
        ske__fail(L, n, "at most 8 module schedules", "too many Module_Schedule elements");
        return;
    }
    int si = m->n_schedules;
    ske_schedule_cfg_t *sc = &m->schedules[si];
    memset(sc, 0, sizeof *sc);
    sc->line = ske__line_of(L, n);
    uint64_t sid = (uint64_t)si + 1;
    if (!ske__attr_u64(L, n, "ScheduleIdentifier", &sid, INT32_MAX, false) && L->failed)
        return;
    sc->id = (int32_t)sid;
    char name[256];
    if (ske__attr(n, "ScheduleName", name, sizeof name)) {
        if (!ske__attr_name(L, n, "ScheduleName", sc->name))
            return;
    } else {
        snprintf(sc->name, sizeof sc->name, "SCHEDULE_%d", sc->id);
    }
    for (int i = 0; i < si; i++)
        if (m->schedules[i].id == sc->id || strcmp(m->schedules[i].name, sc->name) == 0) {
            ske__fail(L, n, "module schedules have distinct identifiers and names",
                      "ScheduleIdentifier=%d / ScheduleName='%s' is already used (line %d)", sc->id,
                      sc->name, m->schedules[i].line);
            return;
        }
    sc->initial = ske__attr_bool(n, "InitialModuleSchedule", false);
    int64_t maf;
    if (!ske__attr_seconds(L, n, "MajorFrameSeconds", &maf, true))
        return;
    if (maf <= 0) {
        ske__fail(L, n, "the major frame is positive", "MajorFrameSeconds must be greater than 0");
        return;
    }
    if (si > 0 && maf != m->major_frame_ns) {
        ske__fail(L, n, "module schedules share the major frame",
                  "schedule '%s' has a major frame of %lld ns, the first schedule %lld ns",
                  sc->name, (long long)maf, (long long)m->major_frame_ns);
        return;
    }
    m->major_frame_ns = maf;
    m->n_schedules++;
    bool scheduled[SKE_MAX_PARTITIONS] = {false};
    for (const xmlNode *ps = n->children; ps && !L->failed; ps = ps->next) {
        if (!ske__is_elem(ps, "Partition_Schedule", false))
            continue;
        int pi = ske__partition_ref(L, ps);
        if (pi < 0)
            return;
        ske_partition_cfg_t *p = &m->partitions[pi];
        if (scheduled[pi]) {
            ske__fail(L, ps, "one Partition_Schedule per partition",
                      "partition '%s' has a second Partition_Schedule", p->name);
            return;
        }
        scheduled[pi] = true;
        int64_t period;
        if (!ske__attr_seconds(L, ps, "PeriodSeconds", &period, true))
            return;
        if (p->period_ns && period != p->period_ns) {
            ske__fail(L, ps, "a partition has the same period in every module schedule",
                      "partition '%s' has period %lld ns here but %lld ns in another schedule",
                      p->name, (long long)period, (long long)p->period_ns);
            return;
        }
        p->period_ns = period;
        if (p->period_ns <= 0 || m->major_frame_ns % p->period_ns != 0) {
            ske__fail(L, ps, "the partition period divides the major frame",
                      "PeriodSeconds of partition '%s' (%lld ns) does not divide the major frame "
                      "(%lld ns)", p->name, (long long)p->period_ns, (long long)m->major_frame_ns);
            return;
        }
        int64_t declared_duration = -1;
        if (ske__attr_seconds(L, ps, "PeriodDurationSeconds", &declared_duration, false) == false &&
            L->failed)
            return;
        int64_t total = 0;
        bool anchor_set = false;
        for (const xmlNode *w = ps->children; w && !L->failed; w = w->next) {
            if (!ske__is_elem(w, "Window_Schedule", false))
                continue;
            if (m->n_windows >= SKE_MAX_WINDOWS) {
                ske__fail(L, w, "at most 256 windows", "too many windows");
                return;
            }
            ske_window_cfg_t *win = &m->windows[m->n_windows];
            memset(win, 0, sizeof *win);
            win->line = ske__line_of(L, w);
            win->partition = pi;
            win->schedule = si;
            uint64_t wid;
            if (!ske__attr_u64(L, w, "WindowIdentifier", &wid, INT32_MAX, true) ||
                !ske__attr_seconds(L, w, "WindowStartSeconds", &win->offset_ns, true) ||
                !ske__attr_seconds(L, w, "WindowDurationSeconds", &win->duration_ns, true))
                return;
            win->id = (int32_t)wid;
            for (int i = 0; i < m->n_windows; i++)
                if (m->windows[i].id == win->id && m->windows[i].schedule == si) {
                    ske__fail(L, w, "window identifiers are unique",
                              "WindowIdentifier=%d is already used (line %d)", win->id,
                              m->windows[i].line);
                    return;
                }
            if (win->duration_ns <= 0) {
                ske__fail(L, w, "windows have a positive duration", "WindowDurationSeconds must be "
                          "greater than 0");
                return;
            }
            if (win->offset_ns >= m->major_frame_ns ||
                win->duration_ns > m->major_frame_ns - win->offset_ns) {
                ske__fail(L, w, "windows end within the major frame",
                          "window %d of partition '%s' runs from %lld ns to %lld ns, past the major "
                          "frame of %lld ns", win->id, p->name, (long long)win->offset_ns,
                          (long long)(win->offset_ns > INT64_MAX - win->duration_ns
                                     ? INT64_MAX : win->offset_ns + win->duration_ns),
                          (long long)m->major_frame_ns);
                return;
            }
            win->period_start = ske__attr_bool(w, "PartitionPeriodStart", false);
            if (win->period_start && !anchor_set) {
                p->anchor_in[si] = win->offset_ns % p->period_ns;
                anchor_set = true;
            }
            total += win->duration_ns;
            p->n_windows++;
            p->windows_in[si]++;
            m->n_windows++;
        }
        if (!anchor_set) {
            /* No window is marked as a period start: the first one starts the period. */
            int64_t first = INT64_MAX;
            for (int i = 0; i < m->n_windows; i++)
                if (m->windows[i].partition == pi && m->windows[i].schedule == si &&
                    m->windows[i].offset_ns < first)
                    first = m->windows[i].offset_ns;
            p->anchor_in[si] = first == INT64_MAX ? 0 : first % p->period_ns;
        }
        int64_t periods = m->major_frame_ns / p->period_ns;
        p->duration_in[si] = total / periods;
        /* The initial schedule's are the partition's until the schedules are all read. */
        p->duration_ns = p->duration_in[si];
        p->period_anchor_ns = p->anchor_in[si];
        if (declared_duration >= 0 && declared_duration * periods != total) {
            ske__fail(L, ps, "PeriodDurationSeconds is the window time per period",
                      "partition '%s' declares %lld ns per period but its windows give %lld ns per "
                      "period", p->name, (long long)declared_duration,
                      (long long)(total / periods));
            return;
        }
        /* Every period of the partition gets the same window time (ARINC 653 Part 1, 2.3.1.3):
         * a window belongs to the period its start falls in, and may not cross into the next. */
        for (int64_t k = 0; k < periods && !L->failed; k++) {
            int64_t lo = p->period_anchor_ns + k * p->period_ns, hi = lo + p->period_ns, in = 0;
            for (int i = 0; i < m->n_windows; i++) {
                const ske_window_cfg_t *win = &m->windows[i];
                if (win->partition != pi || win->schedule != si)
                    continue;
                /* offsets before the anchor belong to the last period, wrapping the frame */
                int64_t off = win->offset_ns < p->period_anchor_ns ? win->offset_ns + m->major_frame_ns
                                                                   : win->offset_ns;
                if (off < lo || off >= hi)
                    continue;
                if (off + win->duration_ns > hi) {
                    L->failed = false;
                    ske__diag_set(L->diag, m->path, win->line, "Window_Schedule",
                                  "a window stays within its partition period",
                                  "window %d of partition '%s' starts at %lld ns and ends past the end "
                                  "of its partition period at %lld ns", win->id, p->name,
                                  (long long)win->offset_ns, (long long)(hi % m->major_frame_ns));
                    L->failed = true;
                    return;
                }
                in += win->duration_ns;
            }
            if (in != p->duration_ns) {
                ske__fail(L, ps, "every partition period gets the same window time",
                          "partition '%s' gets %lld ns in its period starting at %lld ns but %lld ns "
                          "per period on average (period %lld ns)", p->name, (long long)in,
                          (long long)(lo % m->major_frame_ns), (long long)p->duration_ns,
                          (long long)p->period_ns);
                return;
            }
        }
    }
}

static int cmp_window(const void *a, const void *b)
{
    const ske_window_cfg_t *x = a, *y = b;
    if (x->schedule != y->schedule)
        return (x->schedule > y->schedule) - (x->schedule < y->schedule);
    return (x->offset_ns > y->offset_ns) - (x->offset_ns < y->offset_ns);
}

void ske__check_windows(ske_loader_t *L, const xmlNode *root)
{
    ske_module_cfg_t *m = L->m;
    qsort(m->windows, (size_t)m->n_windows, sizeof m->windows[0], cmp_window);
    for (int i = 1; i < m->n_windows; i++) {
        const ske_window_cfg_t *a = &m->windows[i - 1], *b = &m->windows[i];
        if (a->schedule == b->schedule && b->offset_ns < a->offset_ns + a->duration_ns) {
            /* Report at the later window, naming the one it overlaps. */
            const ske_window_cfg_t *late = a->line > b->line ? a : b;
            const ske_window_cfg_t *early = late == a ? b : a;
            L->failed = false; /* no earlier failure can reach here */
            ske__diag_set(L->diag, m->path, late->line, "Window_Schedule",
                          "windows of a module schedule do not overlap",
                          "window %d of partition '%s' [%lld ns, %lld ns) overlaps window %d of "
                          "partition '%s' [%lld ns, %lld ns) (line %d)", late->id,
                          m->partitions[late->partition].name, (long long)late->offset_ns,
                          (long long)(late->offset_ns + late->duration_ns), early->id,
                          m->partitions[early->partition].name, (long long)early->offset_ns,
                          (long long)(early->offset_ns + early->duration_ns), early->line);
            L->failed = true;
            return;
        }
    }
    for (int i = 0; i < m->n_partitions; i++) {
        if (m->partitions[i].n_windows == 0) {
            L->failed = false;
            ske__diag_set(L->diag, m->path, m->partitions[i].line, "Partition",
                          "every partition has at least one window",
                          "partition '%s' has no window in the Module_Schedule",
                          m->partitions[i].name);
            L->failed = true;
            return;
        }
    }
    /* Each schedule's windows, now grouped in schedule order; the initial schedule. */
    int initial = -1;
    for (int s = 0; s < m->n_schedules; s++) {
        ske_schedule_cfg_t *sc = &m->schedules[s];
        sc->first_window = -1;
        for (int i = 0; i < m->n_windows; i++)
            if (m->windows[i].schedule == s) {
                if (sc->first_window < 0)
                    sc->first_window = i;
                sc->n_windows++;
            }
        if (sc->first_window < 0)
            sc->first_window = 0;
        if (sc->initial) {
            if (initial >= 0) {
                L->failed = false;
                ske__diag_set(L->diag, m->path, sc->line, "Module_Schedule",
                              "one initial module schedule",
                              "schedules '%s' and '%s' are both InitialModuleSchedule",
                              m->schedules[initial].name, sc->name);
                L->failed = true;
                return;
            }
            initial = s;
        }
    }
    m->initial_schedule = initial >= 0 ? initial : 0;
    for (int i = 0; i < m->n_partitions; i++) {
        ske_partition_cfg_t *p = &m->partitions[i];
        p->duration_ns = p->duration_in[m->initial_schedule];
        p->period_anchor_ns = p->anchor_in[m->initial_schedule];
    }
    (void)root;
}
